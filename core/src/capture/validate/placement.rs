//! Where a resource's memory comes from: committed, reserved, or placed in a named heap at
//! an offset its alignment, the heap's size and the heap's flags allow.

use std::collections::BTreeSet;

use super::{Validator, describe_allows};
use crate::capture::diag::JsonPath;
use crate::capture::format::{HeapType, Placement, Resource, ResourceFlag, ResourceKind};
use crate::capture::model::{HeapDesc, HeapId, PlacementDesc, ResourceCategory};
use crate::text::human_bytes;

impl Validator<'_> {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn check_placement(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        heaps: &[HeapDesc],
        bytes: u64,
        alignment: u64,
        samples: u32,
        flags: &BTreeSet<ResourceFlag>,
    ) -> Option<PlacementDesc> {
        let ppath = path.field("placement");
        let placement = match &r.placement {
            None => PlacementDesc::Committed {
                heap_type: HeapType::Default,
            },
            Some(Placement::Committed { heap_type }) => {
                if *heap_type == HeapType::Custom {
                    self.diags.error("placement", &ppath.field("committed").field("heap_type"), "committed resources use DEFAULT, UPLOAD or READBACK; put CUSTOM resources in a named heap");
                }
                PlacementDesc::Committed {
                    heap_type: *heap_type,
                }
            }
            Some(Placement::Reserved) => {
                if r.kind == ResourceKind::Texture3D && samples > 1 {
                    self.diags.error(
                        "placement",
                        &ppath,
                        "reserved MSAA 3D textures do not exist",
                    );
                }
                PlacementDesc::Reserved
            }
            Some(Placement::Placed {
                heap,
                offset,
                alignment: reported,
            }) => {
                let hpath = ppath.field("placed").field("heap");
                let id = self.lookup("heap", heap, &hpath)?;
                let h = &heaps[id as usize];
                let opath = ppath.field("placed").field("offset");
                // `alignment` is already the reported one where that is a power of two.
                if let Some(a) = reported.filter(|a| !a.is_power_of_two()) {
                    self.diags.error(
                        "placement-alignment",
                        &ppath.field("placed").field("alignment"),
                        format!("alignment {a} of \"{}\" is not a power of two", r.name),
                    );
                }
                if offset % alignment != 0 {
                    self.diags.error("placement-alignment", &opath, format!(
                        "\"{}\" is placed at offset {offset}, which is not a multiple of its alignment {alignment}{}",
                        r.name, if samples > 1 { " (multisampled resources need 4 MiB)" } else { "" }
                    ));
                }
                if h.alignment < alignment {
                    self.diags.error(
                        "placement-alignment",
                        &hpath,
                        format!(
                            "heap \"{}\" is aligned to {} but \"{}\" needs {alignment}",
                            h.name, h.alignment, r.name
                        ),
                    );
                }
                let end = offset.checked_add(bytes);
                if end.is_none_or(|e| e > h.size) {
                    self.diags.error(
                        "placement-bounds",
                        &opath,
                        format!(
                            "\"{}\" ({} at offset {offset}) does not fit in heap \"{}\" of {}",
                            r.name,
                            human_bytes(bytes),
                            h.name,
                            human_bytes(h.size)
                        ),
                    );
                }
                let category = if !r.kind.is_texture() {
                    ResourceCategory::Buffer
                } else if flags.contains(&ResourceFlag::AllowRenderTarget)
                    || flags.contains(&ResourceFlag::AllowDepthStencil)
                {
                    ResourceCategory::RtDsTexture
                } else {
                    ResourceCategory::OtherTexture
                };
                if !h.allows.allows(category) {
                    self.diags.error(
                        "placement-heap-flags",
                        &hpath,
                        format!(
                            "heap \"{}\" does not allow {} (its flags allow {}), but \"{}\" is one",
                            h.name,
                            category.describe(),
                            describe_allows(h.allows),
                            r.name
                        ),
                    );
                }
                PlacementDesc::Placed {
                    heap: HeapId(id),
                    offset: *offset,
                }
            }
        };
        let heap_type = match &placement {
            PlacementDesc::Committed { heap_type } => *heap_type,
            PlacementDesc::Placed { heap, .. } => heaps[heap.index()].heap_type,
            PlacementDesc::Reserved => HeapType::Default,
        };
        if matches!(heap_type, HeapType::Upload | HeapType::Readback) {
            if r.kind.is_texture() {
                self.diags.error("placement-heap-type", &ppath, format!(
                    "texture \"{}\" is in an {} heap; UPLOAD and READBACK heaps hold buffers (copy textures through them)", r.name, heap_type.name()
                ));
            }
            let bad: Vec<&str> = flags
                .iter()
                .filter(|f| {
                    matches!(
                        f,
                        ResourceFlag::AllowUnorderedAccess
                            | ResourceFlag::AllowRenderTarget
                            | ResourceFlag::AllowDepthStencil
                    )
                })
                .map(|f| f.name())
                .collect();
            if !bad.is_empty() {
                self.diags.error(
                    "placement-heap-type",
                    &path.field("flags"),
                    format!(
                        "\"{}\" in an {} heap cannot have {}",
                        r.name,
                        heap_type.name(),
                        bad.join(", ")
                    ),
                );
            }
        }
        Some(placement)
    }
}
