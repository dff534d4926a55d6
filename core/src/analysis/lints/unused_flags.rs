//! Lint rules FL001, FL002, FL003 and FL013: ALLOW_UNORDERED_ACCESS on a resource never bound
//! as a UAV; ALLOW_RENDER_TARGET on a resource never rendered to; ALLOW_DEPTH_STENCIL on a
//! resource never bound as depth; a resource no pass touches.

use super::{Fix, Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::capture::format::{Access, ResourceFlag};

/// FL001 `unused-uav-flag`: ALLOW_UNORDERED_ACCESS on a resource never bound as a UAV.
pub const UNUSED_UAV_FLAG: LintKind = LintKind::new(&LintDef {
    code: "FL001",
    name: "unused-uav-flag",
    severity: LintSeverity::Warning,
    description: "ALLOW_UNORDERED_ACCESS on a resource never bound as a UAV",
});

/// FL002 `unused-render-target-flag`: ALLOW_RENDER_TARGET on a resource never rendered to.
pub const UNUSED_RENDER_TARGET_FLAG: LintKind = LintKind::new(&LintDef {
    code: "FL002",
    name: "unused-render-target-flag",
    severity: LintSeverity::Warning,
    description: "ALLOW_RENDER_TARGET on a resource never rendered to",
});

/// FL003 `unused-depth-stencil-flag`: ALLOW_DEPTH_STENCIL on a resource never bound as depth.
pub const UNUSED_DEPTH_STENCIL_FLAG: LintKind = LintKind::new(&LintDef {
    code: "FL003",
    name: "unused-depth-stencil-flag",
    severity: LintSeverity::Warning,
    description: "ALLOW_DEPTH_STENCIL on a resource never bound as depth",
});

/// FL013 `unused-resource`: a resource no pass touches.
pub const UNUSED_RESOURCE: LintKind = LintKind::new(&LintDef {
    code: "FL013",
    name: "unused-resource",
    severity: LintSeverity::Warning,
    description: "a resource no pass touches",
});

/// Flags never used.
pub(super) struct UnusedFlags;

impl Rule for UnusedFlags {
    fn kinds(&self) -> &'static [LintKind] {
        &[
            UNUSED_UAV_FLAG,
            UNUSED_RENDER_TARGET_FLAG,
            UNUSED_DEPTH_STENCIL_FLAG,
            UNUSED_RESOURCE,
        ]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *l;
        for r in &capture.resources {
            let uses: Vec<Access> = l.uses_of(r.id).map(|(_, a)| a.access).collect();
            if uses.is_empty() {
                if r.swapchain {
                    continue;
                }
                out.push(lint(
                    UNUSED_RESOURCE,
                    format!("\"{}\" is declared but no pass uses it", r.name),
                    None,
                    Some(r.id),
                ));
                continue;
            }
            let checks = [
                (
                    ResourceFlag::AllowUnorderedAccess,
                    UNUSED_UAV_FLAG,
                    uses.iter().any(|a| a.is_unordered(r.is_texture())),
                    "bound as an unordered-access view",
                ),
                (
                    ResourceFlag::AllowRenderTarget,
                    UNUSED_RENDER_TARGET_FLAG,
                    uses.contains(&Access::ColorAttachment),
                    "rendered to",
                ),
                (
                    ResourceFlag::AllowDepthStencil,
                    UNUSED_DEPTH_STENCIL_FLAG,
                    uses.iter()
                        .any(|a| matches!(a, Access::DepthRead | Access::DepthWrite)),
                    "bound as depth-stencil",
                ),
            ];
            for (flag, code, used, how) in checks {
                if r.has_flag(flag) && !used {
                    let message = if l.vulkan_terms() {
                        let (usage, how) = match flag {
                            ResourceFlag::AllowRenderTarget => ("COLOR_ATTACHMENT", how),
                            ResourceFlag::AllowDepthStencil => ("DEPTH_STENCIL_ATTACHMENT", how),
                            _ if r.is_texture() => ("STORAGE", "bound as a storage image"),
                            _ => ("STORAGE", "bound as a storage buffer"),
                        };
                        let why = if r.is_texture() {
                            "fewer usage flags let the driver pick a better layout"
                        } else {
                            "the usage flag can go"
                        };
                        format!(
                            "\"{}\" was created with {usage} usage but is never {how}; {why}",
                            r.name
                        )
                    } else {
                        format!(
                            "\"{}\" has {} but is never {how}; removing the flag can enable compression",
                            r.name,
                            flag.name()
                        )
                    };
                    let mut l = lint(code, message, None, Some(r.id));
                    l.fix = Some(Fix::RemoveFlag {
                        resource: r.id,
                        flag,
                    });
                    out.push(l);
                }
            }
        }
    }
}
