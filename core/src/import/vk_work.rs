//! What an imported draw or dispatch carries for the replay: the pipeline it bound (noted as
//! used, so the capture's `vulkan` section holds it) and its command state, with the
//! descriptors of its bound sets resolved to resource, image-view and sampler names.

use super::build::Builder;
use super::commands::Use;
use super::pipelines;
use super::state::{Descriptor, Objects};
use crate::capture::format::{VkCommandState, VkDescriptor, VkImageView};

impl Builder {
    /// The pipeline name and command state of a draw or dispatch.
    pub(super) fn vk_work(
        &mut self,
        objects: &Objects,
        pipeline: Option<u64>,
        state: &VkCommandState,
        uses: &[Use],
    ) -> (Option<String>, VkCommandState) {
        let name = pipeline.map(|p| {
            self.pipelines_used.insert(p);
            pipelines::pipeline_name(p)
        });
        let state = VkCommandState {
            descriptors: self.vk_descriptors(objects, uses),
            ..state.clone()
        };
        (name, state)
    }

    /// The descriptors a draw or dispatch can reach, by name, for the replay; the image views
    /// they name are kept for the `vulkan` section.
    fn vk_descriptors(&mut self, objects: &Objects, uses: &[Use]) -> Vec<VkDescriptor> {
        let mut out = Vec::new();
        for u in uses {
            let mut d = VkDescriptor {
                set: u.set,
                binding: u.binding,
                element: u.element,
                descriptor_type: String::new(),
                resource: None,
                view: None,
                sampler: None,
                offset: None,
                range: None,
                format: None,
            };
            match &u.descriptor {
                Descriptor::Sampler { sampler } => {
                    d.descriptor_type = "SAMPLER".to_owned();
                    d.sampler = Some(pipelines::sampler_name(*sampler));
                }
                // Neither a resource nor a view: the replay's stand-in reads zero.
                Descriptor::Null { ty, sampler } => {
                    d.descriptor_type = ty.to_string();
                    d.sampler = (*sampler != 0).then(|| pipelines::sampler_name(*sampler));
                }
                Descriptor::Image {
                    view, sampler, ty, ..
                } => {
                    d.descriptor_type = ty.to_string();
                    let (Some(v), Some((view_type, format, aspect))) =
                        (objects.views.get(view), objects.view_kinds.get(view))
                    else {
                        continue;
                    };
                    let Some(image) = self.resource(objects, v.image) else {
                        continue;
                    };
                    let name = format!("view_{view}");
                    self.views_used.entry(*view).or_insert_with(|| VkImageView {
                        name: name.clone(),
                        image: image.clone(),
                        view_type: view_type.clone(),
                        format: format.clone(),
                        aspect: *aspect as u32,
                        base_mip: v.base_mip,
                        mips: v.mip_count,
                        base_layer: v.base_layer,
                        layers: v.layer_count,
                        swizzle: objects.view_swizzles.get(view).cloned(),
                    });
                    d.resource = Some(image);
                    d.view = Some(name);
                    d.sampler = (*sampler != 0).then(|| pipelines::sampler_name(*sampler));
                }
                Descriptor::Buffer {
                    buffer,
                    offset,
                    range,
                    ty,
                } => {
                    d.descriptor_type = ty.to_string();
                    let Some(name) = self.resource(objects, *buffer) else {
                        continue;
                    };
                    d.resource = Some(name);
                    d.offset = Some(*offset);
                    d.range = Some(*range);
                }
                Descriptor::TexelBuffer { view, ty } => {
                    d.descriptor_type = ty.to_string();
                    let Some(&(buffer, offset, range)) = objects.buffer_views.get(view) else {
                        continue;
                    };
                    let Some(name) = self.resource(objects, buffer) else {
                        continue;
                    };
                    d.resource = Some(name);
                    d.offset = Some(offset);
                    d.range = Some(range);
                    d.format = objects.buffer_view_formats.get(view).cloned();
                }
            }
            out.push(d);
        }
        out
    }
}
