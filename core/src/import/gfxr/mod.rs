//! `framelab import app.gfxr`: GFXReconstruct's binary capture read directly, block by block.
//!
//! Function calls are decoded through tables generated from the Vulkan registry into the
//! same JSON arguments `gfxrecon-convert` writes, and fed to the same importer as a JSON
//! Lines stream, so both routes give the same passes, resources and barriers. What only the
//! binary file holds comes on top: the SPIR-V of every shader module and the memory contents
//! (mapped-memory writes, a trimmed capture's buffer and image snapshot), which the import
//! writes as side files beside the capture.

mod blocks;
mod compress;
mod decode;
pub mod edit;
mod meta;
pub(crate) mod registry;
#[rustfmt::skip]
#[allow(clippy::all, clippy::pedantic)]
pub(crate) mod tables;

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Read;

use super::calls::{CmdFunc, Func};
use super::commands::Origin;
use super::contents::Contents;
use super::state::Objects;
use super::stream::Call;
use super::tree::Tree;
use super::value::Arg;
use super::{ImportError, ImportOptions, Imported, Importer};
use crate::capture::vulkan::ImageLayout;
use blocks::{Block, Blocks, Kind};
pub use blocks::{MAX_BLOCK_BYTES, is_gfxr};
use meta::{Fills, Meta, NoRoom};

/// What reading the blocks gathered besides the importer's own state.
struct Reading {
    tool: String,
    blocks: u64,
    other: BTreeMap<String, u64>,
    /// Calls whose id no table knows, by id.
    unknown_ids: BTreeMap<u32, (u64, u64)>,
    /// The arguments of the call being imported; kept from call to call for its storage.
    args: Tree,
}

fn located(file: &str, at: blocks::At, problem: impl std::fmt::Display) -> ImportError {
    ImportError::Block {
        file: file.to_owned(),
        block: at.block,
        offset: at.offset,
        message: problem.to_string(),
    }
}

fn block_error(file: &str, e: blocks::BlockError) -> ImportError {
    match e.at {
        Some(at) => located(file, at, e.message),
        None => ImportError::Stream {
            file: file.to_owned(),
            message: format!("file header: {}", e.message),
        },
    }
}

impl Reading {
    fn count(&mut self, what: impl Into<String>) {
        *self.other.entry(what.into()).or_default() += 1;
    }

    /// The capture tool's version from the capture's `operation` annotation.
    fn annotation(&mut self, block: &Block) {
        let b = &block.body;
        if b.len() < 12 {
            return;
        }
        let label_len = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
        let rest = &b[12..];
        if label_len > rest.len() {
            return;
        }
        let (label, data) = rest.split_at(label_len);
        if label == b"operation"
            && let Ok(v) = serde_json::from_slice::<serde_json::Value>(data)
            && let Some(version) = v.get("gfxrecon-version").and_then(|x| x.as_str())
        {
            self.tool = format!(
                "GFXReconstruct {}",
                crate::import::state::debug_text(version)
            );
        }
    }
}

/// Whether the capture made room for a compressed payload before it is decompressed: memory
/// is filled within its allocation, and a resource's contents fit in the memory bound to it
/// (or, not bound yet, in all the memory allocated), so a small block cannot claim gigabytes
/// nothing backs.
fn room(objects: &Objects, fills: Fills) -> Result<(), NoRoom> {
    let size = fills.size();
    let (what, bound) = match fills {
        Fills::Memory { memory, offset, .. } => {
            let Some(m) = objects.memories.get(&memory) else {
                return Err(NoRoom::MemoryNeverAllocated { size, memory });
            };
            if offset.checked_add(size).is_none_or(|end| end > m.size) {
                return Err(NoRoom::PastMemory {
                    size,
                    offset,
                    memory,
                    holds: m.size,
                });
            }
            return Ok(());
        }
        Fills::Buffer { buffer, .. } => (
            format!("buffer {buffer:#x}"),
            objects.buffers.get(&buffer).map(|b| b.bound),
        ),
        Fills::Image { image, .. } => (
            format!("image {image:#x}"),
            objects.images.get(&image).map(|i| i.bound),
        ),
    };
    let Some(bound) = bound else {
        return Err(NoRoom::NeverCreated { size, what });
    };
    let (holds, there) =
        match bound.and_then(|(m, at)| Some(objects.memories.get(&m)?.size.saturating_sub(at))) {
            Some(n) => (n, "the memory bound to it"),
            None => (
                objects.memories.values().map(|m| m.size).sum(),
                "all the device memory the capture allocated",
            ),
        };
    if size > holds {
        return Err(NoRoom::PastBound {
            size,
            what,
            holds,
            there,
        });
    }
    Ok(())
}

/// Calls the importer does not model but the binary route reads for what only it holds.
fn binary_only(name: &str) -> bool {
    matches!(
        name,
        "vkCreateShaderModule"
            | "vkFreeMemory"
            | "vkMapMemory2KHR"
            | "vkMapMemory2"
            | "vkGetImageSubresourceLayout"
    )
}

/// Whether the call named `name` is decoded. Calls that touch nothing framelab models (state
/// setting and queries among the commands) are counted without being decoded.
fn is_decoded(name: &str, func: Func) -> bool {
    !matches!(func, Func::Other | Func::Cmd(CmdFunc::Other))
        || binary_only(name)
        || func == Func::MapMemory
}

/// A function call block too short for the thread id every call starts with.
#[derive(Debug, thiserror::Error)]
#[error("call block of {0} bytes has no thread id")]
struct NoThreadId(usize);

/// One function call block: decoded and given to the importer, or counted.
fn call(
    imp: &mut Importer,
    reading: &mut Reading,
    contents: &mut Contents,
    block: &Block,
) -> Result<(), NoThreadId> {
    let Some((def, func)) = registry::command_index(block.id)
        .and_then(|i| Some((&registry::COMMANDS[i], registry::func(i)?)))
    else {
        let e = reading
            .unknown_ids
            .entry(block.id)
            .or_insert((0, block.at.block));
        e.0 += 1;
        return Ok(());
    };
    let extra = binary_only(def.name) || func == Func::MapMemory;
    if !is_decoded(def.name, func) {
        imp.calls += 1;
        imp.check_provided(def.name, block.at.block);
        imp.count_not_modelled(def.name);
        return Ok(());
    }
    if block.body.len() < 8 {
        return Err(NoThreadId(block.body.len()));
    }
    let mut args = std::mem::take(&mut reading.args);
    let mut args = match decode::decode_call(def, &block.body[8..], &mut args) {
        Ok(decoded) => {
            if extra {
                let root = Arg::root(&args);
                contents.observe(def.name, &root, &decoded.blobs);
                if func == Func::CreateShaderModule
                    && let Ok(h) = root.get("pShaderModule").and_then(|v| v.u64())
                    && let Some(code) = contents.modules.get(&h)
                {
                    imp.pipelines.learn_module(h, code);
                    if imp.sync.enabled() {
                        imp.spirv.submit(h, code, imp.objects.spirv);
                    }
                }
                if func == Func::Other {
                    imp.calls += 1;
                    imp.check_provided(def.name, block.at.block);
                    imp.count_not_modelled(def.name);
                    reading.args = args;
                    return Ok(());
                }
            }
            let call = Call {
                line: block.at.block,
                index: block.at.block,
                name: Cow::Borrowed(def.name),
                func,
                args,
                result: decoded.ret,
                dialect: "binary",
            };
            if imp.dialect.is_none() {
                imp.dialect = Some(call.dialect);
            }
            imp.call(&call);
            for cb in std::mem::take(&mut imp.submitted_before) {
                contents.submitted_before(&imp.objects, &imp.recordings, cb);
                imp.sync.submitted_before(&imp.objects, &imp.recordings, cb);
            }
            call.args
        }
        Err(why) => {
            imp.calls += 1;
            imp.skip(
                format!("{}: cannot decode: {why}", def.name),
                block.at.block,
            );
            args
        }
    };
    args.clear();
    reading.args = args;
    Ok(())
}

/// Imports the frames `options` selects from a binary capture of `len` bytes (when known).
/// Side files are named after `stem` (the output capture's), in `<stem>.contents/` and
/// `<stem>.shaders/`.
pub fn import(
    reader: impl Read,
    len: Option<u64>,
    file: &str,
    stem: &str,
    options: &ImportOptions,
) -> Result<Imported, ImportError> {
    let mut blocks = Blocks::new(reader, len).map_err(|e| block_error(file, e))?;
    let compression = blocks.header.compression;
    let mut imp = Importer::new(options);
    imp.keep_submitted_before = true;
    imp.layouts_known = true;
    let mut reading = Reading {
        tool: "GFXReconstruct (version not in the capture)".to_owned(),
        blocks: 0,
        other: BTreeMap::new(),
        unknown_ids: BTreeMap::new(),
        args: Tree::default(),
    };
    let mut contents = Contents::default();
    // Block index where the state snapshot of a trimmed capture ends (`u64::MAX` inside it).
    let mut snapshot_end: Option<u64> = None;
    while let Some(block) = blocks.next_block() {
        let block = block.map_err(|e| block_error(file, e))?;
        reading.blocks += 1;
        let at = block.at;
        match block.kind {
            Kind::FunctionCall => {
                call(&mut imp, &mut reading, &mut contents, &block)
                    .map_err(|m| located(file, at, m))?;
            }
            Kind::MetaData => {
                let room = |fills| room(&imp.objects, fills);
                let meta =
                    meta::read(&block, compression, &room).map_err(|m| located(file, at, m))?;
                // Contents and memory types are reported as what they became, not as
                // blocks that model nothing.
                if matches!(meta, Meta::Other(_)) {
                    reading.count(format!("(meta-data: {})", meta.name()));
                }
                match meta {
                    // Written while the imported frames run: their work reads it from here on.
                    Meta::FillMemory {
                        memory,
                        offset,
                        data,
                    } if contents.frozen => {
                        let at = contents.absolute(memory, offset);
                        imp.host_write(memory, at, &data, &|i| contents.linear_layout(i));
                    }
                    Meta::FillMemory {
                        memory,
                        offset,
                        data,
                    } => contents.fill(memory, contents.absolute(memory, offset), data),
                    Meta::InitBuffer { buffer, data } => contents.init_buffer(buffer, data),
                    Meta::InitImage {
                        image,
                        aspect,
                        layout,
                        level_sizes,
                        data,
                    } => {
                        if let Some(layout) = ImageLayout::from_value(u64::from(layout)) {
                            let origin = Origin::none("the capture's state snapshot");
                            imp.sync.start_layout(image, layout, origin);
                        }
                        contents.init_image(image, aspect, level_sizes, data)
                    }
                    Meta::MemoryProperties { type_flags } => {
                        imp.objects.memory_type_flags =
                            type_flags.into_iter().map(u64::from).collect();
                    }
                    Meta::DeviceProperties {
                        vendor_id,
                        device_name,
                    } => {
                        contents.layout =
                            super::driver_layout::DriverLayout::of(vendor_id, &device_name);
                        imp.objects.device = contents.layout;
                    }
                    Meta::Other(_) => {}
                }
            }
            Kind::FrameMarker => {
                // An explicit end-of-frame marker (file format 0.1 and later).
                if block.id == 2 {
                    imp.frame_end();
                }
            }
            Kind::StateMarker => {
                reading.count("(state snapshot markers)");
                // Marker types: 1 begins the snapshot, 2 ends it.
                if block.id == 1 {
                    snapshot_end = Some(u64::MAX);
                } else if block.id == 2 {
                    snapshot_end = Some(at.block);
                }
                imp.in_snapshot = block.id == 1;
            }
            Kind::Annotation => reading.annotation(&block),
            Kind::MethodCall => reading.count("(D3D12 method calls)"),
            Kind::Unknown(t) => reading.count(format!("(blocks of unknown type {t:#x})")),
        }
        // The frame's contents are what stood before its first submission; a trimmed
        // capture's state snapshot submits too (to set semaphores), and its contents come
        // after that, so only a submission past the snapshot counts.
        if imp
            .builder
            .last_submit
            .is_some_and(|s| snapshot_end.is_none_or(|end| s > end))
        {
            contents.frozen = true;
        }
        if imp.builder.done() {
            break;
        }
    }
    if imp.calls == 0 {
        return Err(ImportError::Stream {
            file: file.to_owned(),
            message: format!("no Vulkan calls in {} blocks", reading.blocks),
        });
    }
    for (id, (n, first)) in &reading.unknown_ids {
        let e = imp
            .skipped
            .entry(format!("calls with unknown call id {id:#x}"))
            .or_insert((0, *first));
        e.0 += n;
    }
    let (major, minor) = blocks.header.version;
    imp.dialect = Some("binary");
    let read = super::Read {
        tool: format!(
            "{} (binary, file format {major}.{minor}, {})",
            reading.tool,
            compression.name()
        ),
        lines: reading.blocks,
        other: reading.other,
    };
    let extras = super::Extras {
        contents: &mut contents,
        stem,
    };
    super::finish(imp, read, file, options, Some(extras))
}

/// Reads and decompresses every block of a capture without decoding any call: the floor an
/// import of the same file cannot go below, for the import benchmark. Returns the blocks
/// read and the bytes they decompress to.
pub fn decompress_only(reader: impl Read, len: Option<u64>) -> Result<(u64, u64), ImportError> {
    let file = "capture";
    let mut blocks = Blocks::new(reader, len).map_err(|e| block_error(file, e))?;
    let compression = blocks.header.compression;
    let (mut count, mut bytes) = (0, 0);
    while let Some(block) = blocks.next_block() {
        let block = block.map_err(|e| block_error(file, e))?;
        count += 1;
        bytes += block.body.len() as u64;
        if block.kind == Kind::MetaData {
            let meta = meta::read(&block, compression, &|_| Ok(()))
                .map_err(|m| located(file, block.at, m))?;
            bytes += meta.payload_len();
        }
    }
    Ok((count, bytes))
}

/// Reads and decompresses every block and decodes every call the importer would (as
/// `import` chooses them), without importing: the second floor, for the import benchmark,
/// which shows how much of an import is decoding and how much the importer. Returns the
/// calls decoded.
pub fn decode_only(reader: impl Read, len: Option<u64>) -> Result<u64, ImportError> {
    let file = "capture";
    let mut blocks = Blocks::new(reader, len).map_err(|e| block_error(file, e))?;
    let compression = blocks.header.compression;
    let mut args = Tree::default();
    let mut decoded = 0;
    while let Some(block) = blocks.next_block() {
        let block = block.map_err(|e| block_error(file, e))?;
        match block.kind {
            Kind::MetaData => {
                meta::read(&block, compression, &|_| Ok(()))
                    .map_err(|m| located(file, block.at, m))?;
            }
            Kind::FunctionCall => {
                let Some((def, func)) = registry::command_index(block.id)
                    .and_then(|i| Some((&registry::COMMANDS[i], registry::func(i)?)))
                else {
                    continue;
                };
                if is_decoded(def.name, func)
                    && block.body.len() >= 8
                    && decode::decode_call(def, &block.body[8..], &mut args).is_ok()
                {
                    decoded += 1;
                }
            }
            _ => {}
        }
    }
    Ok(decoded)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::state::{BufferInfo, MemoryInfo};

    #[test]
    fn a_payload_fits_what_holds_it_or_is_refused_before_it_is_decompressed() {
        let mut objects = Objects::default();
        objects.memories.insert(
            1,
            MemoryInfo {
                size: 4096,
                type_index: 0,
            },
        );
        let buffer = |bound| BufferInfo {
            created_at: 0,
            destroyed_at: None,
            size: 1024,
            usage: 0,
            bound,
            alignment: None,
        };
        objects.buffers.insert(2, buffer(Some((1, 1024))));
        objects.buffers.insert(3, buffer(None));
        let fill = |offset, size| Fills::Memory {
            memory: 1,
            offset,
            size,
        };
        assert!(room(&objects, fill(0, 4096)).is_ok());
        let e = room(&objects, fill(4000, 100)).unwrap_err().to_string();
        assert!(
            e.contains("at offset 4000 of memory 0x1, which holds 4096"),
            "{e}"
        );
        assert!(room(&objects, fill(u64::MAX, 2)).is_err());
        let into = |buffer, size| room(&objects, Fills::Buffer { buffer, size });
        // Bound at 1024: 3072 bytes of memory are its to fill.
        assert!(into(2, 3072).is_ok());
        let e = into(2, 3073).unwrap_err().to_string();
        assert!(
            e.contains("more than the 3072 bytes of the memory bound to it"),
            "{e}"
        );
        // Not bound yet: all the memory allocated.
        let e = into(3, 1 << 30).unwrap_err().to_string();
        assert!(e.contains("4096 bytes of all the device memory"), "{e}");
        let e = into(9, 1).unwrap_err().to_string();
        assert!(
            e.contains("buffer 0x9, which the capture never created"),
            "{e}"
        );
    }
}
