//! Attachment clears inside an imported render pass (`vkCmdClearAttachments`), which wgpu has
//! no command for, drawn: one triangle over the whole target, cut to each rectangle by the
//! scissor, whose fragments write the clear value to the colour targets named (blending off,
//! the others' write masks empty) and whose depth is the clear depth, tested `Always`; the
//! stencil is replaced by the clear value through the reference. The viewport, scissor and
//! stencil reference the draws set are put back afterwards, so the draws after it see theirs.

use std::collections::HashMap;

use framelab_core::plan::{VkClearOp, VkRasterOp};

use super::{ReplayError, Session, close, scope};

/// The pipelines clears draw with (one per distinct shader and states, made before the
/// frame), and the one each clear takes, by pass and clear index.
#[derive(Default)]
pub(super) struct ClearPipelines {
    pipelines: Vec<wgpu::RenderPipeline>,
    of: HashMap<(usize, usize), usize>,
}

/// What a clear's pipeline is made from; `key` names it.
struct ClearDesc {
    shader: String,
    targets: Vec<Option<wgpu::ColorTargetState>>,
    depth: Option<wgpu::DepthStencilState>,
    samples: u32,
}

/// `v` as an `f32` a WGSL literal can spell: finite, in range.
fn literal(v: f64) -> f32 {
    if v.is_finite() {
        v.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
    } else {
        0.0
    }
}

impl ClearDesc {
    fn of(r: &VkRasterOp, c: &VkClearOp) -> Self {
        let mut outputs = String::new();
        let mut values = Vec::new();
        for (i, (v, t)) in c.colors.iter().zip(&r.color).enumerate() {
            let v = v.unwrap_or_default();
            // An integer target takes integers (the import read the value through its format).
            let (ty, [x, y, z, w]) = match t.format.sample_type(None, None) {
                Some(wgpu::TextureSampleType::Uint) => (
                    "vec4<u32>",
                    v.map(|c| format!("{}u", c.clamp(0.0, f64::from(u32::MAX)) as u32)),
                ),
                Some(wgpu::TextureSampleType::Sint) => (
                    "vec4<i32>",
                    v.map(|c| {
                        let c = c.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
                        // WGSL has no negative literal: `-2147483648i` is out of range.
                        format!("i32({c})")
                    }),
                ),
                _ => ("vec4<f32>", v.map(|c| format!("{:?}", literal(c)))),
            };
            outputs.push_str(&format!("@location({i}) c{i}: {ty}, "));
            values.push(format!("{ty}({x}, {y}, {z}, {w})"));
        }
        let fragment = if values.is_empty() {
            "@fragment fn fs() {}".to_owned()
        } else {
            format!(
                "struct Out {{ {outputs} }}\n@fragment fn fs() -> Out {{ return Out({}); }}",
                values.join(", ")
            )
        };
        let shader = format!(
            "@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {{
    let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(p * 2.0 - 1.0, {:?}, 1.0);
}}
{fragment}",
            literal(f64::from(c.depth.unwrap_or(0.0)))
        );
        let targets = r
            .color
            .iter()
            .zip(&c.colors)
            .map(|(t, v)| {
                Some(wgpu::ColorTargetState {
                    format: t.format,
                    blend: None,
                    write_mask: if v.is_some() {
                        wgpu::ColorWrites::ALL
                    } else {
                        wgpu::ColorWrites::empty()
                    },
                })
            })
            .collect();
        let depth = r.depth.as_ref().map(|d| {
            let face = wgpu::StencilFaceState {
                compare: wgpu::CompareFunction::Always,
                fail_op: wgpu::StencilOperation::Keep,
                depth_fail_op: wgpu::StencilOperation::Keep,
                pass_op: wgpu::StencilOperation::Replace,
            };
            wgpu::DepthStencilState {
                format: d.format,
                depth_write_enabled: Some(c.depth.is_some() && d.format.has_depth_aspect()),
                depth_compare: Some(wgpu::CompareFunction::Always),
                // A format without stencil takes no stencil state at all.
                stencil: if d.format.has_stencil_aspect() {
                    wgpu::StencilState {
                        front: face,
                        back: face,
                        read_mask: 0xff,
                        write_mask: if c.stencil.is_some() { 0xff } else { 0 },
                    }
                } else {
                    wgpu::StencilState::default()
                },
                bias: wgpu::DepthBiasState::default(),
            }
        });
        ClearDesc {
            shader,
            targets,
            depth,
            samples: r.samples,
        }
    }

    fn key(&self) -> String {
        format!(
            "{}|{:?}|{:?}|{}",
            self.shader, self.targets, self.depth, self.samples
        )
    }
}

impl Session {
    /// The pipelines of every attachment clear in the plan, made before the frame.
    pub(super) fn create_clear_pipelines(&mut self) -> Result<(), ReplayError> {
        let ops: Vec<((usize, usize), &str, &VkRasterOp, &VkClearOp)> = self
            .plan
            .passes
            .iter()
            .enumerate()
            .filter_map(|(i, p)| match &p.op {
                framelab_core::plan::PassOp::VkRaster(r) => Some((i, p.name.as_str(), r)),
                _ => None,
            })
            .flat_map(|(i, name, r)| {
                r.clears
                    .iter()
                    .enumerate()
                    .map(move |(k, c)| ((i, k), name, r, c))
            })
            .collect();
        let mut made: HashMap<String, usize> = HashMap::new();
        let (mut pipelines, mut of) = (Vec::new(), HashMap::new());
        for (at, pass, r, c) in ops {
            let desc = ClearDesc::of(r, c);
            let key = desc.key();
            if let Some(&p) = made.get(&key) {
                of.insert(at, p);
                continue;
            }
            let scopes = scope(&self.device);
            let module = self
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("attachment clear"),
                    source: wgpu::ShaderSource::Wgsl(desc.shader.as_str().into()),
                });
            let pipeline = self
                .device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("attachment clear"),
                    layout: None,
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: wgpu::PrimitiveState::default(),
                    depth_stencil: desc.depth.clone(),
                    multisample: wgpu::MultisampleState {
                        count: desc.samples,
                        mask: !0,
                        alpha_to_coverage_enabled: false,
                    },
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("fs"),
                        compilation_options: Default::default(),
                        targets: &desc.targets,
                    }),
                    multiview_mask: None,
                    cache: None,
                });
            if let Some(message) = close(scopes) {
                return Err(ReplayError::Pass {
                    pass: pass.to_owned(),
                    message: format!("making the pipeline of an attachment clear: {message}"),
                });
            }
            made.insert(key, pipelines.len());
            of.insert(at, pipelines.len());
            pipelines.push(pipeline);
        }
        self.clear_rects = ClearPipelines { pipelines, of };
        Ok(())
    }

    /// Draws clear `k` of pass `pass` (`r`) into the open render pass `rp`, then puts back
    /// the viewport, scissor and stencil reference the pass's draws had set (`restore`).
    pub(super) fn encode_attachment_clear(
        &self,
        (pass, k): (usize, usize),
        r: &VkRasterOp,
        rp: &mut wgpu::RenderPass<'_>,
        restore: &Restore,
    ) {
        let c = &r.clears[k];
        let Some(pipeline) = self
            .clear_rects
            .of
            .get(&(pass, k))
            .map(|&p| &self.clear_rects.pipelines[p])
        else {
            return;
        };
        let [w, h] = r.extent;
        rp.set_pipeline(pipeline);
        rp.set_viewport(0.0, 0.0, w as f32, h as f32, 0.0, 1.0);
        if let Some(s) = c.stencil {
            rp.set_stencil_reference(s);
        }
        for &[x, y, rw, rh] in &c.rects {
            rp.set_scissor_rect(x, y, rw, rh);
            rp.draw(0..3, 0..1);
        }
        let [x, y, vw, vh, min, max] = restore
            .viewport
            .unwrap_or([0.0, 0.0, w as f32, h as f32, 0.0, 1.0]);
        rp.set_viewport(x, y, vw, vh, min, max);
        let [x, y, sw, sh] = restore.scissor.unwrap_or([0, 0, w, h]);
        rp.set_scissor_rect(x, y, sw, sh);
        if c.stencil.is_some() {
            rp.set_stencil_reference(restore.stencil_reference.unwrap_or(0));
        }
    }
}

/// The dynamic state the pass's draws set so far, which a clear must not change for the
/// draws after it.
#[derive(Default)]
pub(super) struct Restore {
    pub(super) viewport: Option<[f32; 6]>,
    pub(super) scissor: Option<[u32; 4]>,
    pub(super) stencil_reference: Option<u32>,
    pub(super) blend_constant: Option<[f64; 4]>,
}

impl Restore {
    /// Sets the state again in a render pass begun again in the middle of an imported pass
    /// (a new pass starts from wgpu's defaults).
    pub(super) fn apply(&self, rp: &mut wgpu::RenderPass<'_>) {
        if let Some([x, y, w, h, min, max]) = self.viewport {
            rp.set_viewport(x, y, w, h, min, max);
        }
        if let Some([x, y, w, h]) = self.scissor {
            rp.set_scissor_rect(x, y, w, h);
        }
        if let Some(s) = self.stencil_reference {
            rp.set_stencil_reference(s);
        }
        if let Some([r, g, b, a]) = self.blend_constant {
            rp.set_blend_constant(wgpu::Color { r, g, b, a });
        }
    }
}
