//! Copies of what each pass of the browsed frame wrote, kept on the replay device within a
//! memory budget the user sets. With them the worker shows any resource as of any pass without
//! replaying: the copy made after the last pass at or before it that wrote the resource (or at
//! the frame's start, before any pass wrote it). A copy the budget evicted, least recently used
//! first, is made again by a replay up to its pass.

/// What each plan pass writes: plan textures and plan buffers; and how many draws or
/// dispatches it has.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PassWrites {
    pub textures: Vec<usize>,
    pub buffers: Vec<usize>,
    pub steps: usize,
}

/// Where a resource's contents as of a pass come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Found<T> {
    /// A copy made right after pass `after` (`None`: at the frame's start).
    Copy { copy: T, after: Option<usize> },
    /// Nothing in the frame writes it: the resource itself holds its contents.
    Live,
    /// The copy made after `after` was evicted; replay up to the pass to make it again.
    Evicted { after: Option<usize> },
    /// The browsed frame has not been replayed that far yet.
    NotYet,
}

/// One copy of a resource.
#[derive(Debug)]
struct Entry<T> {
    after: Option<usize>,
    copy: Option<T>,
    bytes: u64,
    used: u64,
}

/// The copies of one resource, in pass order (the frame's start first).
#[derive(Debug)]
struct Track<T> {
    entries: Vec<Entry<T>>,
}

impl<T> Default for Track<T> {
    fn default() -> Self {
        Track {
            entries: Vec::new(),
        }
    }
}

/// Which kind of resource a copy is of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Texture,
    Buffer,
}

#[derive(Debug)]
pub struct Snapshots {
    textures: Vec<Track<wgpu::Texture>>,
    buffers: Vec<Track<wgpu::Buffer>>,
    budget: u64,
    used: u64,
    clock: u64,
    /// Passes of the browsed frame replayed so far (its copies made).
    done: Option<usize>,
    /// Copies evicted so far (reported with the memory in use).
    pub evicted: u64,
}

/// The bytes a copy of texture `t` takes: every mip, layer and sample.
pub fn texture_bytes(t: &wgpu::Texture) -> u64 {
    let format = t.format();
    let block = u64::from(format.block_copy_size(None).unwrap_or(8));
    let (bw, bh) = format.block_dimensions();
    (0..t.mip_level_count())
        .map(|mip| t.size().mip_level_size(mip, t.dimension()))
        .map(|s| {
            let s = s.physical_size(format);
            u64::from(s.width / bw)
                * u64::from(s.height / bh)
                * u64::from(s.depth_or_array_layers)
                * block
                * u64::from(t.sample_count())
        })
        .sum()
}

/// Encodes a copy of every mip, layer and sample of `source` into a new texture.
pub fn copy_texture(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    source: &wgpu::Texture,
) -> wgpu::Texture {
    let copy = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("framelab snapshot"),
        size: source.size(),
        mip_level_count: source.mip_level_count(),
        sample_count: source.sample_count(),
        dimension: source.dimension(),
        format: source.format(),
        usage: source.usage() | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    copy_into(encoder, source, &copy);
    copy
}

/// Encodes a copy of every mip of `source` into `target` (same size and format).
pub fn copy_into(
    encoder: &mut wgpu::CommandEncoder,
    source: &wgpu::Texture,
    target: &wgpu::Texture,
) {
    for mip in 0..source.mip_level_count() {
        let size = source.size().mip_level_size(mip, source.dimension());
        let at = |texture| wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: mip,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        };
        encoder.copy_texture_to_texture(
            at(source),
            at(target),
            size.physical_size(source.format()),
        );
    }
}

impl Snapshots {
    /// Room for `textures` and `buffers` plan resources, keeping at most `budget` bytes of
    /// copies.
    pub fn new(textures: usize, buffers: usize, budget: u64) -> Snapshots {
        Snapshots {
            textures: (0..textures).map(|_| Track::default()).collect(),
            buffers: (0..buffers).map(|_| Track::default()).collect(),
            budget,
            used: 0,
            clock: 0,
            done: None,
            evicted: 0,
        }
    }

    /// Bytes of copies held.
    pub fn used(&self) -> u64 {
        self.used
    }

    /// The last pass of the browsed frame whose copies are made.
    pub fn done(&self) -> Option<usize> {
        self.done
    }

    /// Records that the browsed frame has been replayed through `pass`.
    pub fn mark_done(&mut self, pass: usize) {
        self.done = Some(pass);
    }

    /// Whether the browsed frame has been replayed through `pass`.
    pub fn ready(&self, pass: usize) -> bool {
        self.done.is_some_and(|d| pass <= d)
    }

    /// Plan texture `t` as of right after `pass`.
    pub fn texture(&mut self, t: usize, pass: usize) -> Found<wgpu::Texture> {
        let ready = self.ready(pass);
        self.clock += 1;
        let clock = self.clock;
        find(self.textures.get_mut(t), pass, ready, clock)
    }

    /// The copy of plan texture `t` made at the frame's start, if it is held.
    pub fn frame_start_texture(&self, t: usize) -> Option<wgpu::Texture> {
        self.textures
            .get(t)?
            .entries
            .first()
            .filter(|e| e.after.is_none())?
            .copy
            .clone()
    }

    /// Plan buffer `b` as of right after `pass`.
    pub fn buffer(&mut self, b: usize, pass: usize) -> Found<wgpu::Buffer> {
        let ready = self.ready(pass);
        self.clock += 1;
        let clock = self.clock;
        find(self.buffers.get_mut(b), pass, ready, clock)
    }

    /// Encodes a copy of `source` (plan texture `t`) as it is after `after` and keeps it,
    /// evicting the least recently used copies beyond the budget. A texture larger than the
    /// whole budget is recorded as evicted.
    pub fn keep_texture(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        t: usize,
        after: Option<usize>,
        source: &wgpu::Texture,
    ) {
        let bytes = texture_bytes(source);
        let copy = (bytes <= self.budget).then(|| copy_texture(device, encoder, source));
        self.clock += 1;
        let (held, clock) = (copy.is_some(), self.clock);
        let freed = put(self.textures.get_mut(t), after, copy, bytes, clock);
        self.account(held, bytes, freed, (Kind::Texture, t, after));
    }

    /// Encodes a copy of `source` (plan buffer `b`) as it is after `after` and keeps it.
    pub fn keep_buffer(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        b: usize,
        after: Option<usize>,
        source: &wgpu::Buffer,
    ) {
        let bytes = source.size();
        let copy = (bytes <= self.budget).then(|| {
            let copy = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("framelab snapshot"),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            encoder.copy_buffer_to_buffer(source, 0, &copy, 0, bytes & !3);
            copy
        });
        self.clock += 1;
        let (held, clock) = (copy.is_some(), self.clock);
        let freed = put(self.buffers.get_mut(b), after, copy, bytes, clock);
        self.account(held, bytes, freed, (Kind::Buffer, b, after));
    }

    /// Counts a copy of `bytes` put in place of one holding `freed`, then evicts beyond the
    /// budget (never the copy just kept).
    fn account(&mut self, held: bool, bytes: u64, freed: u64, kept: (Kind, usize, Option<usize>)) {
        if held {
            self.used += bytes;
        }
        self.used -= freed;
        self.evict(kept);
    }

    /// Drops the least recently used copies, never `keep`, until the budget holds.
    fn evict(&mut self, keep: (Kind, usize, Option<usize>)) {
        while self.used > self.budget {
            let mut oldest: Option<(u64, Kind, usize, usize)> = None;
            let mut consider = |kind: Kind, index: usize, e: usize, used: u64, after| {
                if (kind, index, after) != keep && oldest.is_none_or(|o| used < o.0) {
                    oldest = Some((used, kind, index, e));
                }
            };
            for (i, track) in self.textures.iter().enumerate() {
                for (e, entry) in track.entries.iter().enumerate() {
                    if entry.copy.is_some() {
                        consider(Kind::Texture, i, e, entry.used, entry.after);
                    }
                }
            }
            for (i, track) in self.buffers.iter().enumerate() {
                for (e, entry) in track.entries.iter().enumerate() {
                    if entry.copy.is_some() {
                        consider(Kind::Buffer, i, e, entry.used, entry.after);
                    }
                }
            }
            let Some((_, kind, index, e)) = oldest else {
                return;
            };
            let bytes = match kind {
                Kind::Texture => drop_copy(&mut self.textures[index].entries[e]),
                Kind::Buffer => drop_copy(&mut self.buffers[index].entries[e]),
            };
            self.used -= bytes;
            self.evicted += 1;
        }
    }
}

fn drop_copy<T>(entry: &mut Entry<T>) -> u64 {
    if entry.copy.take().is_some() {
        entry.bytes
    } else {
        0
    }
}

/// Puts a copy made after `after` in its place in `track` (replacing one made there before)
/// and returns the bytes the replaced copy held.
fn put<T>(
    track: Option<&mut Track<T>>,
    after: Option<usize>,
    copy: Option<T>,
    bytes: u64,
    clock: u64,
) -> u64 {
    let Some(track) = track else {
        return 0;
    };
    let entry = Entry {
        after,
        copy,
        bytes,
        used: clock,
    };
    match track.entries.binary_search_by(|e| e.after.cmp(&after)) {
        Ok(i) => {
            let freed = drop_copy(&mut track.entries[i]);
            track.entries[i] = entry;
            freed
        }
        Err(i) => {
            track.entries.insert(i, entry);
            0
        }
    }
}

fn find<T: Clone>(track: Option<&mut Track<T>>, pass: usize, ready: bool, clock: u64) -> Found<T> {
    if !ready {
        return Found::NotYet;
    }
    let Some(track) = track.filter(|t| !t.entries.is_empty()) else {
        return Found::Live;
    };
    // `None` (the frame's start) orders before every pass.
    let Some(entry) = track
        .entries
        .iter_mut()
        .rev()
        .find(|e| e.after.is_none_or(|a| a <= pass))
    else {
        return Found::Live;
    };
    match &entry.copy {
        Some(copy) => {
            entry.used = clock;
            Found::Copy {
                copy: copy.clone(),
                after: entry.after,
            }
        }
        None => Found::Evicted { after: entry.after },
    }
}
