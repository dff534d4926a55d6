//! What D3D12 lets each DXGI format do: render target, blend, depth-stencil, typed
//! unordered-access store and filtered sampling, after the per-format support tables of
//! D3D12 (`D3D12_FORMAT_SUPPORT1`, the "Hardware support for DXGI formats" pages).
//!
//! Validation asks this once per use (a resource's flags, a clear's view, a colour attachment
//! and its blend, a storage binding), so a format the driver refuses for that use is refused
//! at every use, not at the one place a check happened to be written. Optional support (a
//! cap a driver may or may not report: 96-bit RGB targets, B8G8R8A8 typed stores) counts as
//! supported: validation refuses only what no D3D12 driver accepts. What WebGPU lacks is a
//! separate question, answered by [`super::formats`] where a replay needs the format.

use super::dxgi::{self, FormatInfo, Layout, Numeric};

/// The uses a format supports (for a typeless format, what some member of its family does).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Support {
    pub render_target: bool,
    pub blend: bool,
    pub depth_stencil: bool,
    pub typed_uav_store: bool,
    /// `Sample` with a filtering sampler (integer formats only `Load`).
    pub sample: bool,
}

impl Support {
    /// The support of `f`; a typeless format gets the union of its family's members.
    pub fn of(f: &FormatInfo) -> Support {
        let mut family = dxgi::all()
            .iter()
            .filter(|m| m.typeless_family == Some(f.name))
            .peekable();
        // The aspect views (R24_UNORM_X8_TYPELESS, ...) are named typeless but head no family.
        if f.is_typeless() && family.peek().is_some() {
            return family.map(typed).fold(Support::default(), Support::union);
        }
        typed(f)
    }

    fn union(self, o: Support) -> Support {
        Support {
            render_target: self.render_target || o.render_target,
            blend: self.blend || o.blend,
            depth_stencil: self.depth_stencil || o.depth_stencil,
            typed_uav_store: self.typed_uav_store || o.typed_uav_store,
            sample: self.sample || o.sample,
        }
    }
}

/// Formats with colour channels that are still no render target: 1-bit, packed 4:2:2 and the
/// scan-out-only XR-bias format.
const NOT_TARGETS: &[&str] = &[
    "R1_UNORM",
    "R8G8_B8G8_UNORM",
    "G8R8_G8B8_UNORM",
    "R10G10B10_XR_BIAS_A2_UNORM",
];

fn typed(f: &FormatInfo) -> Support {
    if f.name == "UNKNOWN" || f.is_video_or_palette() {
        return Support::default();
    }
    let numeric = f.numeric();
    let integer = f.is_integer();
    if f.is_depth_format() {
        return Support {
            depth_stencil: true,
            ..Support::default()
        };
    }
    // Views of a depth/stencil family's aspects (R24_UNORM_X8, X24_G8_UINT, ...) are read,
    // never written.
    let aspect_view = f
        .typeless_family
        .is_some_and(|fam| matches!(fam, "R24G8_TYPELESS" | "R32G8X24_TYPELESS"));
    let colour = !aspect_view
        && f.layout == Layout::Linear
        && numeric != Some(Numeric::SharedExp)
        && !NOT_TARGETS.contains(&f.name);
    let sample = !integer && numeric != Some(Numeric::Typeless);
    Support {
        render_target: colour,
        blend: colour && !integer,
        depth_stencil: false,
        typed_uav_store: colour && !f.srgb && !f.name.starts_with("R32G32B32_"),
        sample,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::dxgi::lookup;

    fn of(name: &str) -> Support {
        Support::of(lookup(name).expect("a DXGI format"))
    }

    #[test]
    fn the_tables_rows_that_matter() {
        let rgba8 = of("R8G8B8A8_UNORM");
        assert!(rgba8.render_target && rgba8.blend && rgba8.typed_uav_store && rgba8.sample);
        let srgb = of("R8G8B8A8_UNORM_SRGB");
        assert!(srgb.render_target && srgb.blend && !srgb.typed_uav_store);
        let uint = of("R32_UINT");
        assert!(uint.render_target && !uint.blend && uint.typed_uav_store && !uint.sample);
        for name in NOT_TARGETS {
            let s = of(name);
            assert!(!s.render_target && !s.typed_uav_store && !s.blend, "{name}");
            assert!(s.sample, "{name} is sampled");
        }
        let shared = of("R9G9B9E5_SHAREDEXP");
        assert!(!shared.render_target && !shared.typed_uav_store && shared.sample);
        let bc = of("BC7_UNORM");
        assert!(!bc.render_target && !bc.typed_uav_store && bc.sample);
        let d = of("D24_UNORM_S8_UINT");
        assert_eq!(
            d,
            Support {
                depth_stencil: true,
                ..Support::default()
            }
        );
        let aspect = of("R24_UNORM_X8_TYPELESS");
        assert!(!aspect.render_target && !aspect.depth_stencil && aspect.sample);
        // Typeless: the union of the family.
        assert!(of("R24G8_TYPELESS").depth_stencil);
        assert!(of("R8G8B8A8_TYPELESS").typed_uav_store);
        assert!(of("R10G10B10A2_TYPELESS").render_target);
        assert!(!of("BC1_TYPELESS").render_target);
    }
}
