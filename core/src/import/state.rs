//! The Vulkan objects a stream creates, by handle: queues and their families, memory, images,
//! buffers, views, render passes, framebuffers, descriptor sets, swapchains and debug names.
//! Objects are kept after they are destroyed, since passes recorded before may still name them;
//! everything kept is a few words per object the stream created.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::OnceLock;

use super::HashMap;
use super::gfxr::registry;

use super::calls::{Func, Object};
use super::value::{
    ASPECTS, Arg, BUFFER_USAGE, Got, IMAGE_CREATE, IMAGE_USAGE, MEMORY_PROPERTIES, QUEUE_FLAGS,
    Skip,
};
use crate::capture::vulkan::{AccessFlags, ImageLayout, PipelineStages};

mod render_passes;
use render_passes::render_pass;

/// The longest debug name kept, in characters: names label every pass, barrier and file of
/// the capture, and a longer one says nothing more.
const MAX_NAME: usize = 256;

/// A debug name or label as the application gave it, made fit to name things in a capture:
/// control characters replaced, at most `MAX_NAME` characters.
pub fn debug_text(text: &str) -> String {
    text.chars()
        .take(MAX_NAME)
        .map(|c| if c.is_control() { '\u{fffd}' } else { c })
        .collect()
}

#[derive(Clone, Debug)]
pub struct ImageInfo {
    pub format: String,
    pub image_type: String,
    pub extent: [u32; 3],
    pub mips: u32,
    pub layers: u32,
    pub samples: u32,
    pub usage: u64,
    pub create_flags: u64,
    pub bound: Option<(u64, u64)>,
    pub alignment: Option<u64>,
    /// The swapchain (and image index) it belongs to.
    pub swapchain: Option<(u64, u32)>,
    /// Block index of the call that created it.
    pub created_at: u64,
    /// Block index of the call that destroyed it, if any.
    pub destroyed_at: Option<u64>,
}

#[derive(Clone, Debug)]
pub struct BufferInfo {
    /// Block index of the call that created it.
    pub created_at: u64,
    /// Block index of the call that destroyed it, if any.
    pub destroyed_at: Option<u64>,
    pub size: u64,
    pub usage: u64,
    pub bound: Option<(u64, u64)>,
    pub alignment: Option<u64>,
}

#[derive(Clone, Debug)]
pub struct MemoryInfo {
    pub size: u64,
    pub type_index: u32,
}

/// An image view: the image and the subresources it sees.
#[derive(Clone, Copy, Debug)]
pub struct ViewInfo {
    pub image: u64,
    pub base_mip: u32,
    pub mip_count: Option<u32>,
    pub base_layer: u32,
    pub layer_count: Option<u32>,
}

#[derive(Clone, Debug)]
pub struct AttachmentDesc {
    /// `VK_FORMAT_*`.
    pub format: String,
    pub load: String,
    pub store: String,
    pub stencil_load: String,
    pub stencil_store: String,
    /// `None`: a layout framelab does not know; no transition is derived for it.
    pub initial: Option<ImageLayout>,
    pub final_layout: Option<ImageLayout>,
}

#[derive(Clone, Debug, Default)]
pub struct SubpassDesc {
    pub colors: Vec<(u32, Option<ImageLayout>)>,
    /// Each of `colors`' index in `pColorAttachments`, unused entries counted.
    pub color_slots: Vec<u32>,
    /// Each of `resolves`' index in `pResolveAttachments`: the colour attachment it resolves.
    pub resolve_slots: Vec<u32>,
    pub resolves: Vec<(u32, Option<ImageLayout>)>,
    pub depth: Option<(u32, Option<ImageLayout>)>,
    pub inputs: Vec<(u32, Option<ImageLayout>)>,
}

/// A subpass dependency that involves VK_SUBPASS_EXTERNAL.
#[derive(Clone, Debug)]
pub struct Dependency {
    pub src_subpass: u32,
    pub dst_subpass: u32,
    pub src_stages: PipelineStages,
    pub dst_stages: PipelineStages,
    pub src_access: AccessFlags,
    pub dst_access: AccessFlags,
}

#[derive(Clone, Debug, Default)]
pub struct RenderPassInfo {
    pub attachments: Vec<AttachmentDesc>,
    pub subpasses: Vec<SubpassDesc>,
    pub dependencies: Vec<Dependency>,
}

#[derive(Clone, Debug)]
pub struct FramebufferInfo {
    pub attachments: Vec<u64>,
    pub layers: u32,
}

/// What an update template writes, entry by entry: each entry's index in the template with
/// the descriptors it writes, by (binding, array element).
pub type EntryWrites = Vec<(usize, Vec<((u32, u32), Descriptor)>)>;

/// One descriptor written to a set.
#[derive(Clone, Debug)]
pub enum Descriptor {
    Image {
        view: u64,
        /// The sampler of a combined image sampler (0 for none).
        sampler: u64,
        ty: Cow<'static, str>,
        /// The layout the descriptor says the image is in when the shader accesses it.
        layout: Option<ImageLayout>,
    },
    /// A sampler on its own (`VK_DESCRIPTOR_TYPE_SAMPLER`): no resource, but the draw
    /// samples with it.
    Sampler {
        sampler: u64,
    },
    Buffer {
        buffer: u64,
        offset: u64,
        range: u64,
        ty: Cow<'static, str>,
    },
    TexelBuffer {
        view: u64,
        ty: Cow<'static, str>,
    },
    /// `VK_NULL_HANDLE` written where a resource goes (the nullDescriptor feature of
    /// VK_EXT_robustness2): reads give zero and writes are discarded. It replaces what the
    /// slot held, where a slot never written holds nothing. A combined image sampler keeps
    /// its sampler (0 for none).
    Null {
        ty: Cow<'static, str>,
        sampler: u64,
    },
}

#[derive(Clone, Debug)]
pub struct SwapchainInfo {
    pub format: String,
    pub extent: [u32; 2],
    pub layers: u32,
    pub usage: u64,
}

#[derive(Default, Debug)]
pub struct Objects {
    /// Block index of the call being applied.
    pub at: u64,
    pub queue_family_flags: Vec<u64>,
    pub memory_type_flags: Vec<u64>,
    /// Queue handle -> (family, index).
    pub queues: BTreeMap<u64, (u32, u32)>,
    pub memories: HashMap<u64, MemoryInfo>,
    pub images: HashMap<u64, ImageInfo>,
    pub buffers: HashMap<u64, BufferInfo>,
    /// Memory -> the buffers ever bound to it (each host write looks only at these).
    pub buffers_in: HashMap<u64, Vec<u64>>,
    pub views: HashMap<u64, ViewInfo>,
    /// Image view -> (view type, format, aspect mask), for the replay's views.
    pub view_kinds: HashMap<u64, (String, String, u64)>,
    /// Views whose components are not the identity, as `RRRG` (`0`, `1` for the constants).
    pub view_swizzles: HashMap<u64, String>,
    /// Texel buffer views -> (buffer, offset, range).
    pub buffer_views: HashMap<u64, (u64, u64, u64)>,
    /// Buffer view -> its `VK_FORMAT_*` (a uniform texel buffer's texels are read in it).
    pub buffer_view_formats: HashMap<u64, String>,
    pub render_passes: HashMap<u64, RenderPassInfo>,
    pub framebuffers: HashMap<u64, FramebufferInfo>,
    pub sets: HashMap<u64, BTreeMap<(u32, u32), Descriptor>>,
    /// Pipeline layout -> its compatibility id per set (`Pipelines::compat_ids`).
    pub layout_compat: HashMap<u64, std::sync::Arc<[u64]>>,
    /// Descriptor update templates: their entries, and for push templates the bind point.
    pub templates: HashMap<u64, Template>,
    pub swapchains: HashMap<u64, SwapchainInfo>,
    pub swapchain_images: HashMap<u64, Vec<u64>>,
    pub names: HashMap<u64, String>,
    /// Memory the application mapped (its buffers hold what the CPU wrote).
    pub mapped: std::collections::HashSet<u64>,
    /// Images and buffers created with `VK_SHARING_MODE_CONCURRENT`: any queue family may
    /// use them without an ownership transfer.
    pub concurrent: std::collections::HashSet<u64>,
    /// Timeline semaphores.
    pub timeline: std::collections::HashSet<u64>,
    /// Whether the device enabled `VK_EXT_depth_range_unrestricted` (depth values outside
    /// [0, 1] allowed).
    pub depth_range_unrestricted: bool,
    /// The extensions the instance and the devices enabled, and whether the stream created
    /// its instance (before that, nothing is known to be enabled or not).
    pub extensions: std::collections::HashSet<String>,
    pub instance_created: bool,
    /// Whether the device enabled the `synchronization2` feature: a barrier from a layout to
    /// itself is then no transition and its layouts are ignored.
    pub synchronization2: bool,
    /// Whether the device enabled the `nullDescriptor` feature (VK_EXT_robustness2): a null
    /// descriptor is then valid where a shader uses it.
    pub null_descriptor: bool,
    /// What the device allows its SPIR-V, as the validator's options.
    pub spirv: super::valid_usage_spirv::Rules,
    /// The device the capture was made on, where the capture says and framelab knows it.
    pub device: super::driver_layout::DriverLayout,
}

/// Whether a create info asks for `VK_SHARING_MODE_CONCURRENT` (by name or value).
fn concurrent(ci: &Arg<'_>) -> bool {
    // Read as text (a number comes back as its digits), so that neither spelling takes the
    // error path of the other.
    ci.opt("sharingMode").is_some_and(|m| {
        m.symbol()
            .is_ok_and(|n| n == "1" || n.ends_with("CONCURRENT"))
    })
}

/// A sample count, by name (`VK_SAMPLE_COUNT_4_BIT`) or value.
pub(super) fn samples(a: &Arg<'_>) -> Got<u32> {
    let name = a.symbol()?;
    name.trim_start_matches("VK_SAMPLE_COUNT_")
        .trim_end_matches("_BIT")
        .parse::<u32>()
        .map(|v| v.max(1))
        .map_err(|_| Skip(format!("`{}`: unknown sample count {name}", a.path())))
}

/// A `levelCount`/`layerCount` where VK_REMAINING_* (all ones) means "to the end".
fn count(a: &Arg<'_>) -> Got<Option<u32>> {
    let v = a.u64()?;
    Ok((v < u64::from(u32::MAX)).then_some(v as u32))
}

impl Objects {
    /// Updates the objects from one call; `Ok(false)` when the call creates or describes
    /// nothing this tracks.
    pub fn apply(&mut self, func: Func, args: &Arg<'_>) -> Got<bool> {
        match func {
            Func::QueueFamilyProperties => self.queue_families(args)?,
            Func::MemoryProperties => self.memory_types(args)?,
            Func::GetDeviceQueue => {
                let q = args.get("pQueue")?.handle()?;
                let family = args.get("queueFamilyIndex")?.u32()?;
                let index = args.get("queueIndex")?.u32()?;
                self.queues.insert(q, (family, index));
            }
            Func::GetDeviceQueue2 => {
                let info = args.get("pQueueInfo")?;
                let q = args.get("pQueue")?.handle()?;
                let family = info.get("queueFamilyIndex")?.u32()?;
                let index = info.get("queueIndex")?.u32()?;
                self.queues.insert(q, (family, index));
            }
            Func::AllocateMemory => {
                let info = args.get("pAllocateInfo")?;
                let mem = args.get("pMemory")?.handle()?;
                self.memories.insert(
                    mem,
                    MemoryInfo {
                        size: info.get("allocationSize")?.u64()?,
                        type_index: info.get("memoryTypeIndex")?.u32()?,
                    },
                );
            }
            Func::CreateImage => self.create_image(args)?,
            Func::CreateInstance | Func::CreateDevice => self.create_instance(func, args)?,
            Func::CreateBuffer => self.create_buffer(args)?,
            Func::MemoryRequirements(object) => self.memory_requirements(object, args)?,
            Func::BindMemory(object) => {
                let handle = args.get(object.key())?.handle()?;
                let memory = args.get("memory")?.handle()?;
                let offset = args.get("memoryOffset")?.u64()?;
                self.bind(handle, memory, offset);
            }
            Func::BindMemory2(object) => {
                for info in args.list("pBindInfos")? {
                    let handle = info.get(object.key())?.handle()?;
                    let memory = info.get("memory")?.handle()?;
                    let offset = info.get("memoryOffset")?.u64()?;
                    self.bind(handle, memory, offset);
                }
            }
            Func::CreateImageView => self.create_image_view(args)?,
            Func::CreateBufferView => self.create_buffer_view(args)?,
            Func::CreateRenderPass => {
                let ci = args.get("pCreateInfo")?;
                let rp = render_pass(&ci)?;
                self.render_passes
                    .insert(args.get("pRenderPass")?.handle()?, rp);
            }
            Func::CreateFramebuffer => self.create_framebuffer(args)?,
            Func::AllocateDescriptorSets => {
                for s in args.list("pDescriptorSets")? {
                    self.sets.insert(s.handle()?, BTreeMap::new());
                }
            }
            Func::UpdateDescriptorSets => self.update_descriptor_sets(args)?,
            Func::CreateDescriptorUpdateTemplate => self.create_template(args)?,
            Func::UpdateDescriptorSetWithTemplate => {
                let set = args.get("descriptorSet")?.handle()?;
                let template = args.get("descriptorUpdateTemplate")?.handle()?;
                let written = self.template_writes(template, &args.get("pData")?)?;
                self.sets.entry(set).or_default().extend(written);
            }
            Func::CreateSwapchain => self.create_swapchain(args)?,
            Func::CreateSemaphore => self.create_semaphore(args)?,
            Func::GetSwapchainImages => self.swapchain_images(args)?,
            Func::SetDebugUtilsObjectName => {
                let info = args.get("pNameInfo")?;
                let handle = info.get("objectHandle")?.handle()?;
                let name = match info.opt("pObjectName") {
                    Some(n) => n.str()?,
                    None => "",
                };
                self.name(handle, name);
            }
            Func::DebugMarkerSetObjectName => {
                let info = args.get("pNameInfo")?;
                let handle = info.get("object")?.handle()?;
                self.name(handle, info.get("pObjectName")?.str()?);
            }
            Func::Destroy(Object::Image) => {
                if let Some(i) = self.images.get_mut(&args.get("image")?.handle()?) {
                    i.destroyed_at = Some(self.at);
                }
            }
            Func::Destroy(Object::Buffer) => {
                if let Some(b) = self.buffers.get_mut(&args.get("buffer")?.handle()?) {
                    b.destroyed_at = Some(self.at);
                }
            }
            Func::MapMemory => {
                let memory = match args.opt("pMemoryMapInfo") {
                    Some(info) => info.get("memory")?.handle()?,
                    None => args.get("memory")?.handle()?,
                };
                self.mapped.insert(memory);
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// `vkCreateInstance` or `vkCreateDevice`: the extensions, the API version and the
    /// features enabled.
    fn create_instance(&mut self, func: Func, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        for n in ci.list("ppEnabledExtensionNames").unwrap_or_default() {
            if let Ok(name) = n.str() {
                self.extensions.insert(name.to_owned());
            }
        }
        self.instance_created |= func == Func::CreateInstance;
        self.depth_range_unrestricted = self.extensions.contains("VK_EXT_depth_range_unrestricted");
        self.spirv.spirv_1_4 = self.extensions.contains("VK_KHR_spirv_1_4");
        if func == Func::CreateInstance {
            let version = ci
                .opt("pApplicationInfo")
                .and_then(|a| a.opt("apiVersion"))
                .and_then(|v| v.u64().ok())
                .unwrap_or(0);
            // VK_API_VERSION_MINOR.
            self.spirv.api_minor = ((version >> 12) & 0x3ff) as u32;
        }
        // Features in their own structures or in VkPhysicalDeviceVulkan1xFeatures.
        let mut next = ci.opt("pNext");
        let on = |n: &Arg<'_>, member: &str| {
            n.opt(member)
                .and_then(|v| v.u64().ok())
                .is_some_and(|v| v != 0)
        };
        while let Some(n) = next {
            if on(&n, "synchronization2") {
                self.synchronization2 = true;
            }
            if on(&n, "nullDescriptor") {
                self.null_descriptor = true;
            }
            for feature in super::valid_usage_spirv::Rules::FEATURES {
                if on(&n, feature) {
                    self.spirv.enable(feature);
                }
            }
            next = n.opt("pNext");
        }
        Ok(())
    }

    fn create_buffer_view(&mut self, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        let view = args.get("pView")?.handle()?;
        self.buffer_view_formats
            .insert(view, ci.get("format")?.name()?);
        self.buffer_views.insert(
            view,
            (
                ci.get("buffer")?.handle()?,
                ci.get("offset")?.u64()?,
                ci.get("range")?.u64()?,
            ),
        );
        Ok(())
    }

    fn create_framebuffer(&mut self, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        let attachments = ci
            .list("pAttachments")?
            .iter()
            .map(Arg::handle)
            .collect::<Got<_>>()?;
        let layers = ci.opt("layers").and_then(|l| l.u32().ok()).unwrap_or(1);
        self.framebuffers.insert(
            args.get("pFramebuffer")?.handle()?,
            FramebufferInfo {
                attachments,
                layers,
            },
        );
        Ok(())
    }

    fn create_template(&mut self, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        let entries = ci
            .list("pDescriptorUpdateEntries")?
            .iter()
            .map(|e| {
                Ok(TemplateEntry {
                    binding: e.get("dstBinding")?.u32()?,
                    element: e.get("dstArrayElement")?.u32()?,
                    count: e.get("descriptorCount")?.u32()?,
                    ty: e.get("descriptorType")?.name()?,
                })
            })
            .collect::<Got<_>>()?;
        let compute = ci
            .opt("pipelineBindPoint")
            .and_then(|p| p.name().ok())
            .is_some_and(|n| n.contains("COMPUTE") || n == "1");
        self.templates.insert(
            args.get("pDescriptorUpdateTemplate")?.handle()?,
            Template { entries, compute },
        );
        Ok(())
    }

    fn create_semaphore(&mut self, args: &Arg<'_>) -> Got<()> {
        // VkSemaphoreTypeCreateInfo in the chain: timeline semaphores are waited on by
        // value, binary ones by their last signal.
        let mut next = args.get("pCreateInfo")?.opt("pNext");
        while let Some(n) = next {
            if n.opt("semaphoreType").is_some_and(|t| {
                t.symbol()
                    .is_ok_and(|n| n == "1" || n.ends_with("TIMELINE"))
            }) {
                self.timeline.insert(args.get("pSemaphore")?.handle()?);
            }
            next = n.opt("pNext");
        }
        Ok(())
    }

    /// An object's debug name, cleaned by `debug_text` (the capture format refuses control
    /// characters); an empty name removes the object's name, as it does in Vulkan.
    fn name(&mut self, handle: u64, name: &str) {
        let clean = debug_text(name);
        if clean.trim().is_empty() {
            self.names.remove(&handle);
        } else {
            self.names.insert(handle, clean);
        }
    }

    fn queue_families(&mut self, args: &Arg<'_>) -> Got<()> {
        let list = args.list("pQueueFamilyProperties")?;
        if !list.is_empty() {
            self.queue_family_flags = list
                .iter()
                .map(|p| {
                    let inner = p.opt("queueFamilyProperties").unwrap_or(*p);
                    inner.get("queueFlags")?.flags(QUEUE_FLAGS)
                })
                .collect::<Got<_>>()?;
        }
        Ok(())
    }

    fn memory_types(&mut self, args: &Arg<'_>) -> Got<()> {
        let p = args.get("pMemoryProperties")?;
        let p = p.opt("memoryProperties").unwrap_or(p);
        let n = p.get("memoryTypeCount")?.u64()? as usize;
        let types = p.get("memoryTypes")?.items()?;
        self.memory_type_flags = types
            .iter()
            .take(n)
            .map(|t| t.get("propertyFlags")?.flags(MEMORY_PROPERTIES))
            .collect::<Got<_>>()?;
        Ok(())
    }

    fn create_buffer(&mut self, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        let buffer = args.get("pBuffer")?.handle()?;
        if concurrent(&ci) {
            self.concurrent.insert(buffer);
        }
        self.buffers.insert(
            buffer,
            BufferInfo {
                created_at: self.at,
                destroyed_at: None,
                size: ci.get("size")?.u64()?,
                usage: ci.get("usage")?.flags(BUFFER_USAGE)?,
                bound: None,
                alignment: None,
            },
        );
        Ok(())
    }

    fn create_image(&mut self, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        let extent = ci.get("extent")?;
        let image = args.get("pImage")?.handle()?;
        if concurrent(&ci) {
            self.concurrent.insert(image);
        }
        let info = ImageInfo {
            format: ci.get("format")?.name()?,
            image_type: ci.get("imageType")?.name()?,
            extent: [
                extent.get("width")?.u32()?,
                extent.get("height")?.u32()?,
                extent.get("depth")?.u32()?,
            ],
            mips: ci.get("mipLevels")?.u32()?,
            layers: ci.get("arrayLayers")?.u32()?,
            samples: samples(&ci.get("samples")?)?,
            usage: ci.get("usage")?.flags(IMAGE_USAGE)?,
            create_flags: ci.opt("flags").map_or(Ok(0), |f| f.flags(IMAGE_CREATE))?,
            bound: None,
            alignment: None,
            swapchain: None,
            created_at: self.at,
            destroyed_at: None,
        };
        self.images.insert(image, info);
        Ok(())
    }

    fn memory_requirements(&mut self, object: Object, args: &Arg<'_>) -> Got<()> {
        let (handle, req) = match args.opt("pInfo") {
            Some(info) => {
                let req = args.get("pMemoryRequirements")?;
                let req = req.opt("memoryRequirements").unwrap_or(req);
                (info.get(object.key())?.handle()?, req)
            }
            None => (
                args.get(object.key())?.handle()?,
                args.get("pMemoryRequirements")?,
            ),
        };
        let alignment = req.get("alignment")?.u64()?;
        if let Some(i) = self.images.get_mut(&handle) {
            i.alignment = Some(alignment);
        } else if let Some(b) = self.buffers.get_mut(&handle) {
            b.alignment = Some(alignment);
        }
        Ok(())
    }

    fn create_image_view(&mut self, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        let range = ci.get("subresourceRange")?;
        let aspect = range.get("aspectMask")?.flags(ASPECTS)?;
        let view = args.get("pView")?.handle()?;
        let swizzle = swizzle(&ci)?;
        if swizzle != "RGBA" {
            self.view_swizzles.insert(view, swizzle);
        } else {
            self.view_swizzles.remove(&view);
        }
        self.view_kinds.insert(
            view,
            (
                ci.get("viewType")?.name()?,
                ci.get("format")?.name()?,
                aspect,
            ),
        );
        self.views.insert(
            view,
            ViewInfo {
                image: ci.get("image")?.handle()?,
                base_mip: range.get("baseMipLevel")?.u32()?,
                mip_count: count(&range.get("levelCount")?)?,
                base_layer: range.get("baseArrayLayer")?.u32()?,
                layer_count: count(&range.get("layerCount")?)?,
            },
        );
        Ok(())
    }

    fn update_descriptor_sets(&mut self, args: &Arg<'_>) -> Got<()> {
        for w in args.list("pDescriptorWrites")? {
            let set = w.get("dstSet")?.handle()?;
            let written = descriptor_writes(&w)?;
            let entry = self.sets.entry(set).or_default();
            for (key, d) in written {
                entry.insert(key, d);
            }
        }
        for c in args.list("pDescriptorCopies")? {
            let (src, dst) = (c.get("srcSet")?.handle()?, c.get("dstSet")?.handle()?);
            let (sb, se) = (
                c.get("srcBinding")?.u32()?,
                c.get("srcArrayElement")?.u32()?,
            );
            let (db, de) = (
                c.get("dstBinding")?.u32()?,
                c.get("dstArrayElement")?.u32()?,
            );
            let n = c.get("descriptorCount")?.u32()?;
            let copied: Vec<_> = (0..n.min(4096))
                .filter_map(|k| {
                    let d = self
                        .sets
                        .get(&src)?
                        .get(&(sb, se.saturating_add(k)))?
                        .clone();
                    Some(((db, de.saturating_add(k)), d))
                })
                .collect();
            let entry = self.sets.entry(dst).or_default();
            entry.extend(copied);
        }
        Ok(())
    }

    fn create_swapchain(&mut self, args: &Arg<'_>) -> Got<()> {
        let ci = args.get("pCreateInfo")?;
        let extent = ci.get("imageExtent")?;
        self.swapchains.insert(
            args.get("pSwapchain")?.handle()?,
            SwapchainInfo {
                format: ci.get("imageFormat")?.name()?,
                extent: [extent.get("width")?.u32()?, extent.get("height")?.u32()?],
                layers: ci.get("imageArrayLayers")?.u32()?,
                usage: ci.get("imageUsage")?.flags(IMAGE_USAGE)?,
            },
        );
        Ok(())
    }

    /// Swapchain images become images of their own, described by their swapchain.
    fn swapchain_images(&mut self, args: &Arg<'_>) -> Got<()> {
        let chain = args.get("swapchain")?.handle()?;
        let images: Vec<u64> = args
            .list("pSwapchainImages")?
            .iter()
            .map(Arg::handle)
            .collect::<Got<_>>()?;
        // The count query (no images yet) describes nothing.
        if images.is_empty() {
            return Ok(());
        }
        let sc = self
            .swapchains
            .get(&chain)
            .cloned()
            .ok_or_else(|| Skip(format!("swapchain {chain} was never created")))?;
        for (i, &img) in images.iter().enumerate() {
            self.images.insert(
                img,
                ImageInfo {
                    format: sc.format.clone(),
                    image_type: "VK_IMAGE_TYPE_2D".to_owned(),
                    extent: [sc.extent[0], sc.extent[1], 1],
                    mips: 1,
                    layers: sc.layers.max(1),
                    samples: 1,
                    usage: sc.usage,
                    create_flags: 0,
                    bound: None,
                    alignment: None,
                    swapchain: Some((chain, i as u32)),
                    created_at: self.at,
                    destroyed_at: None,
                },
            );
        }
        self.swapchain_images.insert(chain, images);
        Ok(())
    }

    fn bind(&mut self, handle: u64, memory: u64, offset: u64) {
        if let Some(i) = self.images.get_mut(&handle) {
            i.bound = Some((memory, offset));
        } else if let Some(b) = self.buffers.get_mut(&handle) {
            b.bound = Some((memory, offset));
            self.buffers_in.entry(memory).or_default().push(handle);
        }
    }
}

/// One entry of a descriptor update template.
#[derive(Clone, Debug)]
pub struct TemplateEntry {
    pub binding: u32,
    pub element: u32,
    pub count: u32,
    pub ty: String,
}

#[derive(Clone, Debug)]
pub struct Template {
    pub entries: Vec<TemplateEntry>,
    /// A push template's bind point is compute.
    pub compute: bool,
}

/// Which list of a write holds a descriptor type's data: image infos (samplers included),
/// buffer infos or texel buffer views. `None` for types that reach no resource framelab
/// models (acceleration structures, inline uniform blocks).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Holds {
    Images = 0,
    Buffers = 1,
    TexelViews = 2,
}

impl Holds {
    /// `kind` is the type as `descriptor_kind` gives it.
    pub(super) fn of(kind: &str) -> Option<Holds> {
        match kind {
            "SAMPLER"
            | "COMBINED_IMAGE_SAMPLER"
            | "SAMPLED_IMAGE"
            | "STORAGE_IMAGE"
            | "INPUT_ATTACHMENT" => Some(Holds::Images),
            "UNIFORM_BUFFER"
            | "STORAGE_BUFFER"
            | "UNIFORM_BUFFER_DYNAMIC"
            | "STORAGE_BUFFER_DYNAMIC" => Some(Holds::Buffers),
            "UNIFORM_TEXEL_BUFFER" | "STORAGE_TEXEL_BUFFER" => Some(Holds::TexelViews),
            _ => None,
        }
    }

    /// The member of a VkWriteDescriptorSet holding the list.
    fn key(self) -> &'static str {
        match self {
            Holds::Images => "pImageInfo",
            Holds::Buffers => "pBufferInfo",
            Holds::TexelViews => "pTexelBufferView",
        }
    }
}

/// Whether a descriptor type (as `descriptor_kind` gives it) lets a shader write: storage
/// images, buffers and texel buffers.
pub fn storage_descriptor(kind: &str) -> bool {
    matches!(
        kind,
        "STORAGE_IMAGE" | "STORAGE_BUFFER" | "STORAGE_BUFFER_DYNAMIC" | "STORAGE_TEXEL_BUFFER"
    )
}

/// A descriptor type as every descriptor holds it and everything that reads one compares it:
/// without `VK_DESCRIPTOR_TYPE_`, a value given as a number named, and borrowed from the
/// registry's `VkDescriptorType` where it is one (a frame binds thousands of descriptors).
/// A type the registry does not know stays as it was spelt.
pub fn descriptor_kind(ty: &str) -> Cow<'static, str> {
    static TYPES: OnceLock<Vec<(i32, &'static str)>> = OnceLock::new();
    let types = TYPES.get_or_init(|| {
        registry::enum_named("VkDescriptorType").map_or_else(Vec::new, |e| {
            e.values
                .iter()
                .filter_map(|(v, n)| Some((*v, n.strip_prefix("VK_DESCRIPTOR_TYPE_")?)))
                .collect()
        })
    });
    let kind = ty.trim_start_matches("VK_DESCRIPTOR_TYPE_");
    let value = kind.parse::<i32>().ok();
    types
        .iter()
        .find(|(v, n)| *n == kind || Some(*v) == value)
        .map_or_else(|| Cow::Owned(kind.to_owned()), |(_, n)| Cow::Borrowed(*n))
}

/// The descriptors one VkWriteDescriptorSet writes, by (binding, array element).
pub fn descriptor_writes(w: &Arg<'_>) -> Got<Vec<((u32, u32), Descriptor)>> {
    let binding = w.get("dstBinding")?.u32()?;
    let first = w.get("dstArrayElement")?.u32()?;
    let kind = descriptor_kind(&w.get("descriptorType")?.symbol()?);
    match Holds::of(&kind) {
        Some(holds) => descriptors(binding, first, &kind, &w.list(holds.key())?),
        None => Ok(Vec::new()),
    }
}

/// The descriptors of type `kind` that `items` (the list `Holds::of(kind)` names) put at
/// `binding` from element `first` on; a null handle writes a null descriptor (a null sampler
/// nothing: no feature allows one).
// The `Cow` itself, not its text, so that a type borrowed from the tables stays borrowed in
// every descriptor.
#[allow(clippy::ptr_arg)]
pub(super) fn descriptors(
    binding: u32,
    first: u32,
    kind: &Cow<'static, str>,
    items: &[Arg<'_>],
) -> Got<Vec<((u32, u32), Descriptor)>> {
    let mut out = Vec::new();
    for (k, i) in items.iter().enumerate() {
        let at = (binding, first.saturating_add(k as u32));
        let descriptor = match Holds::of(kind) {
            Some(Holds::Images) if kind == "SAMPLER" => {
                let sampler = i.get("sampler")?.handle()?;
                (sampler != 0).then_some(Descriptor::Sampler { sampler })
            }
            Some(Holds::Images) => {
                let view = i.get("imageView")?.handle()?;
                let sampler = if kind == "COMBINED_IMAGE_SAMPLER" {
                    i.get("sampler")?.handle()?
                } else {
                    0
                };
                Some(if view == 0 {
                    Descriptor::Null {
                        ty: kind.clone(),
                        sampler,
                    }
                } else {
                    Descriptor::Image {
                        view,
                        sampler,
                        ty: kind.clone(),
                        layout: i.opt("imageLayout").and_then(|l| l.layout().ok()),
                    }
                })
            }
            Some(Holds::Buffers) => {
                let buffer = i.get("buffer")?.handle()?;
                if buffer == 0 {
                    Some(Descriptor::Null {
                        ty: kind.clone(),
                        sampler: 0,
                    })
                } else {
                    Some(Descriptor::Buffer {
                        buffer,
                        offset: i.get("offset")?.u64()?,
                        range: i.get("range")?.u64()?,
                        ty: kind.clone(),
                    })
                }
            }
            Some(Holds::TexelViews) => {
                let view = i.handle()?;
                Some(if view == 0 {
                    Descriptor::Null {
                        ty: kind.clone(),
                        sampler: 0,
                    }
                } else {
                    Descriptor::TexelBuffer {
                        view,
                        ty: kind.clone(),
                    }
                })
            }
            None => None,
        };
        out.extend(descriptor.map(|d| (at, d)));
    }
    Ok(out)
}

/// A view's `components` as four letters: the channel each of R, G, B and A reads (`0` and `1`
/// for the constants); `RGBA` is the identity.
fn swizzle(ci: &Arg<'_>) -> Got<String> {
    let Some(c) = ci.opt("components") else {
        return Ok("RGBA".to_owned());
    };
    let mut out = String::new();
    for (own, key) in ['R', 'G', 'B', 'A'].into_iter().zip(["r", "g", "b", "a"]) {
        let name = c.get(key)?.name()?;
        out.push(match name.trim_start_matches("VK_COMPONENT_SWIZZLE_") {
            "R" => 'R',
            "G" => 'G',
            "B" => 'B',
            "A" => 'A',
            "ZERO" => '0',
            "ONE" => '1',
            // IDENTITY (and any value the registry adds later) reads the channel's own.
            _ => own,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descriptor_types_are_held_by_name_however_the_stream_spells_them() {
        for spelt in ["VK_DESCRIPTOR_TYPE_STORAGE_BUFFER", "STORAGE_BUFFER", "7"] {
            let kind = descriptor_kind(spelt);
            assert_eq!(kind, "STORAGE_BUFFER", "{spelt}");
            assert!(matches!(kind, Cow::Borrowed(_)), "{spelt}");
            assert!(storage_descriptor(&kind));
            assert!(matches!(Holds::of(&kind), Some(Holds::Buffers)));
        }
        assert_eq!(descriptor_kind("1"), "COMBINED_IMAGE_SAMPLER");
        assert!(!storage_descriptor(&descriptor_kind("6")));
        // Not in the registry: kept as spelt, holding nothing framelab reads.
        assert_eq!(descriptor_kind("VK_DESCRIPTOR_TYPE_MADE_UP"), "MADE_UP");
        assert!(Holds::of(&descriptor_kind("12345")).is_none());
    }
}
