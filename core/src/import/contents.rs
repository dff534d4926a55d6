//! What only a capture file holds (a GFXReconstruct binary capture, a RenderDoc capture), not
//! a JSON Lines stream, gathered while it is read: the SPIR-V of every shader module, the bytes
//! the application wrote to mapped memory, and the buffer, memory and image contents the
//! capture saved at its start. Both readers feed it through the same few calls, so contents
//! are matched to resources one way. At the end it is matched to the imported resources and
//! written as side files: each buffer or image whose contents at the start of the frame are known
//! gets a `file`, and the rest that existed before the frame stay `before_capture`, named.
//!
//! Memory is bounded by the live objects: mapped-memory writes are kept as non-overlapping
//! extents of each live allocation (a later write replaces what it covers), and dropped when
//! the allocation is freed.

use std::collections::BTreeMap;

use super::{HashMap, HashSet};

use super::value::Arg;

use super::state::{ImageInfo, Objects};
use crate::capture::dxgi;
use crate::capture::format::{InitialContents, RawCapture};

/// A file the import writes beside the capture, by its path relative to it: its bytes are
/// the parts one after another (a contents pack is written without joining them first).
#[derive(Clone, Debug)]
pub struct SideFile {
    pub path: String,
    pub parts: Vec<Vec<u8>>,
}

impl SideFile {
    pub fn one(path: String, bytes: Vec<u8>) -> SideFile {
        SideFile {
            path,
            parts: vec![bytes],
        }
    }

    pub fn len(&self) -> u64 {
        self.parts.iter().map(|p| p.len() as u64).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.parts.iter().all(Vec::is_empty)
    }

    /// Writes the file at `path` (created or truncated).
    pub fn write(&self, path: &std::path::Path) -> std::io::Result<()> {
        use std::io::Write;
        let mut file = std::fs::File::create(path)?;
        for part in &self.parts {
            file.write_all(part)?;
        }
        file.flush()
    }
}

/// The contents of a frame's resources in one file (`contents.bin` in the side folder), each
/// at its offset: one file written once instead of one per resource (a game's frame holds
/// thousands). Resources whose bytes are the same share them.
#[derive(Debug)]
pub struct Pack {
    pub path: String,
    parts: Vec<Vec<u8>>,
    len: u64,
    /// (offset, part) of what is in the pack, by length and a hash of its ends (`key`); the
    /// bytes are compared whole before one is shared.
    seen: HashMap<(usize, u64), Vec<(u64, usize)>>,
}

impl Pack {
    pub fn new(dir: &str) -> Pack {
        Pack {
            path: format!("{dir}/contents.bin"),
            parts: Vec::new(),
            len: 0,
            seen: HashMap::default(),
        }
    }

    /// Where `data` is in the pack, added unless the same bytes are there already.
    pub fn add(&mut self, data: Vec<u8>) -> u64 {
        let key = (data.len(), ends_hash(&data));
        let candidates = self.seen.entry(key).or_default();
        if let Some(&(at, _)) = candidates.iter().find(|(_, p)| self.parts[*p] == data) {
            return at;
        }
        let at = self.len;
        candidates.push((at, self.parts.len()));
        self.len += data.len() as u64;
        self.parts.push(data);
        at
    }

    /// The pack as a side file, or nothing where no resource had contents.
    pub fn into_side_file(self) -> Option<SideFile> {
        (self.len > 0).then_some(SideFile {
            path: self.path,
            parts: self.parts,
        })
    }
}

/// A hash of the first and last 256 bytes: enough to tell most contents apart without
/// reading them whole (equal keys are compared byte for byte).
fn ends_hash(data: &[u8]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    data[..data.len().min(256)].hash(&mut h);
    data[data.len().saturating_sub(256)..].hash(&mut h);
    h.finish()
}

/// The non-overlapping byte extents written to one allocation, by offset.
#[derive(Debug, Default)]
pub(super) struct Extents(BTreeMap<u64, Vec<u8>>);

impl Extents {
    /// Writes `data` at `offset`; a write that would run past the end of the address space
    /// (a damaged offset) is no write.
    pub(super) fn write(&mut self, offset: u64, data: Vec<u8>) {
        let Some(end) = offset.checked_add(data.len() as u64) else {
            return;
        };
        // Cut every extent that overlaps [offset, end) down to the parts outside it.
        let overlapping: Vec<u64> = self
            .0
            .range(..end)
            .filter(|(o, d)| **o + d.len() as u64 > offset)
            .map(|(o, _)| *o)
            .collect();
        for o in overlapping {
            let Some(old) = self.0.remove(&o) else {
                continue;
            };
            let old_end = o + old.len() as u64;
            if o < offset {
                self.0.insert(o, old[..(offset - o) as usize].to_vec());
            }
            if old_end > end {
                self.0.insert(end, old[(end - o) as usize..].to_vec());
            }
        }
        self.0.insert(offset, data);
    }

    /// The bytes [offset, offset + size), zero where nothing was written; `None` when no
    /// write touches the range, or when the range is larger than any block could have
    /// written (a corrupt size).
    pub(super) fn read(&self, offset: u64, size: u64) -> Option<Vec<u8>> {
        let end = offset.checked_add(size)?;
        if size > MAX_BLOCK_BYTES {
            return None;
        }
        let mut out: Option<Vec<u8>> = None;
        for (&o, d) in self.0.range(..end) {
            let d_end = o + d.len() as u64;
            if d_end <= offset {
                continue;
            }
            if out.is_none() {
                let mut v = Vec::new();
                v.try_reserve_exact(size as usize).ok()?;
                v.resize(size as usize, 0);
                out = Some(v);
            }
            let buf = out.as_mut()?;
            let from = o.max(offset);
            let to = d_end.min(end);
            buf[(from - offset) as usize..(to - offset) as usize]
                .copy_from_slice(&d[(from - o) as usize..(to - o) as usize]);
        }
        out
    }
}

/// One aspect of an image snapshot.
#[derive(Debug)]
struct ImageData {
    aspect: u32,
    level_sizes: Vec<u64>,
    data: Vec<u8>,
}

/// The binary-only things gathered while reading.
#[derive(Debug, Default)]
pub struct Contents {
    /// Shader module handle -> its SPIR-V.
    pub modules: BTreeMap<u64, Vec<u8>>,
    pub(super) memory: HashMap<u64, Extents>,
    /// Memory -> the offset its current mapping starts at.
    map_offset: HashMap<u64, u64>,
    pub(super) buffers: HashMap<u64, Vec<u8>>,
    images: HashMap<u64, Vec<ImageData>>,
    /// Images whose contents copies before the frames made, packed (`transfers`).
    pub(super) uploaded: HashMap<u64, Vec<u8>>,
    /// Resources the GPU wrote before the frames in ways the import does not carry out:
    /// their contents are not known, whatever the host wrote before.
    pub(super) gpu_written: HashSet<u64>,
    /// Bytes copies before the frames produced, counted against the same allowance.
    pub(super) copied: u64,
    pub fills: u64,
    /// Bytes the capture wrote (memory fills and snapshots): what the contents written out
    /// may add up to, beside a fixed allowance for the zeros of unwritten ranges.
    pub(super) written: u64,
    /// Set at the first submission of the imported frames: what is written later is the
    /// frame's own work, not its starting contents.
    pub frozen: bool,
    /// Fills that came after snapshot contents (memory, offset in it, bytes): the application
    /// wrote them later, so they overwrite what the snapshot says of buffers bound there.
    late_fills: Vec<(u64, u64, Vec<u8>)>,
    snapshot_seen: bool,
    /// Linear images: (row pitch, offset of the first texel in their memory binding) from
    /// `vkGetImageSubresourceLayout`, for images the application writes through a mapping.
    linear: HashMap<u64, (u64, u64)>,
    /// How the capturing driver lays out images in memory, where known: images without a
    /// snapshot are read from their memory's bytes by it.
    pub(super) layout: super::driver_layout::DriverLayout,
    /// Images whose contents were read so.
    laid_out: usize,
}

/// Largest contents of one resource or range read back: what one GFXReconstruct block can hold.
pub(super) const MAX_BLOCK_BYTES: u64 = 4 << 30;

/// Contents produced beyond the bytes the capture wrote: zeros where a buffer's memory was
/// never written. Past it, a hostile size cannot make the import hold more.
pub(super) const ZERO_ALLOWANCE: u64 = 256 << 20;

impl Contents {
    /// A call only the binary route needs to see.
    pub fn observe(&mut self, name: &str, args: &Arg<'_>, blobs: &[(String, Vec<u8>)]) {
        if self.frozen
            && !matches!(
                name,
                "vkCreateShaderModule"
                    | "vkMapMemory"
                    | "vkMapMemory2KHR"
                    | "vkMapMemory2"
                    | "vkGetImageSubresourceLayout"
            )
        {
            return;
        }
        let number = |a: &Arg<'_>, path: &[&str]| {
            path.iter()
                .try_fold(*a, |a, k| a.get(k).ok())
                .and_then(|v| v.u64().ok())
        };
        match name {
            "vkGetImageSubresourceLayout" => {
                let first = number(args, &["pSubresource", "mipLevel"]) == Some(0)
                    && number(args, &["pSubresource", "arrayLayer"]) == Some(0);
                if let (true, Some(image), Some(pitch), Some(offset)) = (
                    first,
                    number(args, &["image"]),
                    number(args, &["pLayout", "rowPitch"]),
                    number(args, &["pLayout", "offset"]),
                ) {
                    self.linear.insert(image, (pitch, offset));
                }
            }
            "vkCreateShaderModule" => {
                let Some(module) = number(args, &["pShaderModule"]) else {
                    return;
                };
                // Long code comes as raw bytes; a module of a few words as numbers.
                let bytes = match blobs.iter().find(|(p, _)| p == "pCreateInfo.pCode") {
                    Some((_, b)) => b.clone(),
                    None => args
                        .get("pCreateInfo")
                        .and_then(|c| c.get("pCode"))
                        .and_then(|c| c.items())
                        .map(|words| {
                            words
                                .iter()
                                .filter_map(|w| w.u64().ok())
                                .flat_map(|w| (w as u32).to_le_bytes())
                                .collect()
                        })
                        .unwrap_or_default(),
                };
                self.module(module, bytes);
            }
            "vkMapMemory" => {
                if let (Some(m), Some(o)) = (number(args, &["memory"]), number(args, &["offset"])) {
                    self.map_offset.insert(m, o);
                }
            }
            "vkMapMemory2KHR" | "vkMapMemory2" => {
                if let (Some(m), Some(o)) = (
                    number(args, &["pMemoryMapInfo", "memory"]),
                    number(args, &["pMemoryMapInfo", "offset"]),
                ) {
                    self.map_offset.insert(m, o);
                }
            }
            "vkFreeMemory" => {
                if let Some(m) = number(args, &["memory"]) {
                    self.memory.remove(&m);
                    self.map_offset.remove(&m);
                }
            }
            _ => {}
        }
    }

    /// A linear image's row pitch and the offset of its first texel in its memory binding,
    /// where the driver gave them (`vkGetImageSubresourceLayout` of its first subresource).
    pub fn linear_layout(&self, image: u64) -> Option<(u64, u64)> {
        self.linear.get(&image).copied()
    }

    /// Where a fill of `memory` at `offset` lands: offsets of fills count from the start of
    /// the memory's current mapping.
    pub fn absolute(&self, memory: u64, offset: u64) -> u64 {
        self.map_offset
            .get(&memory)
            .copied()
            .unwrap_or(0)
            .saturating_add(offset)
    }

    /// Bytes the application wrote to `memory` at `at` (from the start of the allocation).
    pub fn fill(&mut self, memory: u64, at: u64, data: Vec<u8>) {
        if self.frozen {
            return;
        }
        self.fills += 1;
        self.written += data.len() as u64;
        if self.snapshot_seen {
            self.written += data.len() as u64;
            self.late_fills.push((memory, at, data.clone()));
        }
        self.memory.entry(memory).or_default().write(at, data);
    }

    /// A buffer's contents as the capture saved them at its start.
    pub fn init_buffer(&mut self, buffer: u64, data: Vec<u8>) {
        if self.frozen {
            return;
        }
        self.snapshot_seen = true;
        self.written += data.len() as u64;
        self.buffers.insert(buffer, data);
    }

    /// A whole allocation's contents as the capture saved them at its start: the buffers
    /// bound to it read their ranges from here.
    pub fn init_memory(&mut self, memory: u64, data: Vec<u8>) {
        if self.frozen {
            return;
        }
        self.written += data.len() as u64;
        let mut extents = Extents::default();
        extents.write(0, data);
        self.memory.insert(memory, extents);
    }

    /// One aspect of an image as the capture saved it (`aspect` 1 colour, 2 depth, 4
    /// stencil): each level's size in `level_sizes`, the levels one after the other.
    pub fn init_image(&mut self, image: u64, aspect: u32, level_sizes: Vec<u64>, data: Vec<u8>) {
        if self.frozen {
            return;
        }
        self.snapshot_seen = true;
        self.written += data.len() as u64;
        self.images.entry(image).or_default().push(ImageData {
            aspect,
            level_sizes,
            data,
        });
    }

    /// A shader module's SPIR-V.
    pub fn module(&mut self, module: u64, code: Vec<u8>) {
        self.modules.insert(module, code);
    }

    /// The contents of buffer `handle` at this point: its snapshot, else what was written to
    /// the memory it is bound to.
    pub(super) fn buffer_bytes(&mut self, handle: u64, objects: &Objects) -> Option<Vec<u8>> {
        if self.gpu_written.contains(&handle) {
            return None;
        }
        let info = objects.buffers.get(&handle)?;
        if let Some(d) = self.buffers.get(&handle) {
            if d.len() as u64 != info.size {
                return None;
            }
            let mut d = self.buffers.remove(&handle)?;
            if let Some((memory, bound)) = info.bound {
                let end = bound.saturating_add(info.size);
                for (m, at, bytes) in &self.late_fills {
                    let stop = at.saturating_add(bytes.len() as u64);
                    let (from, to) = ((*at).max(bound), stop.min(end));
                    if *m == memory && from < to {
                        d[(from - bound) as usize..(to - bound) as usize]
                            .copy_from_slice(&bytes[(from - at) as usize..(to - at) as usize]);
                    }
                }
            }
            return Some(d);
        }
        let (memory, offset) = info.bound?;
        self.memory.get(&memory)?.read(offset, info.size)
    }

    /// The contents of image `handle`: its snapshot's color or depth aspect, else, for a
    /// single-level linear image the application wrote through a mapping, its rows read
    /// from that memory at the pitch the driver gave.
    fn image_bytes(&mut self, handle: u64, img: &ImageInfo, size: u64) -> Option<Vec<u8>> {
        if self.gpu_written.contains(&handle) {
            return None;
        }
        if let Some(data) = self.uploaded.remove(&handle) {
            return (data.len() as u64 == size).then_some(data);
        }
        self.image_snapshot(handle, img, size)
    }

    /// An image's snapshot or linear contents, as `image_bytes` without copies.
    pub(super) fn image_snapshot(
        &mut self,
        handle: u64,
        img: &ImageInfo,
        size: u64,
    ) -> Option<Vec<u8>> {
        if let Some(aspects) = self.images.get_mut(&handle) {
            // Color (1) or depth (2); a stencil aspect (4) travels with depth in one resource
            // only where the format packs them, which the size check decides.
            let a = aspects.iter_mut().find(|a| a.aspect & 0x3 != 0)?;
            let data = std::mem::take(&mut a.data);
            if data.len() as u64 == size {
                return Some(data);
            }
            return unpad(img, &a.level_sizes, data);
        }
        let Some(&(pitch, first)) = self.linear.get(&handle) else {
            return self.laid_out(img, size);
        };
        let (memory, bound) = img.bound?;
        let rows = u64::from(img.extent[1]);
        if img.mips != 1 || img.layers != 1 || img.extent[2] != 1 || rows == 0 {
            return None;
        }
        let row = size / rows;
        if pitch < row || pitch.checked_mul(rows)? > MAX_BLOCK_BYTES {
            return None;
        }
        let whole = self
            .memory
            .get(&memory)?
            .read(bound.checked_add(first)?, pitch * (rows - 1) + row)?;
        let mut out = Vec::with_capacity(size as usize);
        for r in 0..rows {
            let at = (r * pitch) as usize;
            out.extend_from_slice(&whole[at..at + row as usize]);
        }
        Some(out)
    }

    /// An image without a snapshot, read from the bytes of the memory bound to it as the
    /// capturing driver lays images out (`driver_layout`), where that is known and the
    /// capture wrote that memory.
    fn laid_out(&mut self, img: &ImageInfo, size: u64) -> Option<Vec<u8>> {
        let (slices, span) = self.layout.slices(img)?;
        let (memory, bound) = img.bound?;
        let whole = self.memory.get(&memory)?.read(bound, span)?;
        let mut out = Vec::new();
        out.try_reserve_exact(size as usize).ok()?;
        for (at, pitch, rows, row) in slices {
            for r in 0..rows {
                let from = usize::try_from(at + r * pitch).ok()?;
                out.extend_from_slice(whole.get(from..from.checked_add(row as usize)?)?);
            }
        }
        if out.len() as u64 != size {
            return None;
        }
        self.laid_out += 1;
        Some(out)
    }

    /// Gives each resource whose contents are known its bytes in `pack`, and returns how
    /// many resources and bytes that was and notes on what stays unknown.
    pub fn attach(
        &mut self,
        names: &BTreeMap<u64, String>,
        objects: &Objects,
        capture: &mut RawCapture,
        pack: &mut Pack,
    ) -> ((usize, u64), Vec<String>) {
        let by_name: HashMap<&str, u64> = names.iter().map(|(h, n)| (n.as_str(), *h)).collect();
        let (mut filled, mut filled_bytes) = (0usize, 0u64);
        let mut unknown = Vec::new();
        let mut wrong_size = Vec::new();
        let mut over_budget = Vec::new();
        let mut budget = self.written.saturating_add(ZERO_ALLOWANCE);
        for r in &mut capture.resources {
            let Some(&h) = by_name.get(r.name.as_str()) else {
                continue;
            };
            let (bytes, size) = match objects.images.get(&h) {
                Some(img) => {
                    let size = packed_size(img);
                    if size.is_some_and(|s| s > budget) {
                        over_budget.push(r.name.clone());
                        continue;
                    }
                    (size.and_then(|s| self.image_bytes(h, img, s)), size)
                }
                None => {
                    let size = objects.buffers.get(&h).map(|b| b.size);
                    if size.is_some_and(|s| s > budget) {
                        over_budget.push(r.name.clone());
                        continue;
                    }
                    (self.buffer_bytes(h, objects), size)
                }
            };
            if let Some(b) = &bytes {
                budget = budget.saturating_sub(b.len() as u64);
            }
            match bytes {
                Some(bytes) if Some(bytes.len() as u64) == size => {
                    filled += 1;
                    filled_bytes += bytes.len() as u64;
                    let offset = pack.add(bytes);
                    r.initial = Some(InitialContents::File {
                        path: pack.path.clone(),
                        offset: Some(offset),
                    });
                }
                Some(bytes) => wrong_size.push(format!("{} ({} bytes)", r.name, bytes.len())),
                None => {
                    if matches!(r.initial, Some(InitialContents::BeforeCapture {})) {
                        unknown.push(r.name.clone());
                    }
                }
            }
        }
        // Names a note lists: a frame may leave hundreds of resources unfilled.
        const LISTED: usize = 8;
        let mut notes = Vec::new();
        if !unknown.is_empty() {
            notes.push(format!(
                "contents of {} resource(s) from before the frame that the capture does not hold (earlier GPU work, or never written): {}",
                unknown.len(),
                crate::text::listed(&unknown, LISTED)
            ));
        }
        if self.laid_out > 0 {
            notes.push(format!(
                "contents of {} image(s) read from the bytes of their memory as {:?} lays images out (the capture's state snapshot holds none for them)",
                self.laid_out, self.layout
            ));
        }
        if !over_budget.is_empty() {
            notes.push(format!(
                "contents larger than everything the capture wrote (left out): {}",
                crate::text::listed(&over_budget, LISTED)
            ));
        }
        if !wrong_size.is_empty() {
            notes.push(format!(
                "snapshot contents whose size is not the resource's packed size (left out): {}",
                crate::text::listed(&wrong_size, LISTED)
            ));
        }
        ((filled, filled_bytes), notes)
    }
}

/// A snapshot the driver padded, packed. GFXReconstruct's snapshot of an optimal image gives
/// each level the size the driver lays it out in, which may exceed its texels; the level's
/// texels come tightly packed from its start, its layers and slices one after the other, and
/// the rest is padding (lavapipe: a 197x13 RGBA8 level of 10,244 bytes comes in 13,312, a
/// 300-row depth buffer's in the size of 304 rows, a 2x2x2 volume's 32 bytes in 512, a 4x4
/// cube's six faces in 1,536 bytes). `None` where a level is smaller than its texels.
fn unpad(img: &ImageInfo, level_sizes: &[u64], mut data: Vec<u8>) -> Option<Vec<u8>> {
    let f = dxgi::lookup_vk(&img.format)?;
    let (block, bytes) = (
        u64::from(f.block_width.max(1)),
        u64::from(f.bits_per_element) / 8,
    );
    if bytes == 0 || level_sizes.len() != img.mips as usize {
        return None;
    }
    // Packed, each level is no longer than its padded self, so its texels move down in place.
    let (mut from, mut to) = (0usize, 0usize);
    for (l, &size) in level_sizes.iter().enumerate() {
        let dim = |d: u32| u64::from((d >> l).max(1));
        let row = dim(img.extent[0]).div_ceil(block) * bytes;
        let rows = dim(img.extent[1]).div_ceil(block);
        let slabs = dim(img.extent[2]) * u64::from(img.layers.max(1));
        let keep = rows.checked_mul(row)?;
        if row == 0 || size < keep.checked_mul(slabs)? {
            return None;
        }
        let end = from.checked_add(size as usize)?;
        if end > data.len() {
            return None;
        }
        // The level's layers and slices, tightly packed from its start.
        let tight = (keep * slabs) as usize;
        data.copy_within(from..from + tight, to);
        to += tight;
        from = end;
    }
    data.truncate(to);
    Some(data)
}

/// Bytes of every mip level and layer of a single-sampled image, tightly packed: the layout
/// of a snapshot and of a `file`'s contents.
pub(super) fn packed_size(img: &ImageInfo) -> Option<u64> {
    if img.samples > 1 {
        return None;
    }
    dxgi::lookup_vk(&img.format)?.texture_bytes(
        (img.extent[0], img.extent[1], img.extent[2]),
        img.layers.max(1),
        img.mips.min(32),
        1,
    )
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A 2D image not bound to memory, for tests here and of the copies before a frame.
    pub(in crate::import) fn image(
        format: &str,
        extent: [u32; 3],
        mips: u32,
        layers: u32,
    ) -> ImageInfo {
        ImageInfo {
            format: format.to_owned(),
            image_type: "VK_IMAGE_TYPE_2D".to_owned(),
            extent,
            mips,
            layers,
            samples: 1,
            usage: 0,
            create_flags: 0,
            bound: None,
            alignment: None,
            swapchain: None,
            created_at: 0,
            destroyed_at: None,
        }
    }

    /// Lavapipe's snapshot of a 4x4 RGBA8 image holds 16 rows of 16 bytes: the texture is the
    /// first four (read as 64-byte rows instead, three of them would be the padding's zeros).
    #[test]
    fn padded_levels_keep_their_first_rows() {
        let data: Vec<u8> = (0..256u32)
            .map(|i| if i < 64 { i as u8 + 1 } else { 0 })
            .collect();
        let img = image("VK_FORMAT_R8G8B8A8_UNORM", [4, 4, 1], 1, 1);
        let packed = unpad(&img, &[256], data.clone()).unwrap();
        assert_eq!(packed, (1..=64u8).collect::<Vec<_>>());
        // Two layers in a padded level: both tightly packed from its start.
        let img = image("VK_FORMAT_R8G8B8A8_UNORM", [4, 4, 1], 1, 2);
        let two: Vec<u8> = (0..512u32)
            .map(|i| if i < 128 { i as u8 } else { 0x33 })
            .collect();
        assert_eq!(unpad(&img, &[512], two.clone()).unwrap(), two[..128]);
        // The two slices of a volume likewise (lavapipe's 2x2x2 lookup table in 512 bytes).
        let volume = image("VK_FORMAT_R8G8B8A8_UNORM", [2, 2, 2], 1, 1);
        let bytes: Vec<u8> = (0..512u32)
            .map(|i| if i < 32 { i as u8 } else { 0x33 })
            .collect();
        assert_eq!(
            unpad(&volume, &[512], bytes).unwrap(),
            (0..32u8).collect::<Vec<_>>()
        );
        // A size that is not whole padded rows: the same.
        assert_eq!(unpad(&img, &[500], two.clone()).unwrap(), two[..128]);
        // Smaller than the texels, or levels the image does not have: refused.
        assert!(unpad(&img, &[100], two.clone()).is_none());
        assert!(unpad(&img, &[512, 4], two).is_none());
    }

    /// Lavapipe's snapshot of Warzone 2100's 197x13 RGBA8 text label: 13,312 bytes, the
    /// 10,244 of its texels tightly packed first (rows 788 bytes apart, as the text reads).
    #[test]
    fn a_level_padded_at_its_end_keeps_its_tight_rows() {
        let data: Vec<u8> = (0..13_312u32).map(|i| (i % 251) as u8).collect();
        let img = image("VK_FORMAT_R8G8B8A8_UNORM", [197, 13, 1], 1, 1);
        let packed = unpad(&img, &[13_312], data.clone()).unwrap();
        assert_eq!(packed, data[..197 * 13 * 4]);
    }

    #[test]
    fn a_pack_shares_the_same_bytes_and_keeps_the_rest_apart() {
        let mut p = Pack::new("frame.contents");
        assert_eq!(p.add(vec![1; 300]), 0);
        assert_eq!(p.add(vec![2; 10]), 300);
        // Same length and ends, another middle: its own bytes.
        let mut other = vec![1; 300];
        other[150] = 9;
        assert_eq!(p.add(other), 310);
        assert_eq!(p.add(vec![1; 300]), 0, "equal bytes are shared");
        assert_eq!(p.add(vec![2; 10]), 300);
        let file = p.into_side_file().unwrap();
        assert_eq!(file.path, "frame.contents/contents.bin");
        assert_eq!(file.len(), 610);
        assert!(Pack::new("x").into_side_file().is_none());
    }

    #[test]
    fn later_writes_replace_what_they_cover() {
        let mut e = Extents::default();
        e.write(0, vec![1; 8]);
        e.write(4, vec![2; 8]);
        e.write(2, vec![3; 2]);
        assert_eq!(
            e.read(0, 12),
            Some(vec![1, 1, 3, 3, 2, 2, 2, 2, 2, 2, 2, 2])
        );
        assert_eq!(e.read(10, 4), Some(vec![2, 2, 0, 0]));
        assert_eq!(e.read(12, 4), None);
        assert_eq!(e.0.len(), 3);
        // A write past the end of the address space (a damaged offset, found by the RenderDoc
        // fuzz harness) is no write, not an overflow.
        e.write(u64::MAX - 2, vec![9; 8]);
        assert_eq!(e.0.len(), 3);
    }
}
