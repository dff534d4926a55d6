//! Copies from a buffer into a texture held as RGBA8 for a 16-bit packed format
//! (`framelab_core::lower::packed16`), which wgpu cannot copy, drawn: one triangle over the
//! destination mip and layer, cut to the copied region by the scissor, whose fragments read
//! their texel's 16-bit word from the buffer (bound as storage, from the region's first word)
//! and widen each channel from its bits; a channel the format lacks reads 1.

use framelab_core::plan::{CopyOp, Packed16};

use super::Session;
use super::drawn_copies::{Region, buffer_into_texture, regions};
use super::encode::EncodeError;

const SHADER: &str = "
struct U { offset: u32, pitch: u32, origin: vec2<u32>, shift: vec4<u32>, bits: vec4<u32> }
@group(0) @binding(0) var<storage, read> words: array<u32>;
@group(0) @binding(1) var<uniform> u: U;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}
@fragment fn unpack(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let xy = vec2<u32>(p.xy) - u.origin;
    let at = u.offset + xy.y * u.pitch + xy.x * 2u;
    let word = (words[at >> 2u] >> ((at & 2u) * 8u)) & 0xffffu;
    let top = (vec4<u32>(1u) << u.bits) - vec4<u32>(1u);
    let v = (vec4<u32>(word) >> u.shift) & top;
    return select(vec4<f32>(v) / vec4<f32>(max(top, vec4<u32>(1u))), vec4<f32>(1.0), u.bits == vec4<u32>(0u));
}
";

/// The one pipeline unpacking copies draw with (their destination is always RGBA8).
#[derive(Default)]
pub(super) struct UnpackPipeline {
    pipeline: Option<wgpu::RenderPipeline>,
}

/// The uniform words of region `r` for `layout`: where its first word is, the pitch, the
/// origin, and each channel's shift and bits.
fn words(r: &Region, layout: Packed16) -> [u32; 12] {
    let [s, b] = [0, 1].map(|i| {
        layout
            .fields
            .map(|f| u32::from(if i == 0 { f.0 } else { f.1 }))
    });
    let (x, y, ..) = r.scissor;
    [
        r.first, r.pitch, x, y, s[0], s[1], s[2], s[3], b[0], b[1], b[2], b[3],
    ]
}

impl Session {
    /// The unpacking pipeline, made on first use.
    pub(super) fn unpack_pipeline(&mut self) {
        if self.unpacks.pipeline.is_some() {
            return;
        }
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("unpack 16-bit texels"),
                source: wgpu::ShaderSource::Wgsl(SHADER.into()),
            });
        let pipeline = super::pipelines::fullscreen_pipeline(
            &self.device,
            "unpack 16-bit texels",
            (&module, "unpack"),
            None,
            wgpu::TextureFormat::Rgba8Unorm,
        );
        self.unpacks.pipeline = Some(pipeline);
    }

    /// Draws copy `c` into its destination, each texel unpacked from the buffer in `layout`.
    pub(super) fn encode_unpack(
        &self,
        c: &CopyOp,
        layout: Packed16,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), EncodeError> {
        let Some((buffer, texture, mip, layer)) = buffer_into_texture(c) else {
            return Ok(());
        };
        // Made for every pass with such a copy before the first frame: a copy never goes
        // undrawn.
        let pipeline = self
            .unpacks
            .pipeline
            .as_ref()
            .ok_or_else(|| EncodeError::NoPipeline("unpack 16-bit texels".into()))?;
        let source = &self.buffers[buffer][parity];
        for (z, r) in regions(c, 2, source.size()).into_iter().enumerate() {
            let group = self.storage_group(pipeline, source, &r, &words(&r, layout));
            let dst = self.view(texture, parity, mip, layer + z as u32, None);
            let mut rp = super::encode::one_target(
                encoder,
                "unpack 16-bit texels",
                &dst,
                wgpu::LoadOp::Load,
            );
            super::drawn_copies::draw_region(&mut rp, pipeline, &group, &r);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A region's words: its first byte and pitch, the origin, then each channel's shift and
    /// bits (R5G6B5 here, no alpha).
    #[test]
    fn the_words_say_where_the_texels_are_and_how_they_are_packed() {
        let layout = Packed16 {
            fields: [(11, 5), (5, 6), (0, 5), (0, 0)],
        };
        let r = Region {
            bind_offset: 256,
            bind_size: 64,
            first: 44,
            pitch: 16,
            scissor: (2, 3, 4, 2),
        };
        assert_eq!(words(&r, layout), [44, 16, 2, 3, 11, 5, 0, 0, 5, 6, 5, 0]);
    }
}
