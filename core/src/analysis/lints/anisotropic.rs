//! Lint rule FL016: a texture with one mip sampled through an anisotropic sampler.

use std::collections::BTreeSet;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::capture::model::BindingTarget;

/// FL016 `anisotropic-without-mips`: a texture with one mip sampled through an anisotropic sampler.
pub const ANISOTROPIC_WITHOUT_MIPS: LintKind = LintKind::new(&LintDef {
    code: "FL016",
    name: "anisotropic-without-mips",
    severity: LintSeverity::Warning,
    description: "a texture with one mip sampled through an anisotropic sampler",
});

/// Anisotropic filtering picks among mips along the footprint's long axis; a texture with
/// one mip leaves it only taps of the full-size level, as many as the footprint is long.
/// Small or thin primitives then cost seconds per draw on software rasterizers (llvmpipe
/// spent minutes on one frame of the example this way), and the result still aliases.
pub(super) struct AnisotropicWithoutMips;

impl Rule for AnisotropicWithoutMips {
    fn kinds(&self) -> &'static [LintKind] {
        &[ANISOTROPIC_WITHOUT_MIPS]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, order, .. } = *l;
        for &p in order {
            let pass = l.capture_pass(p);
            let Some(shader) = &pass.shader else { continue };
            let interface = &capture.shader(shader.id).interface;
            let entries = [&shader.vertex, &shader.fragment, &shader.compute]
                .into_iter()
                .flatten()
                .chain(pass.draws.iter().filter_map(|d| d.vertex.as_ref()))
                .chain(pass.draws.iter().filter_map(|d| d.fragment.as_ref()))
                .chain(pass.dispatches.iter().filter_map(|d| d.entry.as_ref()));
            let pairs: BTreeSet<&(String, String)> = entries
                .filter_map(|e| interface.entry_points.get(e))
                .flat_map(|e| e.sampling.iter())
                .collect();
            let bound = |variable: &str| pass.bindings.iter().find(|b| b.variable == variable);
            for (texture, sampler) in pairs {
                let (Some(t), Some(s)) = (bound(texture), bound(sampler)) else {
                    continue;
                };
                let (BindingTarget::Resource { resource, .. }, BindingTarget::Sampler(s)) =
                    (&t.target, &s.target)
                else {
                    continue;
                };
                let r = capture.resource(*resource);
                let mips = t.range.map_or(r.mip_levels, |range| range.mip_count);
                let s = &capture.samplers[s.index()];
                if s.max_anisotropy > 1 && mips <= 1 {
                    out.push(lint(
                    ANISOTROPIC_WITHOUT_MIPS,
                    format!(
                        "\"{}\" samples \"{}\" (one mip) through \"{}\" with {}x anisotropic filtering: give the texture a mip chain or sample it without anisotropy",
                        pass.name, r.name, s.name, s.max_anisotropy
                    ),
                    Some(pass.id),
                    Some(r.id),
                ));
                }
            }
        }
    }
}
