//! What a draw or dispatch needs of the descriptor sets its command buffer has bound
//! (`set_slots` keeps them): every set its pipeline statically uses bound, through a layout
//! compatible with the pipeline's for that set (`VUID-vkCmdDraw-None-02697` and its siblings,
//! one per draw and dispatch command), and no dynamic state set that the pipeline does not
//! declare dynamic.

use std::collections::BTreeSet;

use super::pipelines::{Pipelines, pipeline_name};
use super::record::Recording;
use super::set_slots::SetProblem;
use crate::capture::format::ValidUsageFinding;

/// What draw or dispatch call `name` (at `index`) finds wrong with the sets its recording
/// has bound for the pipeline at its bind point (`compute`), under the validation layer's
/// ids: the highest set used not bound through a compatible layout, or a used set left
/// unbound below it, is the command's `None-02697`.
/// Nothing is said without a bound pipeline whose code and layout are known.
/// `snapshot`: the command is in a trimmed capture's state snapshot, where GFXReconstruct
/// records again a command buffer made before the frame (without its push descriptors).
pub fn draw_usage(
    name: &str,
    index: u64,
    compute: bool,
    recording: &Recording,
    pipelines: &Pipelines,
    snapshot: bool,
) -> Vec<ValidUsageFinding> {
    let Some(pipeline) = recording.pipeline(compute) else {
        return Vec::new();
    };
    let Some((layout, used)) = pipelines.used_sets(pipeline) else {
        return Vec::new();
    };
    let Some(compat) = pipelines.compat_ids(layout) else {
        return Vec::new();
    };
    // The KHR and AMD names share the core command's VUIDs.
    let command = name.trim_end_matches("KHR").trim_end_matches("AMD");
    let whence = if snapshot {
        " (in the capture's state snapshot, which records the command buffer again)"
    } else {
        ""
    };
    let named = |l: u64| {
        if l == 0 {
            "none".to_owned()
        } else {
            format!("pipeline_layout_{l}")
        }
    };
    recording
        .set_slots(compute)
        .check(&compat, &used)
        .into_iter()
        .map(|p| match p {
            SetProblem::Incompatible { set, layout: bound } => ValidUsageFinding {
                vuid: format!("VUID-{command}-None-02697"),
                command: format!("{name} #{index}"),
                detail: format!(
                    "{} (created with pipeline_layout_{layout}) statically uses descriptor set {set}, which is not bound through a layout compatible for it (the last bind's layout: {}){whence}",
                    pipeline_name(pipeline),
                    named(bound)
                ),
            },
            SetProblem::NotBound { set } => ValidUsageFinding {
                vuid: format!("VUID-{command}-None-02697"),
                command: format!("{name} #{index}"),
                detail: format!(
                    "{} statically uses descriptor set {set}, which is not bound (never, or disturbed by a bind through an incompatible layout){whence}",
                    pipeline_name(pipeline)
                ),
            },
        })
        .collect()
}

/// Draw call `name` (at `index`): the dynamic states set since its pipeline was bound that
/// the pipeline does not declare dynamic (`VUID-vkCmdDraw-None-02859` and its siblings; zink
/// sets its colour blend states after binding a depth-only pipeline that has none). Names
/// are compared without their `_EXT` or `_KHR`, which core promotion dropped.
pub fn undeclared_states(
    name: &str,
    index: u64,
    recording: &Recording,
    pipelines: &Pipelines,
) -> Vec<ValidUsageFinding> {
    let Some(pipeline) = recording.pipeline(false) else {
        return Vec::new();
    };
    let Some(dynamic) = pipelines.dynamic_states(pipeline) else {
        return Vec::new();
    };
    let bare = |s: &str| {
        let s = s.trim_end_matches("_EXT").trim_end_matches("_KHR");
        s.to_owned()
    };
    let declared: BTreeSet<String> = dynamic.iter().map(|s| bare(s)).collect();
    let undeclared: Vec<&str> = recording
        .states_set()
        .iter()
        .filter(|s| !declared.contains(&bare(s)))
        .copied()
        .collect();
    if undeclared.is_empty() {
        return Vec::new();
    }
    let command = name.trim_end_matches("KHR").trim_end_matches("AMD");
    vec![ValidUsageFinding {
        vuid: format!("VUID-{command}-None-02859"),
        command: format!("{name} #{index}"),
        detail: format!(
            "{} does not declare {} dynamic, which calls since it was bound set",
            pipeline_name(pipeline),
            undeclared.join("|")
        ),
    }]
}
