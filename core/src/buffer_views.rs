//! How each buffer of a replay plan can be read as rows, for the inspector's buffer viewer and
//! the MCP server's buffer reads: as the indirect-argument records it feeds, then as the WGSL
//! type of each variable bound to it. Computed from the plan alone, with no device.

use crate::layout::BufferLayout;

/// How the buffer viewer reads a plan buffer.
#[derive(Clone, Debug)]
pub struct BufferView {
    /// The replay plan's buffer index.
    pub plan_index: usize,
    pub size: u64,
    /// Ways to read it as rows, best first: the indirect-argument records it feeds, then the
    /// WGSL types of the variables bound to it; none means raw bytes only.
    pub layouts: Vec<LayoutChoice>,
    /// Where it is consumed as indirect arguments: `pass: draw "label" at byte N`.
    pub indirect: Vec<String>,
}

/// One way to read a buffer as rows.
#[derive(Clone, Debug, PartialEq)]
pub struct LayoutChoice {
    /// Where the type comes from: `var lights in shaders/lighting.wgsl`, `indirect draws`.
    pub source: String,
    /// Byte offset of row 0 (a binding's offset).
    pub base: u64,
    pub layout: BufferLayout,
}

/// Adds `choice` to `list` unless the same layout at the same base is there already.
fn add_layout(list: &mut Vec<LayoutChoice>, choice: LayoutChoice) {
    if !list
        .iter()
        .any(|c| c.layout == choice.layout && c.base == choice.base)
    {
        list.push(choice);
    }
}

/// How the buffer viewer can read each plan buffer, found in one walk over the plan: as the
/// indirect arguments it feeds, then as the WGSL type of each variable bound to it (first
/// binding of each distinct type; named struct members before bare scalar arrays).
pub fn buffer_views(plan: &crate::plan::Plan) -> Vec<BufferView> {
    use crate::plan::{BindTarget, PassOp};
    let mut views: Vec<BufferView> = plan
        .buffers
        .iter()
        .enumerate()
        .map(|(i, b)| BufferView {
            plan_index: i,
            size: b.size,
            layouts: Vec::new(),
            indirect: Vec::new(),
        })
        .collect();
    let mut typed: Vec<Vec<LayoutChoice>> = vec![Vec::new(); views.len()];
    // (buffer, byte offset, record layout, what reads it) for every indirect draw or dispatch.
    let mut indirect_use = |buffer: usize, offset: u64, layout: BufferLayout, text: String| {
        if let Some(v) = views.get_mut(buffer) {
            v.indirect.push(text);
            let source = if layout.type_name.starts_with("Dispatch") {
                "indirect dispatches"
            } else {
                "indirect draws"
            };
            add_layout(
                &mut v.layouts,
                LayoutChoice {
                    source: source.to_owned(),
                    base: offset % layout.stride,
                    layout,
                },
            );
        }
    };
    for pass in &plan.passes {
        let (shader, bindings) = match &pass.op {
            PassOp::Raster(r) => {
                for (i, d) in r.draws.iter().enumerate() {
                    let Some((b, offset)) = d.indirect else {
                        continue;
                    };
                    let indexed = d
                        .mesh
                        .and_then(|m| plan.meshes.get(m))
                        .is_some_and(|m| m.indices.is_some());
                    let label = d.label.clone().unwrap_or_else(|| format!("#{i}"));
                    let (layout, kind) = if indexed {
                        (BufferLayout::draw_indexed_indirect(), "indexed")
                    } else {
                        (BufferLayout::draw_indirect(), "non-indexed")
                    };
                    let text = format!("{}: {kind} draw {label} at byte {offset}", pass.name);
                    indirect_use(b, offset, layout, text);
                }
                (r.shader, &r.bindings)
            }
            PassOp::Compute(c) => {
                for (i, d) in c.dispatches.iter().enumerate() {
                    if let Some((b, offset)) = d.indirect {
                        let text = format!("{}: dispatch #{i} at byte {offset}", pass.name);
                        indirect_use(b, offset, BufferLayout::dispatch_indirect(), text);
                    }
                }
                (c.shader, &c.bindings)
            }
            _ => continue,
        };
        let Some(source) = plan.shaders.get(shader) else {
            continue;
        };
        let file = std::path::Path::new(&source.name)
            .file_name()
            .and_then(|f| f.to_str())
            .unwrap_or(source.name.as_str());
        for b in bindings {
            if let BindTarget::Buffer { buffer, offset, .. } = b.target
                && let Some(list) = typed.get_mut(buffer)
                && let Some(layout) = source.validated.buffer_layout(&b.variable)
            {
                add_layout(
                    list,
                    LayoutChoice {
                        source: format!("var {} in {file}", b.variable),
                        base: offset,
                        layout,
                    },
                );
            }
        }
    }
    for (view, mut typed) in views.iter_mut().zip(typed) {
        typed.sort_by_key(|c| c.layout.is_plain());
        view.layouts.extend(typed);
    }
    views
}
