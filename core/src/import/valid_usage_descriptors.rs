//! Descriptor validity at a draw or dispatch (`VUID-vkCmdDraw-None-02699` and its siblings:
//! the descriptors of the bound sets that the pipeline statically uses must be valid): a null
//! descriptor where the device did not enable the `nullDescriptor` feature (FFmpeg writes
//! `VK_NULL_HANDLE` for the planes a format lacks in an array its shader indexes), and a
//! descriptor whose image is not in the layout the descriptor says at that command, which the
//! synchronization rules find as they follow layouts and which the validation layer reports
//! with this VUID as well as the layout's own.

use super::pipelines::{Pipelines, pipeline_name};
use super::record::Recording;
use super::state::{Descriptor, Objects};
use crate::capture::format::{HazardKind, SyncHazard, ValidUsageFinding};

/// The VUID of draw or dispatch `name`'s rule (the KHR and AMD names share the core one's).
fn vuid(name: &str) -> String {
    let command = name.trim_end_matches("KHR").trim_end_matches("AMD");
    format!("VUID-{command}-None-02699")
}

/// The null descriptors draw or dispatch call `name` (at `index`) statically uses at its
/// bind point (`compute`), where the device did not enable `nullDescriptor`.
pub fn null_descriptors(
    name: &str,
    index: u64,
    compute: bool,
    recording: &Recording,
    pipelines: &Pipelines,
    objects: &Objects,
) -> Vec<ValidUsageFinding> {
    if objects.null_descriptor {
        return Vec::new();
    }
    let Some(pipeline) = recording.pipeline(compute) else {
        return Vec::new();
    };
    recording
        .bound_uses(compute)
        .filter(|u| matches!(u.descriptor, Descriptor::Null { .. }))
        .filter(|u| {
            pipelines
                .used_stages(pipeline, u.set, u.binding)
                .is_some_and(|s| s != 0)
        })
        .map(|u| ValidUsageFinding {
            vuid: vuid(name),
            command: format!("{name} #{index}"),
            detail: format!(
                "{} statically uses set {} binding {}, whose element {} is a null descriptor, and the device did not enable nullDescriptor",
                pipeline_name(pipeline),
                u.set,
                u.binding,
                u.element
            ),
        })
        .collect()
}

/// The draws and dispatches at which a descriptor's image is in another layout than the
/// descriptor says, where the command buffer itself put it in that layout (the layer's
/// check as it records), once per command.
pub fn layout_mismatches(hazards: &[SyncHazard]) -> Vec<ValidUsageFinding> {
    let mut seen = std::collections::BTreeSet::new();
    hazards
        .iter()
        .filter(|h| h.kind == HazardKind::LayoutMismatch && h.access.starts_with("descriptor"))
        .filter(|h| h.command.starts_with("vkCmdDraw") || h.command.starts_with("vkCmdDispatch"))
        .filter(|h| seen.insert(h.command.clone()))
        .map(|h| {
            let name = h.command.split(" #").next().unwrap_or(&h.command);
            ValidUsageFinding {
                vuid: vuid(name),
                command: h.command.clone(),
                detail: format!(
                    "the {} of \"{}\" is used with the image in {}",
                    h.access, h.resource, h.prior
                ),
            }
        })
        .collect()
}
