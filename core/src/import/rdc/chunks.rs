//! Each RenderDoc chunk fed to the importer as the Vulkan calls it stands for. Most chunks are
//! one call whose parameters are matched to the registry's; some hold what Vulkan spreads over
//! several calls, or RenderDoc's own records, and are given as the calls an application would
//! have made:
//! - `vkEnumeratePhysicalDevices` carries the memory and queue family properties;
//! - `vkCreateImage`/`vkCreateBuffer` carry the memory requirements;
//! - `vkGetSwapchainImagesKHR` comes once per image;
//! - a descriptor set's initial contents are its descriptors as they stood when the frame
//!   began: they become the `vkUpdateDescriptorSets` that wrote them;
//! - device memory and image initial contents, and mapped-memory writes, go to the contents.

use std::collections::BTreeMap;

use super::super::HashMap;
use std::io::{Read, Seek};

use serde_json::{Map, Value, json};

use super::super::Importer;
use super::super::calls::Func;
use super::super::contents::Contents;
use super::super::gfxr::registry::{self, CommandDef};
use super::super::stream::Call;
use super::super::tree::Tree;
use super::args;
use super::errors::ChunkError;
use super::members::Members;
use super::xml::{Chunk, Node};

/// One binding of a descriptor set layout: its number, type and element count.
#[derive(Debug, Clone)]
struct LayoutBinding {
    binding: u32,
    ty: String,
    count: u32,
}

/// What reading the chunks needs to remember besides the importer's state.
pub struct Reader<R> {
    pub members: Members<R>,
    pub contents: Contents,
    set_layout: HashMap<u64, u64>,
    layouts: HashMap<u64, Vec<LayoutBinding>>,
    swapchain_images: HashMap<u64, BTreeMap<u32, u64>>,
    /// Chunks that are not calls, by what they are.
    pub other: BTreeMap<String, u64>,
    /// Chunks whose name no table knows, by name.
    pub unknown: BTreeMap<String, (u64, u64)>,
    pub in_frame: bool,
    pub frame_number: Option<u64>,
}

impl<R> std::fmt::Debug for Reader<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Reader")
            .field("in_frame", &self.in_frame)
            .finish_non_exhaustive()
    }
}

fn handle_of(node: Option<&Node>) -> Option<u64> {
    node.and_then(Node::u64)
}

impl<R: Read + Seek> Reader<R> {
    pub fn new(members: Members<R>) -> Self {
        Reader {
            members,
            contents: Contents::default(),
            set_layout: HashMap::default(),
            layouts: HashMap::default(),
            swapchain_images: HashMap::default(),
            other: BTreeMap::new(),
            unknown: BTreeMap::new(),
            in_frame: false,
            frame_number: None,
        }
    }

    fn count(&mut self, what: String) {
        *self.other.entry(what).or_default() += 1;
    }

    /// The bytes a `<buffer>` element points at.
    fn bytes(&mut self, node: &Node) -> Result<Vec<u8>, ChunkError> {
        let len = node.byte_length.ok_or(ChunkError::NoByteLength)?;
        Ok(self.members.bytes(&node.text, len)?)
    }

    /// Feeds one chunk to the importer. An error is a damaged file (a member missing or of
    /// the wrong size); a call the importer cannot use is left out by the importer itself.
    pub fn chunk(&mut self, imp: &mut Importer, chunk: &Chunk) -> Result<(), ChunkError> {
        let name = chunk.name.as_str();
        match name {
            "Internal::Initial Contents" => return self.initial_contents(imp, chunk),
            "Internal::Beginning of Capture" => {
                self.in_frame = true;
                self.count(format!("({name})"));
                return Ok(());
            }
            "Internal::End of Capture" => {
                imp.frame_end();
                self.count(format!("({name})"));
                return Ok(());
            }
            "Internal::Frame Metadata" => {
                self.frame_number = handle_of(chunk.root.child("frameNumber"));
                self.count(format!("({name})"));
                return Ok(());
            }
            "Internal::Coherent Mapped Memory Write"
            | "vkFlushMappedMemoryRanges"
            | "vkUnmapMemory" => {
                // Reported as the contents it wrote, not as a chunk that models nothing.
                self.mapped_write(imp, chunk)?;
                if name.starts_with("Internal") {
                    return Ok(());
                }
            }
            "vkEnumeratePhysicalDevices" => return self.physical_device(imp, chunk),
            "vkSetDebugUtilsObjectNameEXT" | "vkDebugMarkerSetObjectNameEXT" => {
                return self.object_name(imp, chunk);
            }
            "vkGetSwapchainImagesKHR" => return self.swapchain_image(imp, chunk),
            _ => {}
        }
        if name.starts_with("Internal::") {
            self.count(format!("({name})"));
            return Ok(());
        }
        let Some(def) = registry::command_named(name) else {
            let e = self
                .unknown
                .entry(name.to_owned())
                .or_insert((0, chunk.ordinal));
            e.0 += 1;
            return Ok(());
        };
        let func = Func::of(def.name);
        let args = {
            let mut load = |n: &Node| self.bytes(n);
            args::call_args(def, &chunk.root, &mut load)?
        };
        match func {
            Func::CreateShaderModule => {
                if let (Some(module), Some(code)) = (
                    args.get("pShaderModule").and_then(Value::as_u64),
                    chunk
                        .root
                        .child("CreateInfo")
                        .and_then(|c| c.child("pCode")),
                ) {
                    let bytes = self.bytes(code)?;
                    imp.pipelines.learn_module(module, &bytes);
                    self.contents.module(module, bytes);
                }
            }
            Func::CreateDescriptorSetLayout => self.set_layout_created(&args),
            Func::AllocateDescriptorSets => {
                let layouts = args.pointer("/pAllocateInfo/pSetLayouts");
                let sets = args.get("pDescriptorSets");
                if let (Some(Value::Array(l)), Some(Value::Array(s))) = (layouts, sets) {
                    for (set, layout) in s.iter().zip(l) {
                        if let (Some(s), Some(l)) = (set.as_u64(), layout.as_u64()) {
                            self.set_layout.insert(s, l);
                        }
                    }
                }
            }
            _ => {}
        }
        feed(imp, chunk, def, func, args);
        // RenderDoc keeps the memory requirements with the object; the importer reads them
        // from the query an application makes.
        if matches!(func, Func::CreateImage | Func::CreateBuffer)
            && let Some(req) = chunk.root.child("memoryRequirements")
        {
            let (key, query) = match func {
                Func::CreateImage => ("image", "vkGetImageMemoryRequirements"),
                _ => ("buffer", "vkGetBufferMemoryRequirements"),
            };
            let object = chunk.root.children.iter().find(|c| {
                c.name
                    .as_deref()
                    .is_some_and(|n| n.eq_ignore_ascii_case(key))
            });
            if let (Some(def), Some(object)) = (registry::command_named(query), handle_of(object)) {
                let mut load = |n: &Node| self.bytes(n);
                let req = args::value(req, None, &mut load)?;
                let args = json!({"device": 0, key: object, "pMemoryRequirements": req});
                feed(imp, chunk, def, Func::of(query), args);
            }
        }
        if imp.builder.last_submit.is_some() {
            self.contents.frozen = true;
        }
        Ok(())
    }

    fn set_layout_created(&mut self, args: &Value) {
        let Some(layout) = args.get("pSetLayout").and_then(Value::as_u64) else {
            return;
        };
        let mut bindings: Vec<LayoutBinding> = args
            .pointer("/pCreateInfo/pBindings")
            .and_then(Value::as_array)
            .map(|list| {
                list.iter()
                    .filter_map(|b| {
                        Some(LayoutBinding {
                            binding: u32::try_from(b.get("binding")?.as_u64()?).ok()?,
                            ty: b.get("descriptorType")?.as_str()?.to_owned(),
                            count: u32::try_from(b.get("descriptorCount")?.as_u64()?).ok()?,
                        })
                    })
                    .collect()
            })
            .unwrap_or_default();
        bindings.sort_by_key(|b| b.binding);
        self.layouts.insert(layout, bindings);
    }

    /// `vkEnumeratePhysicalDevices` with the device's memory and queue family properties,
    /// which an application reads with calls of their own.
    fn physical_device(&mut self, imp: &mut Importer, chunk: &Chunk) -> Result<(), ChunkError> {
        let root = &chunk.root;
        let device = handle_of(root.child("PhysicalDevice")).unwrap_or(0);
        let mut load = |n: &Node| self.bytes(n);
        if let (Some(props), Some(def)) = (
            root.child("memProps"),
            registry::command_named("vkGetPhysicalDeviceMemoryProperties"),
        ) {
            let p = args::value(props, None, &mut load)?;
            let args = json!({"physicalDevice": device, "pMemoryProperties": p});
            feed(imp, chunk, def, Func::MemoryProperties, args);
        }
        if let (Some(props), Some(def)) = (
            root.child("queueProps"),
            registry::command_named("vkGetPhysicalDeviceQueueFamilyProperties"),
        ) {
            let n = handle_of(root.child("queueCount")).unwrap_or(0) as usize;
            let mut list = match args::value(props, None, &mut load)? {
                Value::Array(a) => a,
                _ => Vec::new(),
            };
            list.truncate(n);
            let args = json!({
                "physicalDevice": device,
                "pQueueFamilyPropertyCount": list.len(),
                "pQueueFamilyProperties": list,
            });
            feed(imp, chunk, def, Func::QueueFamilyProperties, args);
        }
        Ok(())
    }

    /// An object's debug name: RenderDoc keeps the object and the name, not the structure
    /// the application passed.
    fn object_name(&mut self, imp: &mut Importer, chunk: &Chunk) -> Result<(), ChunkError> {
        let root = &chunk.root;
        let (Some(object), Some(name), Some(def)) = (
            handle_of(root.child("Object")),
            root.child("ObjectName"),
            registry::command_named(&chunk.name),
        ) else {
            return Ok(());
        };
        let key = if chunk.name == "vkSetDebugUtilsObjectNameEXT" {
            "objectHandle"
        } else {
            "object"
        };
        let args = json!({
            "device": 0,
            "pNameInfo": {key: object, "pObjectName": name.text},
        });
        feed(imp, chunk, def, Func::of(def.name), args);
        Ok(())
    }

    /// One swapchain image; the importer is given the swapchain's images so far, in order.
    fn swapchain_image(&mut self, imp: &mut Importer, chunk: &Chunk) -> Result<(), ChunkError> {
        let root = &chunk.root;
        let (Some(chain), Some(index), Some(image)) = (
            handle_of(root.child("Swapchain")),
            handle_of(root.child("SwapchainImageIndex")),
            handle_of(root.child("SwapchainImage")),
        ) else {
            return Err(ChunkError::SwapchainParts);
        };
        let images = self.swapchain_images.entry(chain).or_default();
        images.insert(index as u32, image);
        // Only a run of images from index 0 says which index each one has.
        if images.keys().copied().eq(0..images.len() as u32)
            && let Some(def) = registry::command_named("vkGetSwapchainImagesKHR")
        {
            let list: Vec<u64> = images.values().copied().collect();
            let args = json!({
                "device": handle_of(root.child("device")).unwrap_or(0),
                "swapchain": chain,
                "pSwapchainImageCount": list.len(),
                "pSwapchainImages": list,
            });
            feed(imp, chunk, def, Func::GetSwapchainImages, args);
        }
        Ok(())
    }

    /// Bytes the application wrote through a mapping: contents before the frame's first
    /// submission, the frame's own host writes after it.
    fn mapped_write(&mut self, imp: &mut Importer, chunk: &Chunk) -> Result<(), ChunkError> {
        let root = &chunk.root;
        let range = root.child("MemRange");
        let memory = handle_of(range.and_then(|r| r.child("memory")))
            .or_else(|| handle_of(root.child("memory")));
        let offset = handle_of(range.and_then(|r| r.child("offset")))
            .or_else(|| handle_of(root.child("MapOffset")))
            .or_else(|| handle_of(root.child("offset")));
        let data = root.children.iter().find(|c| c.tag == "buffer");
        let (Some(memory), Some(offset), Some(data)) = (memory, offset, data) else {
            return Ok(());
        };
        if data.byte_length == Some(0) {
            return Ok(());
        }
        let bytes = self.bytes(data)?;
        if self.contents.frozen {
            let contents = &self.contents;
            imp.host_write(memory, offset, &bytes, &|i| contents.linear_layout(i));
        } else {
            self.contents.fill(memory, offset, bytes);
        }
        Ok(())
    }

    /// A resource's contents when the frame began, or a descriptor set's descriptors.
    fn initial_contents(&mut self, imp: &mut Importer, chunk: &Chunk) -> Result<(), ChunkError> {
        let root = &chunk.root;
        let kind = root
            .child("type")
            .and_then(|t| t.string.clone())
            .unwrap_or_default();
        let id = handle_of(root.child("id")).ok_or(ChunkError::NoId)?;
        match kind.as_str() {
            "eResDeviceMemory" => {
                if root.child("IsSparse").is_some_and(|s| s.text == "true") {
                    return Ok(());
                }
                if let Some(c) = root.child("Contents") {
                    let bytes = self.bytes(c)?;
                    self.contents.init_memory(id, bytes);
                }
            }
            "eResImage" => {
                if root.child("IsSparse").is_some_and(|s| s.text == "true") {
                    return Ok(());
                }
                if let Some(c) = root.child("Contents") {
                    let bytes = self.bytes(c)?;
                    let len = bytes.len() as u64;
                    // RenderDoc saves every subresource, packed; which aspect is decided by
                    // the image's format when the contents are matched to it.
                    self.contents.init_image(id, 3, vec![len], bytes);
                }
            }
            "eResDescriptorSet" => self.descriptor_set(imp, chunk, id),
            _ => {}
        }
        Ok(())
    }

    /// A descriptor set's slots, one per array element of each binding in binding order,
    /// as the writes that put them there.
    fn descriptor_set(&mut self, imp: &mut Importer, chunk: &Chunk, set: u64) {
        let Some(slots) = chunk.root.child("Bindings") else {
            return;
        };
        let Some(bindings) = self
            .set_layout
            .get(&set)
            .and_then(|l| self.layouts.get(l))
            .cloned()
        else {
            imp.builder
                .note("descriptor set contents for a set whose layout the capture does not hold");
            return;
        };
        let expected: u64 = bindings.iter().map(|b| u64::from(b.count)).sum();
        if expected != slots.children.len() as u64 {
            imp.builder.note(format!(
                "descriptor set contents with {} slots where its layout has {expected}: left out",
                slots.children.len()
            ));
            return;
        }
        let mut writes = Vec::new();
        let mut slot = slots.children.iter();
        for b in &bindings {
            for element in 0..b.count {
                let Some(s) = slot.next() else { break };
                if let Some(w) = write_of(set, b, element, s) {
                    writes.push(w);
                }
            }
        }
        if writes.is_empty() {
            return;
        }
        if let Some(def) = registry::command_named("vkUpdateDescriptorSets") {
            let args = json!({
                "device": 0,
                "descriptorWriteCount": writes.len(),
                "pDescriptorWrites": writes,
                "descriptorCopyCount": 0,
                "pDescriptorCopies": [],
            });
            feed(imp, chunk, def, Func::UpdateDescriptorSets, args);
        }
    }
}

/// The write that puts one slot's descriptor in place; `None` for an empty slot.
fn write_of(set: u64, b: &LayoutBinding, element: u32, slot: &Node) -> Option<Value> {
    let resource = handle_of(slot.child("resource")).unwrap_or(0);
    let sampler = handle_of(slot.child("sampler")).unwrap_or(0);
    let kind = b.ty.trim_start_matches("VK_DESCRIPTOR_TYPE_");
    let mut w = Map::new();
    w.insert(
        "sType".into(),
        json!("VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET"),
    );
    w.insert("dstSet".into(), json!(set));
    w.insert("dstBinding".into(), json!(b.binding));
    w.insert("dstArrayElement".into(), json!(element));
    w.insert("descriptorCount".into(), json!(1));
    w.insert("descriptorType".into(), json!(b.ty));
    w.insert("pImageInfo".into(), json!([]));
    w.insert("pBufferInfo".into(), json!([]));
    w.insert("pTexelBufferView".into(), json!([]));
    match kind {
        "SAMPLER"
        | "COMBINED_IMAGE_SAMPLER"
        | "SAMPLED_IMAGE"
        | "STORAGE_IMAGE"
        | "INPUT_ATTACHMENT" => {
            if resource == 0 && sampler == 0 {
                return None;
            }
            let layout = slot
                .child("imageLayout")
                .and_then(|l| l.string.clone())
                .unwrap_or_else(|| "VK_IMAGE_LAYOUT_GENERAL".to_owned());
            w.insert(
                "pImageInfo".into(),
                json!([{"sampler": sampler, "imageView": resource, "imageLayout": layout}]),
            );
        }
        "UNIFORM_BUFFER"
        | "STORAGE_BUFFER"
        | "UNIFORM_BUFFER_DYNAMIC"
        | "STORAGE_BUFFER_DYNAMIC" => {
            if resource == 0 {
                return None;
            }
            let offset = handle_of(slot.child("offset")).unwrap_or(0);
            let range = handle_of(slot.child("range")).unwrap_or(u64::MAX);
            w.insert(
                "pBufferInfo".into(),
                json!([{"buffer": resource, "offset": offset, "range": range}]),
            );
        }
        "UNIFORM_TEXEL_BUFFER" | "STORAGE_TEXEL_BUFFER" => {
            if resource == 0 {
                return None;
            }
            w.insert("pTexelBufferView".into(), json!([resource]));
        }
        _ => return None,
    }
    Some(Value::Object(w))
}

/// Hands one call to the importer, numbered by the chunk it came from.
fn feed(imp: &mut Importer, chunk: &Chunk, def: &CommandDef, func: Func, args: Value) {
    let call = Call {
        line: chunk.ordinal,
        index: chunk.ordinal,
        name: std::borrow::Cow::Borrowed(def.name),
        func,
        args: Tree::from_json(&args),
        result: None,
        dialect: "renderdoc",
    };
    if imp.dialect.is_none() {
        imp.dialect = Some(call.dialect);
    }
    imp.call(&call);
}
