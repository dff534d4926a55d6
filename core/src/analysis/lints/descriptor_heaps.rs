//! Lint rule FL010: more descriptors needed than a descriptor heap holds, or no heap of a needed
//! type.

use std::collections::BTreeMap;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::capture::format::DescriptorHeapType;
use crate::capture::model::BindingTarget;

/// FL010 `descriptor-heap-capacity`: more descriptors needed than a descriptor heap holds, or no
/// heap of a needed type.
pub const DESCRIPTOR_HEAP_CAPACITY: LintKind = LintKind::new(&LintDef {
    code: "FL010",
    name: "descriptor-heap-capacity",
    severity: LintSeverity::Error,
    description: "more descriptors needed than a descriptor heap holds, or no heap of a needed type",
});

/// Descriptor heaps.
pub(super) struct DescriptorHeaps;

impl Rule for DescriptorHeaps {
    fn kinds(&self) -> &'static [LintKind] {
        &[DESCRIPTOR_HEAP_CAPACITY]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, order, .. } = *l;
        let mut needed: BTreeMap<DescriptorHeapType, u64> = BTreeMap::new();
        for &p in order {
            let pass = l.capture_pass(p);
            for b in &pass.bindings {
                let ty = match b.target {
                    BindingTarget::Sampler(_) => DescriptorHeapType::Sampler,
                    BindingTarget::Resource { .. } => DescriptorHeapType::CbvSrvUav,
                };
                *needed.entry(ty).or_default() += 1;
            }
            if pass.shader.is_some() {
                // The frame-constants and per-pass parameter buffers.
                *needed.entry(DescriptorHeapType::CbvSrvUav).or_default() += 2;
            }
            *needed.entry(DescriptorHeapType::Rtv).or_default() +=
                pass.color_attachments.len() as u64;
            *needed.entry(DescriptorHeapType::Dsv).or_default() +=
                u64::from(pass.depth_stencil.is_some());
        }
        for (ty, count) in needed.into_iter().filter(|(_, c)| *c > 0) {
            let name = match ty {
                DescriptorHeapType::CbvSrvUav => "CBV_SRV_UAV",
                DescriptorHeapType::Sampler => "SAMPLER",
                DescriptorHeapType::Rtv => "RTV",
                DescriptorHeapType::Dsv => "DSV",
            };
            let capacity: u64 = capture
                .descriptor_heaps
                .iter()
                .filter(|h| h.heap_type == ty)
                .map(|h| u64::from(h.capacity))
                .sum();
            if capture.descriptor_heaps.is_empty() {
                continue; // A capture without descriptor heaps does not model them.
            }
            if capacity == 0 {
                out.push(lint(
                    DESCRIPTOR_HEAP_CAPACITY,
                    format!(
                        "the frame needs {count} {name} descriptors but declares no {name} heap"
                    ),
                    None,
                    None,
                ));
            } else if count > capacity {
                out.push(lint(DESCRIPTOR_HEAP_CAPACITY, format!("the frame needs {count} {name} descriptors but its {name} heaps hold {capacity}"), None, None));
            }
        }
    }
}
