//! Turns a call's encoded parameters into the JSON the JSON Lines importer reads, driven by
//! the registry tables: one decoder for every call and structure, so the binary capture and
//! `gfxrecon-convert`'s stream of the same frame reach the importer in the same shape
//! (pointers to one value inline, arrays as arrays, handles as numbers, enums by name).
//!
//! Lengths come from the data and are checked against the bytes left before anything is
//! allocated for them; nesting is bounded, so no input can take memory or stack beyond its
//! own size.

use std::borrow::Cow;

use super::super::tree::{Node, Text, Tree, int};
use super::super::value::shortest;
use super::registry::{self, CommandDef, STRUCTS, Ty};

const IS_NULL: u32 = 0x1;
const IS_ARRAY: u32 = 0x4;
const IS_STRING: u32 = 0x8;
const IS_WSTRING: u32 = 0x10;
const IS_ARRAY_2D: u32 = 0x100;
const HAS_ADDRESS: u32 = 0x40;
const HAS_DATA: u32 = 0x80;
/// Deepest nesting of structures and `pNext` chains read.
const MAX_DEPTH: u32 = 48;

/// A decoded call: its arguments by name (in the tree given to `decode_call`), and its
/// return value as the JSON Lines stream writes it.
#[derive(Debug)]
pub struct Decoded {
    /// Borrowed from the tables where it is an enumerant (`VK_SUCCESS`), as it mostly is.
    pub ret: Option<Cow<'static, str>>,
    /// Long arrays of bytes or 32-bit words (SPIR-V code, update data), kept as raw bytes by their path (`pCreateInfo.pCode`) instead of one
    /// JSON number per element; the arguments show `"(N bytes)"` in their place, as the JSON
    /// Lines stream shows no data there either.
    pub blobs: Vec<(String, Vec<u8>)>,
}

/// Word arrays longer than this (SPIR-V) and byte arrays longer than `BLOB_BYTES_U8` (update
/// data, cache blobs) are kept as raw bytes; shorter ones, such as specialization data and
/// push constants, stay numbers the importer reads.
const BLOB_BYTES: usize = 256;
const BLOB_BYTES_U8: usize = 4096;

struct Reader<'a, 't> {
    buf: &'a [u8],
    tree: &'t mut Tree,
    pos: usize,
    depth: u32,
    /// Where the reader is (`pCreateInfo.pStages[1].pName`), kept as parts and spelt out only
    /// for an error, since most calls never need it; kept at all only when `track` is set.
    path: Vec<Part>,
    /// Whether `path` is kept. A call is decoded without it first; the rare call that needs
    /// it (an error to locate, a blob to name, a path to find) is decoded again with it.
    track: bool,
    blobs: Vec<(String, Vec<u8>)>,
    /// A parameter path to find (`locate`), and where its bytes were found.
    seek: Option<&'a str>,
    found: Option<(usize, usize)>,
}

#[derive(Clone, Copy, Debug)]
enum Part {
    Name(&'static str),
    Index(usize),
}

/// Why a call's parameters could not be decoded, and where: the parameter's path
/// (`pRegions[0].bufferOffset`; `the return value`), the byte of the call's parameters the
/// decoder had reached, and what it met there.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}", self.text())]
pub struct DecodeError {
    pub field: String,
    pub byte: usize,
    pub problem: Problem,
}

/// What a call's parameters break (`DecodeError`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Problem {
    /// `need` bytes asked for with `left` left.
    Truncated { need: usize, left: usize },
    /// A length of more elements than there are bytes left.
    Count { elements: u64, left: usize },
    /// A parameter type the tables give no way to read.
    UnreadableType,
    /// A structure index past the tables.
    NoStructure(u16),
    /// Structures nested deeper than `MAX_DEPTH`.
    TooDeep,
    /// A `pNext` element whose data ends before its `sType`.
    EndsBeforeSType,
    /// A `pNext` element of an `sType` the registry does not have.
    UnknownSType(u32),
    /// Update-template data written as an array, not in GFXReconstruct's layout.
    TemplateArray(u64),
    /// Update-template data whose counts need more bytes than are left.
    TemplateCounts {
        images: u64,
        buffers: u64,
        views: u64,
        left: usize,
    },
    /// An update-template data section of a descriptor type the decoder does not know.
    TemplateSection(u32),
    /// `locate`: the call has no number at the path asked for.
    NoNumber { call: &'static str, path: String },
    /// Not an error of the data: the call is decoded again with its path kept, so that a
    /// blob's elements can be found (see `Reader::track`).
    Retrack,
}

impl DecodeError {
    fn text(&self) -> String {
        let f = &self.field;
        match &self.problem {
            Problem::Truncated { need, left } => format!(
                "{f} needs {need} bytes at parameter byte {}, {left} left",
                self.byte
            ),
            Problem::Count { elements, left } => {
                format!("{f} says {elements} elements, but only {left} bytes are left")
            }
            Problem::UnreadableType => format!("{f} has a type this decoder cannot read"),
            Problem::NoStructure(i) => format!("{f}: no structure {i} in the tables"),
            Problem::TooDeep => format!("{f}: structures nested deeper than {MAX_DEPTH}"),
            Problem::EndsBeforeSType => format!("{f}: the data ends before the sType"),
            Problem::UnknownSType(t) => format!("{f}: a structure with unknown sType {t}"),
            Problem::TemplateArray(len) => format!(
                "{f}: template data written as an array of {len}, not GFXReconstruct's layout"
            ),
            Problem::TemplateCounts {
                images,
                buffers,
                views,
                left,
            } => format!(
                "{f}: {images} image infos, {buffers} buffer infos and {views} texel buffer views need more than the {left} bytes left"
            ),
            Problem::TemplateSection(t) => format!(
                "{f}: a template data section of descriptor type {t} this decoder does not know"
            ),
            Problem::NoNumber { call, path } => format!(
                "{call} has no number at `{path}` (a path is spelt like `pImageMemoryBarriers[0].oldLayout`)"
            ),
            Problem::Retrack => "(decode again with the path kept)".to_owned(),
        }
    }
}

/// Why a call could not be decoded, boxed so that every result on the path each value takes
/// is two words, returned in registers rather than through memory.
#[derive(Debug)]
struct Fail(Box<DecodeError>);

type Res<T> = Result<T, Fail>;

impl<'a> Reader<'a, '_> {
    /// `problem` where the decoder is.
    #[cold]
    fn fail(&self, problem: Problem) -> Fail {
        Fail(Box::new(DecodeError {
            field: self.at(),
            byte: self.pos,
            problem,
        }))
    }

    fn take(&mut self, n: usize) -> Res<&'a [u8]> {
        let left = self.buf.len() - self.pos;
        if n > left {
            return Err(self.fail(Problem::Truncated { need: n, left }));
        }
        let s = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// The path spelt out, for messages.
    fn at(&self) -> String {
        let mut s = String::new();
        for p in &self.path {
            match p {
                Part::Name(n) if s.is_empty() => s.push_str(n),
                Part::Name(n) => {
                    s.push('.');
                    s.push_str(n);
                }
                Part::Index(i) => s.push_str(&format!("[{i}]")),
            }
        }
        if s.is_empty() {
            "the return value".to_owned()
        } else {
            s
        }
    }

    fn array<const N: usize>(&mut self) -> Res<[u8; N]> {
        let mut a = [0; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }

    fn u32(&mut self) -> Res<u32> {
        self.array().map(u32::from_le_bytes)
    }

    fn u64(&mut self) -> Res<u64> {
        self.array().map(u64::from_le_bytes)
    }

    /// `f` with `part` on the path.
    #[inline]
    fn within<T>(&mut self, part: Part, f: impl FnOnce(&mut Self) -> Res<T>) -> Res<T> {
        if !self.track {
            return f(self);
        }
        self.path.push(part);
        let r = f(self);
        self.path.pop();
        r
    }

    fn left(&self) -> usize {
        self.buf.len() - self.pos
    }

    /// A pointer's preamble: the attribute mask, the address when flagged, the length for
    /// arrays and strings (else 1). `None` for a null pointer.
    fn preamble(&mut self) -> Res<Option<(u32, u64)>> {
        let attrib = self.u32()?;
        if attrib & IS_NULL != 0 {
            return Ok(None);
        }
        if attrib & HAS_ADDRESS != 0 {
            self.u64()?;
        }
        let len = if attrib & (IS_ARRAY | IS_ARRAY_2D | IS_STRING | IS_WSTRING) != 0 {
            self.u64()?
        } else {
            1
        };
        Ok(Some((attrib, len)))
    }

    /// A length read from the data, refused when even one byte per element would not fit.
    fn count(&self, len: u64) -> Res<usize> {
        if len > self.left() as u64 {
            return Err(self.fail(Problem::Count {
                elements: len,
                left: self.left(),
            }));
        }
        Ok(len as usize)
    }

    fn leaf(&mut self, node: Node) -> Res<usize> {
        Ok(self.tree.leaf(node))
    }

    fn value(&mut self, ty: Ty) -> Res<usize> {
        if let Some(seek) = self.seek {
            let width = match ty {
                Ty::U8 => 1,
                Ty::U16 => 2,
                Ty::U32 | Ty::Flags32 | Ty::I32 | Ty::F32 | Ty::Enum(_) => 4,
                Ty::U64 | Ty::Flags64 | Ty::Handle | Ty::Address | Ty::I64 | Ty::F64 => 8,
                _ => 0,
            };
            if width > 0 && self.found.is_none() && self.at() == seek {
                self.found = Some((self.pos, width));
            }
        }
        let scalar = match ty {
            Ty::U8 => Node::U64(u64::from(self.array::<1>()?[0])),
            Ty::U16 => Node::U64(u64::from(u16::from_le_bytes(self.array()?))),
            Ty::U32 | Ty::Flags32 => Node::U64(u64::from(self.u32()?)),
            Ty::I32 => int(i64::from(i32::from_le_bytes(self.array()?))),
            Ty::U64 | Ty::Flags64 | Ty::Handle | Ty::Address => Node::U64(self.u64()?),
            Ty::I64 => int(i64::from_le_bytes(self.array()?)),
            Ty::F32 => Node::F64(shortest(f32::from_le_bytes(self.array()?))),
            Ty::F64 => Node::F64(f64::from_le_bytes(self.array()?)),
            Ty::Enum(table) => Node::Enum {
                table,
                value: i32::from_le_bytes(self.array()?),
            },
            _ => return self.composite(ty),
        };
        self.leaf(scalar)
    }

    fn composite(&mut self, ty: Ty) -> Res<usize> {
        match ty {
            Ty::Struct(s) => self.structure(s),
            Ty::PNext => self.pnext(),
            Ty::Ptr(elem) => self.pointer(*elem),
            Ty::Arr(elem) => {
                let v = self.pointer(*elem)?;
                match self.tree.node(v) {
                    Node::Array(_) | Node::Null => Ok(v),
                    _ => {
                        let mark = self.tree.mark();
                        self.tree.element(v);
                        Ok(self.tree.array(mark))
                    }
                }
            }
            Ty::Str => self.string(),
            Ty::Strs => match self.preamble()? {
                Some((attrib, len)) if attrib & HAS_DATA != 0 => {
                    let n = self.count(len)?;
                    let mark = self.tree.mark();
                    for i in 0..n {
                        let item = self.within(Part::Index(i), Self::string)?;
                        self.tree.element(item);
                    }
                    Ok(self.tree.array(mark))
                }
                _ => self.leaf(Node::Null),
            },
            _ => Err(self.fail(Problem::UnreadableType)),
        }
    }

    fn string(&mut self) -> Res<usize> {
        match self.preamble()? {
            Some((attrib, len)) if attrib & HAS_DATA != 0 => {
                let n = self.count(len)?;
                let bytes = self.take(n)?;
                let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
                let text = String::from_utf8_lossy(&bytes[..end]);
                Ok(self.tree.string(&text))
            }
            _ => self.leaf(Node::Null),
        }
    }

    fn pointer(&mut self, elem: Ty) -> Res<usize> {
        let Some((attrib, len)) = self.preamble()? else {
            return self.leaf(Node::Null);
        };
        if attrib & HAS_DATA == 0 {
            return self.leaf(Node::Null);
        }
        if attrib & IS_ARRAY == 0 {
            return self.value(elem);
        }
        let n = self.count(len)?;
        let width = match elem {
            Ty::U8 => 1,
            Ty::U32 => 4,
            _ => 0,
        };
        let limit = if width == 1 {
            BLOB_BYTES_U8
        } else {
            BLOB_BYTES
        };
        if width > 0 && n * width > limit {
            if !self.track {
                return Err(self.fail(Problem::Retrack));
            }
            // An element of the blob (`pCreateInfo.pCode[5]`, a word of shader code) is found
            // as any scalar is.
            if let Some(seek) = self.seek
                && self.found.is_none()
                && let Some(i) = seek
                    .strip_prefix(self.at().as_str())
                    .and_then(|rest| rest.strip_prefix('['))
                    .and_then(|rest| rest.strip_suffix(']'))
                    .and_then(|i| i.parse::<usize>().ok())
                    .filter(|i| *i < n)
            {
                self.found = Some((self.pos + i * width, width));
            }
            let bytes = self.take(n * width)?.to_vec();
            let shown = self.tree.string(&format!("({} bytes)", bytes.len()));
            self.blobs.push((self.at(), bytes));
            return Ok(shown);
        }
        let mark = self.tree.mark();
        for i in 0..n {
            let item = self.within(Part::Index(i), |r| r.value(elem))?;
            self.tree.element(item);
        }
        Ok(self.tree.array(mark))
    }

    fn structure(&mut self, index: u16) -> Res<usize> {
        let def = STRUCTS
            .get(usize::from(index))
            .ok_or_else(|| self.fail(Problem::NoStructure(index)))?;
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.fail(Problem::TooDeep));
        }
        let mark = self.tree.mark();
        for m in def.members {
            let v = self.within(Part::Name(m.name), |r| r.value(m.ty))?;
            self.tree.member(Text::Static(m.name), v);
            // The union's other view: the same first two words as a depth and a stencil
            // value, which a depth/stencil attachment's clear reads.
            if def.name == "VkClearValue" && m.name == "color" {
                let ds = self.clear_depth_stencil_view(v);
                self.tree.member(Text::Static("depthStencil"), ds);
            }
        }
        self.depth -= 1;
        let object = self.tree.object(mark);
        if def.name == "VkClearColorValue" {
            return Ok(self.clear_color_views(object));
        }
        Ok(object)
    }

    /// A `pNext` element: the preamble, then the structure its `sType` names (read ahead,
    /// since the structure repeats it).
    fn pnext(&mut self) -> Res<usize> {
        let attrib = self.u32()?;
        if attrib & IS_NULL != 0 {
            return self.leaf(Node::Null);
        }
        if attrib & HAS_ADDRESS != 0 {
            self.u64()?;
        }
        if attrib & HAS_DATA == 0 {
            return self.leaf(Node::Null);
        }
        let stype = u32::from_le_bytes(
            self.buf
                .get(self.pos..self.pos + 4)
                .and_then(|s| s.try_into().ok())
                .ok_or_else(|| self.fail(Problem::EndsBeforeSType))?,
        );
        let index = registry::struct_index_of_stype(stype)
            .ok_or_else(|| self.fail(Problem::UnknownSType(stype)))?;
        self.structure(index)
    }

    /// A clear value's `depthStencil` view of the colour words already read (`color`): the
    /// first as a 32-bit float depth, the second as the stencil value, as the JSON Lines
    /// stream shows it.
    fn clear_depth_stencil_view(&mut self, color: usize) -> usize {
        let tree = &mut *self.tree;
        let words = union_words(tree, color);
        let word = |i: usize| words.get(i).copied().unwrap_or(0);
        let mark = tree.mark();
        let depth = tree.leaf(Node::F64(shortest(f32::from_bits(word(0)))));
        tree.member(Text::Static("depth"), depth);
        let stencil = tree.leaf(Node::U64(u64::from(word(1))));
        tree.member(Text::Static("stencil"), stencil);
        tree.object(mark)
    }

    /// A clear colour is a union GFXReconstruct writes as its four `uint32` words; it is
    /// given back in all three of its views, as the JSON Lines stream shows it.
    fn clear_color_views(&mut self, object: usize) -> usize {
        let tree = &mut *self.tree;
        let words = union_words(tree, object);
        let views: [(&'static str, View); 3] = [
            ("float32", |w| Node::F64(shortest(f32::from_bits(w)))),
            ("int32", |w| int(i64::from(w as i32))),
            ("uint32", |w| Node::U64(u64::from(w))),
        ];
        let mark = tree.mark();
        for (name, view) in views {
            let inner = tree.mark();
            for w in &words {
                let n = tree.leaf(view(*w));
                tree.element(n);
            }
            let a = tree.array(inner);
            tree.member(Text::Static(name), a);
        }
        tree.object(mark)
    }
}

/// One view of a clear colour's words.
type View = fn(u32) -> Node;

/// Calls whose `pData` is an update template's data, which GFXReconstruct writes in a layout
/// of its own rather than as the application's bytes.
const TEMPLATE_CALLS: [&str; 4] = [
    "vkUpdateDescriptorSetWithTemplate",
    "vkUpdateDescriptorSetWithTemplateKHR",
    "vkCmdPushDescriptorSetWithTemplateKHR",
    "vkCmdPushDescriptorSetWithTemplate",
];

/// `VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR` and `..._INLINE_UNIFORM_BLOCK`: the tags
/// of the optional sections after the three groups.
const ACCELERATION_STRUCTURES: u32 = 1_000_150_000;
const INLINE_UNIFORM_BLOCK: u32 = 1_000_138_000;

impl Reader<'_, '_> {
    /// An update template's data as GFXReconstruct writes it: the pointer's preamble, the
    /// counts of image infos, buffer infos and texel buffer views (u64 each), then each group
    /// packed (image infos as sampler, view and layout; buffer infos as buffer, offset and
    /// range; views as handles), then optional sections (a u64 count and a u32 descriptor
    /// type: acceleration structures as handles, an inline uniform block as bytes) to the end
    /// of the parameters. Each group lists the template's entries of its kinds in entry
    /// order, every element of each; pairing them with the entries is the importer's. Given
    /// as `gfxrecon-convert` 1.x writes it (`imageInfos`, `bufferInfos`, `bufferViews`).
    fn template_data(&mut self) -> Res<usize> {
        let attrib = self.u32()?;
        if attrib & IS_NULL != 0 {
            return self.leaf(Node::Null);
        }
        if attrib & HAS_ADDRESS != 0 {
            self.u64()?;
        }
        if attrib & (IS_ARRAY | IS_ARRAY_2D | IS_STRING | IS_WSTRING) != 0 {
            // The capture layer writes an empty array for a template it did not know.
            let len = self.u64()?;
            if len == 0 {
                return self.leaf(Node::Null);
            }
            return Err(self.fail(Problem::TemplateArray(len)));
        }
        if attrib & HAS_DATA == 0 {
            return self.leaf(Node::Null);
        }
        let counts = [self.u64()?, self.u64()?, self.u64()?];
        let needed = counts[0]
            .checked_mul(20)
            .zip(counts[1].checked_mul(24))
            .zip(counts[2].checked_mul(8))
            .and_then(|((a, b), c)| a.checked_add(b)?.checked_add(c));
        if needed.is_none_or(|n| n > self.left() as u64) {
            return Err(self.fail(Problem::TemplateCounts {
                images: counts[0],
                buffers: counts[1],
                views: counts[2],
                left: self.left(),
            }));
        }
        let layouts = registry::enum_named("VkImageLayout");
        let out = self.tree.mark();
        let images = self.tree.mark();
        for _ in 0..counts[0] {
            let (sampler, view) = (self.u64()?, self.u64()?);
            let layout = i32::from_le_bytes(self.array()?);
            let layout = match layouts.and_then(|e| e.name_of(layout)) {
                Some(name) => Node::Str(Text::Static(name)),
                None => int(i64::from(layout)),
            };
            let info = self.tree.mark();
            self.member("sampler", Node::U64(sampler));
            self.member("imageView", Node::U64(view));
            self.member("imageLayout", layout);
            let info = self.tree.object(info);
            self.tree.element(info);
        }
        let images = self.tree.array(images);
        let buffers = self.tree.mark();
        for _ in 0..counts[1] {
            let info = self.tree.mark();
            for name in ["buffer", "offset", "range"] {
                let v = self.u64()?;
                self.member(name, Node::U64(v));
            }
            let info = self.tree.object(info);
            self.tree.element(info);
        }
        let buffers = self.tree.array(buffers);
        let views = self.tree.mark();
        for _ in 0..counts[2] {
            let v = self.u64()?;
            let v = self.leaf(Node::U64(v))?;
            self.tree.element(v);
        }
        let views = self.tree.array(views);
        self.tree.member(Text::Static("imageInfos"), images);
        self.tree.member(Text::Static("bufferInfos"), buffers);
        self.tree.member(Text::Static("bufferViews"), views);
        while self.left() > 0 {
            let count = self.u64()?;
            let ty = self.u32()?;
            let (name, n, width) = match ty {
                ACCELERATION_STRUCTURES => (
                    "accelStructViews",
                    self.count(count.saturating_mul(8))? / 8,
                    8,
                ),
                INLINE_UNIFORM_BLOCK => ("inlineUniformBlock", self.count(count)?, 1),
                other => {
                    return Err(self.fail(Problem::TemplateSection(other)));
                }
            };
            let items = self.tree.mark();
            for _ in 0..n {
                let v = if width == 8 {
                    self.u64()?
                } else {
                    u64::from(self.array::<1>()?[0])
                };
                let v = self.leaf(Node::U64(v))?;
                self.tree.element(v);
            }
            let items = self.tree.array(items);
            self.tree.member(Text::Static(name), items);
        }
        Ok(self.tree.object(out))
    }

    /// A scalar member of the object being built.
    fn member(&mut self, name: &'static str, node: Node) {
        let n = self.tree.leaf(node);
        self.tree.member(Text::Static(name), n);
    }
}

/// Decodes `params` (the bytes after the thread id) as the parameters of `def` into `tree`
/// (emptied first).
pub fn decode_call(
    def: &CommandDef,
    params: &[u8],
    tree: &mut Tree,
) -> Result<Decoded, DecodeError> {
    decode(def, params, None, tree).map(|(d, _)| d)
}

/// Where the scalar parameter at `path` (`pImageMemoryBarriers[0].oldLayout`) lies in
/// `params`: its byte offset and width.
pub fn locate(def: &CommandDef, params: &[u8], path: &str) -> Result<(usize, usize), DecodeError> {
    match decode(def, params, Some(path), &mut Tree::default())? {
        (_, Some(found)) => Ok(found),
        (_, None) => Err(DecodeError {
            field: path.to_owned(),
            byte: 0,
            problem: Problem::NoNumber {
                call: def.name,
                path: path.to_owned(),
            },
        }),
    }
}

fn decode<'a>(
    def: &CommandDef,
    params: &'a [u8],
    seek: Option<&'a str>,
    tree: &mut Tree,
) -> Result<(Decoded, Option<(usize, usize)>), DecodeError> {
    let tracked = if seek.is_some() {
        decode_with(def, params, seek, tree, true)
    } else {
        decode_with(def, params, None, tree, false)
            .or_else(|_| decode_with(def, params, None, tree, true))
    };
    tracked.map_err(|f| *f.0)
}

fn decode_with<'a>(
    def: &CommandDef,
    params: &'a [u8],
    seek: Option<&'a str>,
    tree: &mut Tree,
    track: bool,
) -> Res<(Decoded, Option<(usize, usize)>)> {
    tree.clear();
    let mut r = Reader {
        buf: params,
        tree,
        pos: 0,
        depth: 0,
        path: if track {
            Vec::with_capacity(8)
        } else {
            Vec::new()
        },
        track,
        blobs: Vec::new(),
        seek,
        found: None,
    };
    let args = r.tree.mark();
    for p in def.params {
        let v = if p.name == "pData" && TEMPLATE_CALLS.contains(&def.name) {
            r.within(Part::Name(p.name), Reader::template_data)?
        } else {
            r.within(Part::Name(p.name), |r| r.value(p.ty))?
        };
        r.tree.member(Text::Static(p.name), v);
    }
    let args = r.tree.object(args);
    r.tree.set_root(args);
    let ret = match def.ret {
        Some(ty) => {
            let v = r.value(ty)?;
            match r.tree.node(v) {
                Node::Str(Text::Static(name)) => Some(Cow::Borrowed(name)),
                Node::Str(t) => Some(Cow::Owned(r.tree.text(t).to_owned())),
                Node::U64(n) => Some(Cow::Owned(n.to_string())),
                Node::I64(n) => Some(Cow::Owned(n.to_string())),
                _ => None,
            }
        }
        None => None,
    };
    Ok((
        Decoded {
            ret,
            blobs: r.blobs,
        },
        r.found,
    ))
}

/// The four `uint32` words of a clear colour union (`object`) as decoded.
fn union_words(tree: &Tree, object: usize) -> Vec<u32> {
    match tree.get(object, "uint32").map(|a| tree.node(a)) {
        Some(Node::Array(run)) => tree
            .kids(run)
            .iter()
            .filter_map(|k| match tree.node(k.node) {
                Node::U64(w) => Some(w as u32),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(name: &str) -> &'static CommandDef {
        registry::COMMANDS.iter().find(|c| c.name == name).unwrap()
    }

    /// A call cut short says which parameter ran out, at which byte of the parameters, and
    /// how many bytes it needed and had; a path with no number says the call and the path.
    #[test]
    fn a_call_that_ends_early_is_located_by_parameter_and_byte() {
        // vkCmdDraw: a command buffer handle and four 32-bit counts, 24 bytes; 14 given.
        let def = command("vkCmdDraw");
        let e = decode_call(def, &[0; 14], &mut Tree::default()).unwrap_err();
        assert_eq!(e.field, "instanceCount");
        assert_eq!(e.byte, 12);
        assert_eq!(e.problem, Problem::Truncated { need: 4, left: 2 });
        assert_eq!(
            e.to_string(),
            "instanceCount needs 4 bytes at parameter byte 12, 2 left"
        );
        let whole = decode_call(def, &[0; 24], &mut Tree::default());
        assert!(whole.is_ok());
        let e = locate(def, &[0; 24], "vertexCount.x").unwrap_err();
        assert!(matches!(
            e.problem,
            Problem::NoNumber {
                call: "vkCmdDraw",
                ..
            }
        ));
    }
}
