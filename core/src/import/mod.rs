//! `framelab import`: a GFXReconstruct capture converted to JSON Lines (`gfxrecon-convert`)
//! becomes a framelab capture. The stream is read line by line; the objects it creates are
//! tracked by handle, command buffers recorded as they are, and each queue submission turned
//! into passes in submission order with the barriers, labels and semaphores the application
//! really used. Shader code is not in the stream, so the capture is analysed, not replayed.

mod bindings;
mod build;
mod calls;
mod cmd_calls;
mod commands;
mod contents;
mod driver_layout;
mod emit;
mod extended_state;
mod finish;
use finish::finish;
pub mod file;
pub mod gfxr;
mod host_writes;
mod packed;
mod pipelines;
pub mod program;
mod provided;
mod queue_calls;
pub mod rdc;
mod record;
mod render_pass;
mod set_slots;
mod state;
mod stream;
mod subresources;
mod sync;
mod templates;
mod transfer_calls;
mod transfers;
mod tree;
mod valid_usage;
mod valid_usage_buffers;
mod valid_usage_clears;
mod valid_usage_copies;
mod valid_usage_descriptors;
mod valid_usage_filters;
mod valid_usage_params;
mod valid_usage_sets;
mod valid_usage_spirv;
mod value;
mod vk_work;

/// Maps and sets keyed by handles and ids, hashed millions of times in a long capture:
/// foldhash is several times faster than the standard SipHash on such keys, and resistance
/// to crafted collisions buys nothing for a file the user chose to import.
type HashMap<K, V> = std::collections::HashMap<K, V, foldhash::fast::RandomState>;
type HashSet<K> = std::collections::HashSet<K, foldhash::fast::RandomState>;

/// Most emptied recordings kept for reuse.
const SPARE_RECORDINGS: usize = 64;

use crate::capture::vulkan::{ImageLayout, PipelineStages};
use std::collections::BTreeMap;
use std::io::BufRead;

use serde::Serialize;

use crate::capture::format::RawCapture;
use build::Builder;
use calls::Func;
use commands::Origin;
use record::{Recording, Recordings};
use state::Objects;
use stream::{Call, Entry, Lines};
use value::{Arg, Got};

pub use stream::MAX_LINE_BYTES;

/// What to import.
#[derive(Clone, Copy, Debug, Default)]
pub struct ImportOptions {
    /// Which frames (0-based, inclusive); all when absent.
    pub frames: Option<(u32, u32)>,
    /// Leave out the synchronization check (the capture then records no `sync_hazards`):
    /// what the check costs is the difference.
    pub skip_sync_check: bool,
}

#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    #[error("{file}:{line}: {message}")]
    Line {
        file: String,
        line: u64,
        message: String,
    },
    #[error("{file}: {message}")]
    Stream { file: String, message: String },
    /// A binary capture's block that cannot be read: its number and the byte it starts at.
    #[error("{file}: block {block} at byte {offset}: {message}")]
    Block {
        file: String,
        block: u64,
        offset: u64,
        message: String,
    },
}

/// Something the import left out, how often, and the first line it happened on.
#[derive(Clone, Debug, Serialize, PartialEq, Eq)]
pub struct Skipped {
    pub what: String,
    pub count: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_line: Option<u64>,
}

/// What an import found and made.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub file: String,
    pub tool: String,
    /// `0.9.x` (`vkFunc` lines) or `1.x` (`function` lines).
    pub dialect: String,
    pub lines: u64,
    pub calls: u64,
    /// Frames the stream holds (up to the last one read when a selection ended reading).
    pub frames_in_stream: u32,
    /// Whether reading stopped after the selected frames, before the end of the file: `lines`,
    /// `calls` and `frames_in_stream` then count only what was read.
    pub stopped_after_selection: bool,
    pub frames_imported: (u32, u32),
    pub passes: usize,
    pub passes_by_kind: BTreeMap<String, usize>,
    pub draws: u64,
    pub dispatches: u64,
    pub images: usize,
    pub buffers: usize,
    pub heaps: usize,
    pub queues: usize,
    pub recorded_barriers: u64,
    /// Synchronization hazards found in the imported command stream.
    pub sync_hazards: usize,
    /// Valid-usage findings (`CaptureSource::valid_usage`).
    pub valid_usage: usize,
    pub fences: usize,
    pub skipped: Vec<Skipped>,
    /// Calls of functions that create or record nothing framelab models, by name.
    pub not_modelled: BTreeMap<String, u64>,
    /// Vulkan pipelines the imported draws and dispatches bound (in the capture's `vulkan`).
    pub pipelines: usize,
    /// Binary captures: SPIR-V modules written as side files.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shader_modules: Option<usize>,
    /// Binary captures: resources whose contents at the start of the frame were written as
    /// side files, and the bytes they hold.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contents: Option<ContentsSummary>,
    /// Why the capture cannot be replayed yet.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_replayable: Option<String>,
}

/// The contents a binary import wrote.
#[derive(Clone, Debug, Serialize)]
pub struct ContentsSummary {
    pub resources: usize,
    pub bytes: u64,
    /// Mapped-memory writes the capture holds.
    pub memory_writes: u64,
}

#[derive(Debug)]
pub struct Imported {
    pub capture: RawCapture,
    pub summary: Summary,
    /// Files to write beside the capture (paths relative to it): a binary capture's SPIR-V
    /// modules and resource contents. Empty for a JSON Lines stream.
    pub side_files: Vec<SideFile>,
}

pub use contents::SideFile;
pub use file::{FileImportError, Source, Written, import_file, sniff, sniff_file};

/// What only a binary capture brings, for `finish` to attach.
struct Extras<'a> {
    contents: &'a mut contents::Contents,
    /// The capture's stem: side files go in `<stem>.contents/` and `<stem>.shaders/`.
    stem: &'a str,
}

/// Calls whose failure at capture time means they created or did nothing.
fn failed(call: &Call) -> bool {
    call.result
        .as_deref()
        .is_some_and(|r| r.starts_with("VK_ERROR") || (r.starts_with('-') && r.len() > 1))
}

struct Importer {
    objects: Objects,
    pipelines: pipelines::Pipelines,
    recordings: Recordings,
    /// Emptied recordings of freed command buffers, for reuse. Boxed as in `recordings`,
    /// so that one moves between the two as a pointer.
    #[allow(clippy::vec_box)]
    spare: Vec<Box<Recording>>,
    /// Pool -> the command buffers allocated from it and not freed, for vkResetCommandPool.
    pools: HashMap<u64, HashSet<u64>>,
    builder: Builder,
    submitted_in_frame: bool,
    skipped: BTreeMap<String, (u64, u64)>,
    not_modelled: BTreeMap<String, u64>,
    calls: u64,
    dialect: Option<&'static str>,
    /// The last block index seen, and whether blocks were left out of the JSON before the
    /// first imported submission (a trimmed capture's state snapshot, memory fills).
    last_index: u64,
    hidden_blocks: bool,
    /// Vulkan's synchronization rules over the imported frames' submissions.
    sync: sync::Sync,
    /// Command buffers submitted before the imported frames, not yet looked at by the
    /// binary route (which carries out their copies on the contents); kept only when
    /// `keep_submitted_before` is set, as the binary route drains it after every call.
    submitted_before: Vec<u64>,
    keep_submitted_before: bool,
    /// Whether the stream says every image's layout before the frames: its creation and,
    /// in a trimmed capture, the layout its snapshot restores (the binary route's metadata;
    /// the JSON Lines stream of a trimmed capture lacks the snapshot's layouts).
    layouts_known: bool,
    /// Inside a trimmed capture's state snapshot: calls the capture tool made to rebuild the
    /// program's state, not always as the program made them (surface queries through
    /// `VK_KHR_get_surface_capabilities2` it never enabled).
    in_snapshot: bool,
    /// Functions already reported as called without the extension that provides them.
    unprovided: std::collections::HashSet<String>,
    /// Commands the submissions so far asked to walk (`MAX_WALKED`).
    walked: u64,
    /// Valid-usage statements the calls break (`valid_usage`), at most `MAX_FINDINGS`.
    valid_usage: Vec<crate::capture::format::ValidUsageFinding>,
    /// Each shader module's creating call (`vkCreateShaderModule #N`), where its code is
    /// validated.
    module_calls: BTreeMap<u64, String>,
    /// Shader code validated in the background as the stream creates it.
    spirv: valid_usage_spirv::Checker,
}

/// Most valid-usage findings one import keeps: a program that breaks a rule in every call
/// would otherwise list millions.
const MAX_FINDINGS: usize = 10_000;

/// Most commands one submission may ask to walk, secondary command buffers expanded: a real
/// frame's submissions hold thousands to a few hundred thousand.
const MAX_SUBMIT_COMMANDS: u64 = 1 << 20;
/// Most commands all submissions of one import may ask to walk (every frame's before the
/// imported ones included): a few seconds of walking.
const MAX_WALKED: u64 = 1 << 26;

impl Importer {
    fn skip(&mut self, what: String, line: u64) {
        let e = self.skipped.entry(what).or_insert((0, line));
        e.0 += 1;
    }

    /// Counts a call of a function framelab does not model (without a new key's allocation
    /// for every call).
    fn count_not_modelled(&mut self, name: &str) {
        match self.not_modelled.get_mut(name) {
            Some(n) => *n += 1,
            None => {
                self.not_modelled.insert(name.to_owned(), 1);
            }
        }
    }

    /// A call of `name` (at `index`) where no extension that provides it is enabled: the
    /// specification's rule (an extension's commands need it enabled) has no VUID; the
    /// finding takes the validation layer's id. Core commands need none; nothing is said
    /// before the stream creates its instance, nor of a trimmed capture's snapshot, so only
    /// the binary route, which marks the snapshot, checks (the JSON Lines stream of a trimmed
    /// capture does not say where its snapshot ends; RenderDoc's holds no instance call).
    fn check_provided(&mut self, name: &str, index: u64) {
        if !self.layouts_known
            || self.in_snapshot
            || !self.objects.instance_created
            || !self.checks_valid_usage()
            || self.unprovided.contains(name)
        {
            return;
        }
        let Ok(at) = provided::PROVIDED.binary_search_by(|(n, _)| (*n).cmp(name)) else {
            return;
        };
        let by = provided::PROVIDED[at].1;
        if by.starts_with(|c: char| c.is_ascii_digit())
            || by.split(',').any(|e| self.objects.extensions.contains(e))
        {
            return;
        }
        // Once per function: a label around every draw would crowd out every other finding.
        self.unprovided.insert(name.to_owned());
        self.valid_usage
            .push(crate::capture::format::ValidUsageFinding {
                vuid: "UNASSIGNED-GeneralParameterError-ExtensionNotEnabled".to_owned(),
                command: format!("{name} #{index}"),
                detail: format!(
                    "calls a command of {}, which neither the instance nor the device enabled (its first call; every later one too)",
                    by.replace(',', " or ")
                ),
            });
    }

    fn call(&mut self, call: &Call) {
        self.calls += 1;
        self.check_provided(&call.name, call.index);
        if call.index > self.last_index.saturating_add(1) && self.builder.first_submit.is_none() {
            self.hidden_blocks = true;
        }
        self.last_index = self.last_index.max(call.index);
        self.objects.at = call.index;
        if failed(call) {
            self.skip(
                format!(
                    "{} calls that failed at capture ({})",
                    call.name,
                    call.result.as_deref().unwrap_or("")
                ),
                call.line,
            );
            return;
        }
        let args = Arg::root(&call.args);
        if self.checks_valid_usage() {
            let found = valid_usage_params::array_lengths(&call.name, call.index, &args);
            self.valid_usage.extend(found);
        }
        match self.dispatch(call, &args) {
            Ok(true) => {}
            Ok(false) => self.count_not_modelled(&call.name),
            Err(value::Skip(why)) => self.skip(format!("{}: {why}", call.name), call.line),
        }
    }

    fn dispatch(&mut self, call: &Call, args: &Arg<'_>) -> Got<bool> {
        match call.func {
            Func::Cmd(cmd) => return self.cmd_call(cmd, call, args),
            Func::AllocateCommandBuffers => {
                let pool = args.get("pAllocateInfo")?.get("commandPool")?.handle()?;
                let members = self.pools.entry(pool).or_default();
                for cb in args.list("pCommandBuffers")? {
                    members.insert(cb.handle()?);
                }
            }
            Func::ResetCommandBuffer => {
                let cb = args.get("commandBuffer")?.handle()?;
                self.reset_recording(cb);
            }
            Func::FreeCommandBuffers => {
                let pool = args.get("commandPool")?.handle()?;
                for cb in args.list("pCommandBuffers")? {
                    let cb = cb.handle()?;
                    self.free_recording(cb);
                    if let Some(members) = self.pools.get_mut(&pool) {
                        members.remove(&cb);
                    }
                }
            }
            Func::ResetCommandPool => self.reset_pool(args)?,
            Func::DestroyCommandPool => {
                let pool = args.get("commandPool")?.handle()?;
                for cb in self.pools.remove(&pool).into_iter().flatten() {
                    self.free_recording(cb);
                }
            }
            Func::QueueSubmit { v2 } => self.submit(call, args, v2)?,
            Func::CreateImage if self.layouts_known => {
                if self.checks_valid_usage() {
                    let command = format!("{} #{}", call.name, call.index);
                    let found = valid_usage::image_usage(&command, args).unwrap_or_default();
                    self.valid_usage.extend(found);
                }
                let applied = self.objects.apply(call.func, args)?;
                // The image is made: a layout it does not say is only left unknown.
                let layout = args
                    .get("pCreateInfo")
                    .and_then(|ci| ci.get("initialLayout")?.name())
                    .ok()
                    .and_then(|l| ImageLayout::from_name(&l));
                let image = args.get("pImage").and_then(|i| i.handle());
                if let (Some(layout), Ok(image)) = (layout, image) {
                    let origin = Origin::call(&call.name, call.index);
                    self.sync.start_layout(image, layout, origin);
                }
                return Ok(applied);
            }
            Func::QueuePresent => self.present(call, args)?,
            Func::AcquireNextImage { v2 } => self.acquire(call, args, v2)?,
            Func::HostWait(wait) => self.host_wait(args, wait)?,
            Func::CreateShaderModule => {
                if let Ok(h) = args.get("pShaderModule").and_then(|h| h.handle()) {
                    self.module_calls
                        .insert(h, format!("{} #{}", call.name, call.index));
                }
                return self.pipelines.apply(call.func, args);
            }
            Func::CreatePipelineLayout => {
                let applied = self.pipelines.apply(call.func, args)?;
                // The recordings tell compatible binds apart by these ids.
                let h = args.get("pPipelineLayout")?.handle()?;
                if let Some(ids) = self.pipelines.compat_ids(h) {
                    self.objects.layout_compat.insert(h, ids);
                }
                return Ok(applied);
            }
            Func::CreateSampler
            | Func::CreateDescriptorSetLayout
            | Func::CreatePipelines { .. } => return self.pipelines.apply(call.func, args),
            Func::UpdateDescriptorSetWithTemplate if self.checks_valid_usage() => {
                let command = format!("{} #{}", call.name, call.index);
                let template = args.get("descriptorUpdateTemplate")?.handle()?;
                let data = args.get("pData")?;
                let found = valid_usage::template_usage(&command, template, &data, &self.objects);
                self.valid_usage.extend(found.unwrap_or_default());
                return self.objects.apply(call.func, args);
            }
            Func::UpdateDescriptorSets if self.checks_valid_usage() => {
                let command = format!("{} #{}", call.name, call.index);
                let found = valid_usage::descriptor_usage(&command, args, &self.objects);
                self.valid_usage.extend(found.unwrap_or_default());
                return self.objects.apply(call.func, args);
            }
            Func::CreateBufferView if self.checks_valid_usage() => {
                let command = format!("{} #{}", call.name, call.index);
                let found = valid_usage_buffers::buffer_view_usage(&command, args, &self.objects);
                self.valid_usage.extend(found.unwrap_or_default());
                return self.objects.apply(call.func, args);
            }
            Func::CreateFramebuffer if self.checks_valid_usage() => {
                let command = format!("{} #{}", call.name, call.index);
                let found = valid_usage::framebuffer_usage(&command, args, &self.objects);
                self.valid_usage.extend(found.unwrap_or_default());
                return self.objects.apply(call.func, args);
            }
            Func::CreateDevice if self.checks_valid_usage() => {
                let command = format!("{} #{}", call.name, call.index);
                let found = valid_usage::device_features(&command, args).unwrap_or_default();
                self.valid_usage.extend(found);
                return self.objects.apply(call.func, args);
            }
            Func::CreateRenderPass => {
                if self.checks_valid_usage() {
                    let command = format!("{} #{}", call.name, call.index);
                    let v2 = call.name.contains('2');
                    // A call too malformed to check is skipped by `objects.apply` below.
                    let found = valid_usage::render_pass(&command, v2, args).unwrap_or_default();
                    self.valid_usage.extend(found);
                }
                return self.objects.apply(call.func, args);
            }
            other => return self.objects.apply(other, args),
        }
        Ok(true)
    }

    /// Whether calls are checked for valid usage: with the synchronization check, and until
    /// a frame has given `MAX_FINDINGS` of them.
    fn checks_valid_usage(&self) -> bool {
        self.sync.enabled() && self.valid_usage.len() < MAX_FINDINGS
    }

    fn reset_pool(&mut self, args: &Arg<'_>) -> Got<()> {
        let pool = args.get("commandPool")?.handle()?;
        // Buffers of the pool never recorded stay unknown, as they were.
        for cb in self.pools.get(&pool).into_iter().flatten() {
            if let Some(r) = self.recordings.get_mut(cb) {
                r.reset();
            }
        }
        Ok(())
    }

    /// A command buffer starts empty again; its storage is kept for what it records next,
    /// since applications record the same buffers frame after frame.
    fn reset_recording(&mut self, cb: u64) {
        let spare = &mut self.spare;
        self.recordings
            .entry(cb)
            .or_insert_with(|| spare.pop().unwrap_or_default())
            .reset();
    }

    /// A freed command buffer's storage goes to the next one allocated: applications (wgpu
    /// among them) allocate and free command buffers by the thousand.
    fn free_recording(&mut self, cb: u64) {
        if let Some(mut r) = self.recordings.remove(&cb)
            && self.spare.len() < SPARE_RECORDINGS
        {
            r.reset();
            self.spare.push(r);
        }
    }
}

/// What reading the stream gathered besides the importer's own state.
struct Read {
    tool: String,
    lines: u64,
    /// Entries other than calls, by what they are.
    other: BTreeMap<String, u64>,
}

/// Feeds every entry of the stream to the importer until the selected frames are done.
fn read_stream(reader: impl BufRead, file: &str, imp: &mut Importer) -> Result<Read, ImportError> {
    let mut lines = Lines::new(reader);
    let mut read = Read {
        tool: "GFXReconstruct (version not in the stream)".to_owned(),
        lines: 0,
        other: BTreeMap::new(),
    };
    while let Some(entry) = lines.next_entry() {
        let entry = entry.map_err(|e| ImportError::Line {
            file: file.to_owned(),
            line: e.line,
            message: e.message,
        })?;
        read.lines += 1;
        match entry {
            Entry::Header {
                gfxr_version,
                json_version,
            } => {
                // Versions are the stream's own words: cleaned and cut like a debug name.
                read.tool = format!(
                    "GFXReconstruct {} (JSON {})",
                    state::debug_text(&gfxr_version),
                    state::debug_text(&json_version)
                );
            }
            Entry::Call(call) => {
                if imp.dialect.is_none() {
                    imp.dialect = Some(call.dialect);
                }
                imp.call(&call);
            }
            Entry::FrameEnd => imp.frame_end(),
            Entry::Other(kind) => *read.other.entry(format!("({kind} lines)")).or_default() += 1,
        }
        if imp.builder.done() {
            break;
        }
    }
    Ok(read)
}

impl Importer {
    fn new(options: &ImportOptions) -> Self {
        Importer {
            objects: Objects::default(),
            pipelines: pipelines::Pipelines::default(),
            recordings: HashMap::default(),
            spare: Vec::new(),
            pools: HashMap::default(),
            submitted_before: Vec::new(),
            keep_submitted_before: false,
            layouts_known: false,
            in_snapshot: false,
            unprovided: Default::default(),
            walked: 0,
            builder: Builder::new(options.frames),
            submitted_in_frame: false,
            skipped: BTreeMap::new(),
            not_modelled: BTreeMap::new(),
            calls: 0,
            dialect: None,
            last_index: 0,
            hidden_blocks: false,
            sync: sync::Sync::new(!options.skip_sync_check),
            valid_usage: Vec::new(),
            module_calls: BTreeMap::new(),
            spirv: valid_usage_spirv::Checker::default(),
        }
    }

    /// The end of a frame the stream marks explicitly.
    fn frame_end(&mut self) {
        if self.submitted_in_frame {
            self.builder.end_frame();
            self.submitted_in_frame = false;
        }
    }
}

/// Imports the frames `options` selects from a JSON Lines stream; `file` names it in messages.
pub fn import(
    reader: impl BufRead,
    file: &str,
    options: &ImportOptions,
) -> Result<Imported, ImportError> {
    let mut imp = Importer::new(options);
    let read = read_stream(reader, file, &mut imp)?;
    if imp.calls == 0 {
        return Err(ImportError::Stream {
            file: file.to_owned(),
            message: "no API calls: not a GFXReconstruct JSON Lines stream (gfxrecon-convert --format jsonl)".to_owned(),
        });
    }
    finish(imp, read, file, options, None)
}
