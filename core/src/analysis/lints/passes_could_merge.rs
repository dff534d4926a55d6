//! Lint rule FL017: two raster passes recorded one after the other that could be one render
//! pass. The second draws into the attachments the first leaves, loading what the first
//! stored; as one render pass the attachments would stay in tile memory between them (a
//! tiling GPU's store and load of every attachment saved). The fix is `what-if --merge`.

use super::{Fix, Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::capture::format::{LoadOp, PassKind};
use crate::capture::model::{AccessSource, Capture, PassDesc, ResourceAccess};

/// FL017 `passes-could-merge`: consecutive raster passes on the same attachments that could be
/// one render pass.
pub const PASSES_COULD_MERGE: LintKind = LintKind::new(&LintDef {
    code: "FL017",
    name: "passes-could-merge",
    severity: LintSeverity::Info,
    description: "consecutive raster passes on the same attachments that could be one render pass",
});

/// A shader access one of two passes makes that the other's conflicts with, outside the
/// attachments both share: inside one render pass nothing would order them.
#[derive(Debug)]
pub struct Unordered<'a> {
    pub writer: &'a PassDesc,
    pub reader: &'a PassDesc,
    pub resource: &'a str,
    /// How the other pass uses it.
    pub access: &'static str,
}

fn attachment(access: &ResourceAccess) -> bool {
    matches!(
        access.source,
        AccessSource::ColorAttachment(_) | AccessSource::DepthStencil
    )
}

/// Whether `x` and `y` touch the same bytes or texels, one of them writing.
pub fn conflict(x: &ResourceAccess, y: &ResourceAccess) -> bool {
    x.resource == y.resource && (x.writes || y.writes) && x.range.overlaps(&y.range)
}

/// The first access of `b` that conflicts with one of `a` other than through attachments both
/// render to (which rasterization orders), if any.
pub fn unordered_inside<'a>(
    capture: &'a Capture,
    a: &'a PassDesc,
    b: &'a PassDesc,
) -> Option<Unordered<'a>> {
    for x in &a.accesses {
        for y in b.accesses.iter().filter(|y| conflict(x, y)) {
            if attachment(x) && attachment(y) {
                continue;
            }
            let (writer, reader, access) = if x.writes {
                (a, b, y.access.as_str())
            } else {
                (b, a, x.access.as_str())
            };
            return Some(Unordered {
                writer,
                reader,
                resource: &capture.resource(x.resource).name,
                access,
            });
        }
    }
    None
}

/// The depth access of a pass's depth attachment (read-only or writable), if it has one.
fn depth_access(p: &PassDesc) -> Vec<(crate::capture::format::Access, bool)> {
    p.accesses
        .iter()
        .filter(|a| a.source == AccessSource::DepthStencil)
        .map(|a| (a.access, a.writes))
        .collect()
}

/// The two values serialize alike (the capture format's own equality).
fn same<T: serde::Serialize>(a: &T, b: &T) -> bool {
    serde_json::to_value(a).ok() == serde_json::to_value(b).ok()
}

/// Everything but the draws is one render pass's: the same queue, attachments, blending,
/// fixed-function state, shader file, bindings and parameters; the second loads every
/// attachment, waits on nothing and records no barrier.
fn one_render_pass(capture: &Capture, a: &PassDesc, b: &PassDesc) -> bool {
    let raster = a.kind == PassKind::Raster && b.kind == PassKind::Raster;
    let targets = a.color_attachments.len() == b.color_attachments.len()
        && a.color_attachments
            .iter()
            .zip(&b.color_attachments)
            .all(|(x, y)| {
                (x.resource, x.mip, x.layer, x.format) == (y.resource, y.mip, y.layer, y.format)
                    && same(&x.blend, &y.blend)
                    && x.write_mask == y.write_mask
                    && y.load == LoadOp::Load
            });
    let depth = match (&a.depth_stencil, &b.depth_stencil) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            (x.resource, x.mip, x.layer, x.format) == (y.resource, y.mip, y.layer, y.format)
                && y.depth_load == LoadOp::Load
                && y.stencil_load == LoadOp::Load
                && depth_access(a) == depth_access(b)
        }
        _ => false,
    };
    let same = |x: &crate::capture::format::RenderState,
                y: &crate::capture::format::RenderState| {
        serde_json::to_value(x).ok() == serde_json::to_value(y).ok()
    };
    let shader = a.shader.as_ref().map(|s| s.id) == b.shader.as_ref().map(|s| s.id);
    let bindings = b.bindings.iter().all(|y| {
        a.bindings
            .iter()
            .find(|x| x.variable == y.variable)
            .is_none_or(|x| x == y)
    });
    let params = b
        .params
        .iter()
        .all(|(k, v)| a.params.get(k).is_none_or(|w| w == v));
    raster
        && a.queue == b.queue
        && targets
        && depth
        && same(&a.state, &b.state)
        && shader
        && bindings
        && params
        && b.wait.is_empty()
        && b.barriers.is_empty()
        && unordered_inside(capture, a, b).is_none()
}

/// Raster passes recorded one after the other that could be one render pass.
pub(super) struct PassesCouldMerge;

impl Rule for PassesCouldMerge {
    fn kinds(&self) -> &'static [LintKind] {
        &[PASSES_COULD_MERGE]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter {
            capture,
            culled,
            model,
            ..
        } = *l;
        let culled: Vec<_> = culled.iter().map(|p| model.passes[p.index()].id).collect();
        let runs = |p: &PassDesc| l.in_order.contains(&p.id) && !culled.contains(&p.id);
        let mut merged_into_previous = false;
        for pair in capture.passes.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            // A pass merged with the one before it is left for the next round: merges made
            // together never name the same pass twice.
            if merged_into_previous || !runs(a) || !runs(b) || !one_render_pass(capture, a, b) {
                merged_into_previous = false;
                continue;
            }
            merged_into_previous = true;
            let mut finding = lint(
                PASSES_COULD_MERGE,
                format!(
                    "\"{}\" and \"{}\" draw into the same attachments one after the other, the second loading what the first stored: as one render pass they would keep the attachments in tile memory between them",
                    a.name, b.name
                ),
                Some(a.id),
                None,
            );
            finding.fix = Some(Fix::MergePasses {
                first: a.id,
                second: b.id,
            });
            out.push(finding);
        }
    }
}
