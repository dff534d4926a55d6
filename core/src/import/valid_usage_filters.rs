//! What a draw or dispatch samples against what the capturing device can filter: a combined
//! image sampler its pipeline statically uses, whose sampler filters linearly without
//! comparing, over a view whose format the device cannot filter linearly
//! (`VUID-vkCmdDraw-magFilter-04553` and its siblings; vkBasalt's depth effects read the
//! program's depth buffer so on lavapipe). Said only where framelab knows the device's
//! format features (`DriverLayout::filters_linearly`).

use super::pipelines::{Pipelines, pipeline_name, sampler_name};
use super::record::Recording;
use super::state::{Descriptor, Objects};
use crate::capture::format::ValidUsageFinding;

/// The findings of draw or dispatch call `name` (at `index`), at its bind point (`compute`).
pub fn draw_filters(
    name: &str,
    index: u64,
    compute: bool,
    recording: &Recording,
    pipelines: &Pipelines,
    objects: &Objects,
) -> Vec<ValidUsageFinding> {
    let Some(pipeline) = recording.pipeline(compute) else {
        return Vec::new();
    };
    // The KHR and AMD names share the core command's VUIDs.
    let command = name.trim_end_matches("KHR").trim_end_matches("AMD");
    let mut out = Vec::new();
    for u in recording.bound_uses(compute) {
        let Descriptor::Image { view, sampler, .. } = &u.descriptor else {
            continue;
        };
        let used = pipelines
            .used_stages(pipeline, u.set, u.binding)
            .is_some_and(|s| s != 0);
        if *sampler == 0 || !used {
            continue;
        }
        let Some(s) = pipelines.sampler_of(*sampler) else {
            continue;
        };
        let linear = [&s.mag_filter, &s.min_filter]
            .iter()
            .any(|f| f.ends_with("LINEAR"));
        let Some((_, format, _)) = objects.view_kinds.get(view) else {
            continue;
        };
        if !linear
            || s.compare_op.is_some()
            || objects.device.filters_linearly(format) != Some(false)
        {
            continue;
        }
        out.push(ValidUsageFinding {
            vuid: format!("VUID-{command}-magFilter-04553"),
            command: format!("{name} #{index}"),
            detail: format!(
                "{} samples set {} binding {} through {}, which filters linearly without comparing, but the capturing device cannot filter the view's format {format} linearly",
                pipeline_name(pipeline),
                u.set,
                u.binding,
                sampler_name(*sampler),
            ),
        });
    }
    out
}
