//! Copies from a buffer into a depth texture without stencil that WebGPU copies no buffer into
//! (`Depth32Float`, `Depth24Plus`), drawn: one triangle over the destination mip and layer, cut
//! to the copied region by the scissor, whose fragments read their texel's word from the
//! buffer (bound as storage, from the region's first word) and write it as their depth, every
//! test passing: a float as it is, 24 normalized bits as the float they stand for.

use framelab_core::plan::CopyOp;

use super::Session;
use super::drawn_copies::{Region, buffer_into_texture, regions};
use super::encode::EncodeError;

const SHADER: &str = "
struct U { offset: u32, pitch: u32, origin: vec2<u32>, float_words: u32, pad0: u32, pad1: u32, pad2: u32 }
@group(0) @binding(0) var<storage, read> words: array<u32>;
@group(0) @binding(1) var<uniform> u: U;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
@fragment fn fs(@builtin(position) p: vec4<f32>) -> @builtin(frag_depth) f32 {
    let xy = vec2<u32>(p.xy) - u.origin;
    let w = words[(u.offset + xy.y * u.pitch + xy.x * 4u) >> 2u];
    if u.float_words == 1u {
        return bitcast<f32>(w);
    }
    return f32(w & 0xffffffu) / 16777215.0;
}
";

/// The pipelines depth copies draw with, one a depth format, made before the first frame.
pub(super) fn pipelines() -> super::depth_upload::DepthPipelines {
    super::depth_upload::DepthPipelines::new("depth copy", SHADER)
}

/// The uniform words of region `r`: where its first word is, the pitch, the origin, and
/// whether the words are floats (else 24 normalized bits).
fn words(r: &Region, float_words: bool) -> [u32; 8] {
    let (x, y, ..) = r.scissor;
    [r.first, r.pitch, x, y, u32::from(float_words), 0, 0, 0]
}

impl Session {
    /// Draws copy `c` into its depth destination, each texel's depth read from the buffer.
    pub(super) fn encode_depth_copy(
        &self,
        c: &CopyOp,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), EncodeError> {
        let Some((buffer, texture, mip, layer)) = buffer_into_texture(c) else {
            return Ok(());
        };
        let format = self.plan.textures[texture].format;
        // Made for every pass with such a copy before the first frame: a copy never goes
        // undrawn.
        let pipeline = self
            .depth_copies
            .get(format)
            .ok_or_else(|| EncodeError::NoPipeline(format!("depth copy into {format:?}")))?;
        let float_words = format == wgpu::TextureFormat::Depth32Float;
        let source = &self.buffers[buffer][parity];
        for (z, r) in regions(c, 4, source.size()).into_iter().enumerate() {
            let group = self.storage_group(pipeline, source, &r, &words(&r, float_words));
            let dst = self.view(texture, parity, mip, layer + z as u32, None);
            let mut rp = super::depth_upload::depth_pass(
                encoder,
                "depth copy",
                &dst,
                wgpu::LoadOp::Load,
                false,
            );
            super::drawn_copies::draw_region(&mut rp, pipeline, &group, &r);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A region's words: its first byte and pitch, the origin, then whether they are floats.
    #[test]
    fn the_words_say_where_the_depths_are_and_what_they_are() {
        let r = Region {
            bind_offset: 256,
            bind_size: 64,
            first: 44,
            pitch: 32,
            scissor: (2, 3, 4, 2),
        };
        assert_eq!(words(&r, true), [44, 32, 2, 3, 1, 0, 0, 0]);
        assert_eq!(words(&r, false)[4], 0);
    }
}
