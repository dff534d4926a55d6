//! Values in the `vulkan` section and the draws' Vulkan state that no device accepts:
//! viewports that are not finite or have no width, scissors before the origin or past
//! `i32`, push-constant ranges that are not whole words within what any device offers, and
//! pipelines naming a stage twice or mixing compute with graphics stages. Checked here
//! because replay would otherwise meet them as a GPU validation failure mid-frame, or, for a
//! push-constant range of gigabytes, allocate that much for every draw.

use super::{JsonPath, Validator};
use crate::capture::format::{GraphicsState, Pipeline, PipelineLayout, VkCommandState};

use crate::capture::vulkan::MAX_PUSH_CONSTANT_BYTES;

/// Why viewport `[x, y, width, height, min depth, max depth]` cannot be, if it cannot.
fn viewport_fault(v: &[f32]) -> Option<String> {
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Some(format!(
            "viewport value {i} is not a finite number ({})",
            v[i]
        ));
    }
    // Vulkan lets the height be negative (the application flips y itself), never the width.
    if v[2] <= 0.0 {
        return Some(format!("viewport width {} is not positive", v[2]));
    }
    if v[3] == 0.0 {
        return Some("viewport height is 0".to_owned());
    }
    let (x0, x1) = (v[0], v[0] + v[2]);
    let (y0, y1) = (v[1].min(v[1] + v[3]), v[1].max(v[1] + v[3]));
    let bound = VIEWPORT_BOUND;
    (x0 < -bound || y0 < -bound || x1 > bound || y1 > bound).then(|| {
        format!(
            "viewport spans x {x0}..{x1}, y {y0}..{y1}, past -{bound}..{bound}, wider than any device's viewport bounds"
        )
    })
}

/// Half the widest `viewportBoundsRange` of any device (twice a 32768-texel viewport).
const VIEWPORT_BOUND: f32 = 65536.0;

/// The depth range is checked apart: outside `[0, 1]` needs `VK_EXT_depth_range_unrestricted`,
/// which a frame may use but replay cannot.
fn depth_fault(v: &[f32; 6]) -> Option<String> {
    let (min, max) = (v[4], v[5]);
    if !(0.0..=1.0).contains(&min) || !(0.0..=1.0).contains(&max) {
        return Some(format!(
            "viewport depth range {min}..{max} is outside 0..1 (VK_EXT_depth_range_unrestricted); replay cannot reproduce it"
        ));
    }
    // Vulkan lets the range run backwards (depth reversed); wgpu does not.
    (min > max).then(|| {
        format!("viewport depth range {min}..{max} runs backwards; replay cannot reproduce it")
    })
}

/// Why scissor `[x, y, width, height]` cannot be, if it cannot.
fn scissor_fault(s: &[i64; 4]) -> Option<String> {
    let [x, y, w, h] = *s;
    if x < 0 || y < 0 {
        return Some(format!("scissor offset ({x}, {y}) is negative"));
    }
    if w < 0 || h < 0 {
        return Some(format!("scissor extent {w}x{h} is negative"));
    }
    let max = i64::from(i32::MAX);
    (x.saturating_add(w) > max || y.saturating_add(h) > max)
        .then(|| format!("scissor ({x}, {y}) + {w}x{h} reaches past {max}, the most a scissor can"))
}

/// The `VK_SHADER_STAGE_*_BIT` names a graphics pipeline may hold.
const GRAPHICS_STAGES: &[&str] = &[
    "VK_SHADER_STAGE_VERTEX_BIT",
    "VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT",
    "VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT",
    "VK_SHADER_STAGE_GEOMETRY_BIT",
    "VK_SHADER_STAGE_FRAGMENT_BIT",
    "VK_SHADER_STAGE_TASK_BIT_EXT",
    "VK_SHADER_STAGE_MESH_BIT_EXT",
];

impl Validator<'_> {
    /// Every value of the section and of the draws' state a device would refuse.
    pub(super) fn check_vk_values(&mut self) {
        let raw = self.raw;
        let root = self.root.field("vulkan");
        if let Some(vk) = &raw.vulkan {
            for (i, l) in vk.pipeline_layouts.iter().enumerate() {
                self.check_push_ranges(l, &root.field("pipeline_layouts").index(i));
            }
            for (i, p) in vk.pipelines.iter().enumerate() {
                let path = root.field("pipelines").index(i);
                self.check_stages(p, &path);
                if let Some(g) = &p.graphics {
                    self.check_fixed_state(g, &path.field("graphics"));
                }
            }
        }
        for (i, pass) in raw.passes.iter().enumerate() {
            let path = self.root.field("passes").index(i);
            for (j, d) in pass.draws.iter().enumerate() {
                let sp = path.field("draws").index(j).field("vulkan_state");
                self.check_state(&d.vulkan_state, &sp);
            }
            for (j, d) in pass.dispatches.iter().enumerate() {
                let sp = path.field("dispatches").index(j).field("vulkan_state");
                self.check_state(&d.vulkan_state, &sp);
            }
        }
    }

    fn check_push_ranges(&mut self, l: &PipelineLayout, path: &JsonPath) {
        for (k, r) in l.push_constants.iter().enumerate() {
            let rp = path.field("push_constants").index(k);
            let end = u64::from(r.offset) + u64::from(r.size);
            let why = if r.size == 0 {
                Some("push-constant range of 0 bytes".to_owned())
            } else if !r.offset.is_multiple_of(4) || !r.size.is_multiple_of(4) {
                Some(format!(
                    "push-constant range {}..{end} is not whole 4-byte words",
                    r.offset
                ))
            } else if end > u64::from(MAX_PUSH_CONSTANT_BYTES) {
                Some(format!(
                    "push-constant range {}..{end} reaches past {MAX_PUSH_CONSTANT_BYTES} bytes, more than any device takes",
                    r.offset
                ))
            } else {
                None
            };
            if let Some(why) = why {
                self.diags.error("vulkan", &rp, why);
            }
        }
    }

    fn check_stages(&mut self, p: &Pipeline, path: &JsonPath) {
        let compute = p.bind_point.contains("COMPUTE");
        for (j, st) in p.stages.iter().enumerate() {
            let sp = path.field("stages").index(j).field("stage");
            if p.stages[..j].iter().any(|s| s.stage == st.stage) {
                self.diags.error(
                    "vulkan",
                    &sp,
                    format!("pipeline \"{}\" names stage {} twice", p.name, st.stage),
                );
            } else if compute && st.stage != "VK_SHADER_STAGE_COMPUTE_BIT" {
                self.diags.error(
                    "vulkan",
                    &sp,
                    format!(
                        "compute pipeline \"{}\" has a {} stage; it takes one VK_SHADER_STAGE_COMPUTE_BIT",
                        p.name, st.stage
                    ),
                );
            } else if !compute && !GRAPHICS_STAGES.contains(&st.stage.as_str()) {
                self.diags.error(
                    "vulkan",
                    &sp,
                    format!("graphics pipeline \"{}\" has a {} stage", p.name, st.stage),
                );
            }
        }
        if compute && p.stages.is_empty() {
            self.diags.error(
                "vulkan",
                &path.field("stages"),
                format!("compute pipeline \"{}\" has no stage", p.name),
            );
        }
    }

    fn check_fixed_state(&mut self, g: &GraphicsState, path: &JsonPath) {
        for (k, v) in g.viewports.iter().enumerate() {
            if let Some(why) = viewport_fault(v) {
                self.diags
                    .error("vulkan", &path.field("viewports").index(k), why);
            }
        }
        for (k, s) in g.scissors.iter().enumerate() {
            if let Some(why) = scissor_fault(s) {
                self.diags
                    .error("vulkan", &path.field("scissors").index(k), why);
            }
        }
        let floats = [
            ("blend_constants", g.blend_constants.as_slice()),
            ("depth_bias", g.depth_bias.as_ref().map_or(&[][..], |b| b)),
            ("line_width", std::slice::from_ref(&g.line_width)),
        ];
        self.check_finite(&floats, path);
    }

    fn check_state(&mut self, s: &VkCommandState, path: &JsonPath) {
        if let Some(v) = &s.viewport {
            let vp = path.field("viewport");
            if let Some(why) = viewport_fault(v) {
                self.diags.error("vulkan", &vp, why);
            } else if let Some(why) = depth_fault(v) {
                self.diags.warning("vulkan", &vp, why);
            }
        }
        if let Some(why) = s.scissor.as_ref().and_then(scissor_fault) {
            self.diags.error("vulkan", &path.field("scissor"), why);
        }
        let blend = s.blend_constants.as_ref().map_or(&[][..], |b| b);
        self.check_finite(&[("blend_constants", blend)], path);
    }

    fn check_finite(&mut self, fields: &[(&str, &[f32])], path: &JsonPath) {
        for (field, values) in fields {
            if let Some(x) = values.iter().find(|x| !x.is_finite()) {
                self.diags.error(
                    "vulkan",
                    &path.field(field),
                    format!("{field} holds {x}, not a finite number"),
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_are_named() {
        assert_eq!(viewport_fault(&[0.0, 0.0, 64.0, -64.0, 0.0, 1.0]), None);
        assert!(
            viewport_fault(&[0.0, 0.0, f32::INFINITY, 64.0, 0.0, 1.0])
                .unwrap()
                .contains("value 2")
        );
        assert!(
            viewport_fault(&[0.0, 0.0, 0.0, 64.0])
                .unwrap()
                .contains("width 0")
        );
        assert!(
            viewport_fault(&[0.0, 0.0, 1.0, 0.0])
                .unwrap()
                .contains("height is 0")
        );
        assert!(
            viewport_fault(&[1e30, 0.0, 1.0, 1.0])
                .unwrap()
                .contains("past")
        );
        assert!(
            viewport_fault(&[0.0, 70000.0, 1.0, -10000.0])
                .unwrap()
                .contains("y 60000..70000")
        );
        assert!(
            depth_fault(&[0.0, 0.0, 1.0, 1.0, 0.0, 5.0])
                .unwrap()
                .contains("0..5")
        );
        assert!(
            depth_fault(&[0.0, 0.0, 1.0, 1.0, 1.0, 0.0])
                .unwrap()
                .contains("backwards")
        );
        assert_eq!(depth_fault(&[0.0, 0.0, 1.0, 1.0, 0.0, 1.0]), None);
        assert_eq!(scissor_fault(&[0, 0, 64, 64]), None);
        assert!(
            scissor_fault(&[-1, 0, 64, 64])
                .unwrap()
                .contains("negative")
        );
        assert!(scissor_fault(&[0, 0, -4, 64]).unwrap().contains("extent"));
        assert!(
            scissor_fault(&[i64::from(i32::MAX), 0, 1, 1])
                .unwrap()
                .contains("past")
        );
    }
}
