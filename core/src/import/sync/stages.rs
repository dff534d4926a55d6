//! Pipeline stages as the synchronization chapter orders them: each pipeline's stages in
//! logical order, the first and second synchronization scopes a stage mask reaches, and the
//! stages a binding's shaders run at. Plain functions on stage masks, kept apart from the
//! checker that applies them.

use crate::capture::vulkan::PipelineStages as S;

/// The stages of each pipeline in their logical order: a stage's "earlier" stages come first.
const ORDERS: [&[S]; 3] = [
    &[
        S::TOP_OF_PIPE,
        S::DRAW_INDIRECT,
        S::VERTEX_INPUT,
        S::VERTEX_SHADER,
        S::TESSELLATION_CONTROL_SHADER,
        S::TESSELLATION_EVALUATION_SHADER,
        S::GEOMETRY_SHADER,
        S::EARLY_FRAGMENT_TESTS,
        S::FRAGMENT_SHADER,
        S::LATE_FRAGMENT_TESTS,
        S::COLOR_ATTACHMENT_OUTPUT,
        S::BOTTOM_OF_PIPE,
    ],
    &[
        S::TOP_OF_PIPE,
        S::DRAW_INDIRECT,
        S::COMPUTE_SHADER,
        S::BOTTOM_OF_PIPE,
    ],
    &[S::TOP_OF_PIPE, S::TRANSFER, S::BOTTOM_OF_PIPE],
];

/// A stage with the parts the `*2` enum splits it into, so one bit stands for them all.
pub(super) fn canonical(s: S) -> S {
    let mut out = s.expand();
    if out.intersects(S::TRANSFER_PARTS) {
        out |= S::TRANSFER;
    }
    if out.intersects(S::VERTEX_INPUT_PARTS) {
        out |= S::VERTEX_INPUT;
    }
    if out.intersects(S::PRE_RASTERIZATION_SHADERS) {
        out |= S::PRE_RASTERIZATION_PARTS;
    }
    out
}

/// The stages and every stage logically earlier (`earlier`) or later than them, in each
/// pipeline that has them.
fn reach(s: S, earlier: bool) -> S {
    let s = canonical(s);
    let mut out = s;
    for order in ORDERS {
        let hit = |x: &S| s.intersects(*x);
        let span = if earlier {
            order.iter().rposition(hit).map(|last| &order[..=last])
        } else {
            order.iter().position(hit).map(|first| &order[first..])
        };
        for x in span.unwrap_or(&[]) {
            out |= *x;
        }
    }
    out
}

/// A first synchronization scope: the stages and every stage logically earlier.
pub(super) fn earlier(s: S) -> S {
    reach(s, true)
}

/// A second synchronization scope: the stages and every stage logically later.
pub(super) fn later(s: S) -> S {
    reach(s, false)
}

/// Which shader stages of the bound pipeline can reach a binding (its set layout's stages),
/// as pipeline stages.
pub(super) fn shader_stages(flags: u32, compute: bool) -> S {
    if compute {
        return S::COMPUTE_SHADER;
    }
    let mut s = S::EMPTY;
    for (bit, stage) in [
        (0x1, S::VERTEX_SHADER),
        (0x2, S::TESSELLATION_CONTROL_SHADER),
        (0x4, S::TESSELLATION_EVALUATION_SHADER),
        (0x8, S::GEOMETRY_SHADER),
        (0x10, S::FRAGMENT_SHADER),
    ] {
        if flags & bit != 0 {
            s |= stage;
        }
    }
    if s.is_empty() {
        S::VERTEX_SHADER | S::FRAGMENT_SHADER
    } else {
        s
    }
}

/// The single stages of a set.
pub(super) fn stages_of(s: S) -> impl Iterator<Item = S> {
    (0..64)
        .map(|b| S::from_bits(1u64 << b))
        .filter(move |x| s.intersects(*x))
}
