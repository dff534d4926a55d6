//! Turns a call's encoded parameters into the JSON the JSON Lines importer reads, driven by
//! the registry tables: one decoder for every call and structure, so the binary capture and
//! `gfxrecon-convert`'s stream of the same frame reach the importer in the same shape
//! (pointers to one value inline, arrays as arrays, handles as numbers, enums by name).
//!
//! Lengths come from the data and are checked against the bytes left before anything is
//! allocated for them; nesting is bounded, so no input can take memory or stack beyond its
//! own size.

use serde_json::{Map, Value};

use super::super::value::shortest;
use super::registry::{self, CommandDef, ENUMS, STRUCTS, Ty};

const IS_NULL: u32 = 0x1;
const IS_ARRAY: u32 = 0x4;
const IS_STRING: u32 = 0x8;
const IS_WSTRING: u32 = 0x10;
const IS_ARRAY_2D: u32 = 0x100;
const HAS_ADDRESS: u32 = 0x40;
const HAS_DATA: u32 = 0x80;
/// Deepest nesting of structures and `pNext` chains read.
const MAX_DEPTH: u32 = 48;

/// A decoded call: its arguments by name, and its return value.
#[derive(Debug)]
pub struct Decoded {
    pub args: Value,
    pub ret: Option<Value>,
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

struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
    depth: u32,
    /// Where the reader is (`pCreateInfo.pStages[1].pName`), kept as parts and spelt out only
    /// for an error, since most calls never need it.
    path: Vec<Part>,
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

type Res<T> = Result<T, String>;

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Res<&'a [u8]> {
        let left = self.buf.len() - self.pos;
        if n > left {
            return Err(format!(
                "{} needs {n} bytes at parameter byte {}, {left} left",
                self.at(),
                self.pos
            ));
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
    fn within<T>(&mut self, part: Part, f: impl FnOnce(&mut Self) -> Res<T>) -> Res<T> {
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
            return Err(format!(
                "{} says {len} elements, but only {} bytes are left",
                self.at(),
                self.left()
            ));
        }
        Ok(len as usize)
    }

    fn value(&mut self, ty: Ty) -> Res<Value> {
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
        Ok(match ty {
            Ty::U8 => Value::from(self.array::<1>()?[0]),
            Ty::U16 => Value::from(u16::from_le_bytes(self.array()?)),
            Ty::U32 | Ty::Flags32 => Value::from(self.u32()?),
            Ty::I32 => Value::from(i32::from_le_bytes(self.array()?)),
            Ty::U64 | Ty::Flags64 | Ty::Handle | Ty::Address => Value::from(self.u64()?),
            Ty::I64 => Value::from(i64::from_le_bytes(self.array()?)),
            Ty::F32 => Value::from(shortest(f32::from_le_bytes(self.array()?))),
            Ty::F64 => Value::from(f64::from_le_bytes(self.array()?)),
            Ty::Enum(e) => {
                let v = i32::from_le_bytes(self.array()?);
                match ENUMS.get(usize::from(e)).and_then(|d| d.name_of(v)) {
                    Some(name) => Value::from(name),
                    None => Value::from(v),
                }
            }
            Ty::Struct(s) => self.structure(s)?,
            Ty::PNext => self.pnext()?,
            Ty::Ptr(elem) => self.pointer(*elem)?,
            Ty::Arr(elem) => match self.pointer(*elem)? {
                v @ (Value::Array(_) | Value::Null) => v,
                one => Value::Array(vec![one]),
            },
            Ty::Str => self.string()?,
            Ty::Strs => match self.preamble()? {
                Some((attrib, len)) if attrib & HAS_DATA != 0 => {
                    let n = self.count(len)?;
                    let mut items = Vec::with_capacity(n);
                    for i in 0..n {
                        items.push(self.within(Part::Index(i), Self::string)?);
                    }
                    Value::Array(items)
                }
                _ => Value::Null,
            },
            Ty::Opaque => return Err(format!("{} has a type this decoder cannot read", self.at())),
        })
    }

    fn string(&mut self) -> Res<Value> {
        match self.preamble()? {
            Some((attrib, len)) if attrib & HAS_DATA != 0 => {
                let n = self.count(len)?;
                let bytes = self.take(n)?;
                let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
                Ok(Value::from(
                    String::from_utf8_lossy(&bytes[..end]).into_owned(),
                ))
            }
            _ => Ok(Value::Null),
        }
    }

    fn pointer(&mut self, elem: Ty) -> Res<Value> {
        let Some((attrib, len)) = self.preamble()? else {
            return Ok(Value::Null);
        };
        if attrib & HAS_DATA == 0 {
            return Ok(Value::Null);
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
            let bytes = self.take(n * width)?.to_vec();
            let shown = Value::from(format!("({} bytes)", bytes.len()));
            self.blobs.push((self.at(), bytes));
            return Ok(shown);
        }
        let mut items = Vec::with_capacity(n);
        for i in 0..n {
            items.push(self.within(Part::Index(i), |r| r.value(elem))?);
        }
        Ok(Value::Array(items))
    }

    fn structure(&mut self, index: u16) -> Res<Value> {
        let def = STRUCTS
            .get(usize::from(index))
            .ok_or_else(|| format!("{}: no structure {index} in the tables", self.at()))?;
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(format!(
                "{}: structures nested deeper than {MAX_DEPTH}",
                self.at()
            ));
        }
        let mut map = Map::new();
        for m in def.members {
            let v = self.within(Part::Name(m.name), |r| r.value(m.ty))?;
            map.insert(m.name.to_owned(), v);
        }
        self.depth -= 1;
        if def.name == "VkClearColorValue" {
            return Ok(clear_color_views(map));
        }
        Ok(Value::Object(map))
    }

    /// A `pNext` element: the preamble, then the structure its `sType` names (read ahead,
    /// since the structure repeats it).
    fn pnext(&mut self) -> Res<Value> {
        let attrib = self.u32()?;
        if attrib & IS_NULL != 0 {
            return Ok(Value::Null);
        }
        if attrib & HAS_ADDRESS != 0 {
            self.u64()?;
        }
        if attrib & HAS_DATA == 0 {
            return Ok(Value::Null);
        }
        let stype = u32::from_le_bytes(
            self.buf
                .get(self.pos..self.pos + 4)
                .and_then(|s| s.try_into().ok())
                .ok_or_else(|| format!("{}: the data ends before the sType", self.at()))?,
        );
        let index = registry::struct_index_of_stype(stype)
            .ok_or_else(|| format!("{}: a structure with unknown sType {stype}", self.at()))?;
        self.structure(index)
    }
}

/// A clear colour is a union GFXReconstruct writes as its four `uint32` words; it is given
/// back in all three of its views, as the JSON Lines stream shows it.
fn clear_color_views(map: Map<String, Value>) -> Value {
    let words: Vec<u32> = map
        .get("uint32")
        .and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .filter_map(Value::as_u64)
                .map(|w| w as u32)
                .collect()
        })
        .unwrap_or_default();
    let float32: Vec<Value> = words
        .iter()
        .map(|w| Value::from(shortest(f32::from_bits(*w))))
        .collect();
    let int32: Vec<Value> = words.iter().map(|w| Value::from(*w as i32)).collect();
    let uint32: Vec<Value> = words.iter().map(|w| Value::from(*w)).collect();
    let mut out = Map::new();
    out.insert("float32".to_owned(), Value::Array(float32));
    out.insert("int32".to_owned(), Value::Array(int32));
    out.insert("uint32".to_owned(), Value::Array(uint32));
    Value::Object(out)
}

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

impl Reader<'_> {
    /// An update template's data as GFXReconstruct writes it: the pointer's preamble, the
    /// counts of image infos, buffer infos and texel buffer views (u64 each), then each group
    /// packed (image infos as sampler, view and layout; buffer infos as buffer, offset and
    /// range; views as handles), then optional sections (a u64 count and a u32 descriptor
    /// type: acceleration structures as handles, an inline uniform block as bytes) to the end
    /// of the parameters. Each group lists the template's entries of its kinds in entry
    /// order, every element of each; pairing them with the entries is the importer's. Given
    /// as `gfxrecon-convert` 1.x writes it (`imageInfos`, `bufferInfos`, `bufferViews`).
    fn template_data(&mut self) -> Res<Value> {
        let attrib = self.u32()?;
        if attrib & IS_NULL != 0 {
            return Ok(Value::Null);
        }
        if attrib & HAS_ADDRESS != 0 {
            self.u64()?;
        }
        if attrib & (IS_ARRAY | IS_ARRAY_2D | IS_STRING | IS_WSTRING) != 0 {
            // The capture layer writes an empty array for a template it did not know.
            let len = self.u64()?;
            if len == 0 {
                return Ok(Value::Null);
            }
            return Err(format!(
                "{}: template data written as an array of {len}, not GFXReconstruct's layout",
                self.at()
            ));
        }
        if attrib & HAS_DATA == 0 {
            return Ok(Value::Null);
        }
        let counts = [self.u64()?, self.u64()?, self.u64()?];
        let needed = counts[0]
            .checked_mul(20)
            .zip(counts[1].checked_mul(24))
            .zip(counts[2].checked_mul(8))
            .and_then(|((a, b), c)| a.checked_add(b)?.checked_add(c));
        if needed.is_none_or(|n| n > self.left() as u64) {
            return Err(format!(
                "{}: {} image infos, {} buffer infos and {} texel buffer views need more than the {} bytes left",
                self.at(),
                counts[0],
                counts[1],
                counts[2],
                self.left()
            ));
        }
        let layouts = ENUMS.iter().find(|e| e.name == "VkImageLayout");
        let mut images = Vec::with_capacity(counts[0] as usize);
        for _ in 0..counts[0] {
            let (sampler, view) = (self.u64()?, self.u64()?);
            let layout = i32::from_le_bytes(self.array()?);
            let mut m = Map::new();
            m.insert("sampler".to_owned(), Value::from(sampler));
            m.insert("imageView".to_owned(), Value::from(view));
            m.insert(
                "imageLayout".to_owned(),
                match layouts.and_then(|e| e.name_of(layout)) {
                    Some(name) => Value::from(name),
                    None => Value::from(layout),
                },
            );
            images.push(Value::Object(m));
        }
        let mut buffers = Vec::with_capacity(counts[1] as usize);
        for _ in 0..counts[1] {
            let mut m = Map::new();
            m.insert("buffer".to_owned(), Value::from(self.u64()?));
            m.insert("offset".to_owned(), Value::from(self.u64()?));
            m.insert("range".to_owned(), Value::from(self.u64()?));
            buffers.push(Value::Object(m));
        }
        let mut views = Vec::with_capacity(counts[2] as usize);
        for _ in 0..counts[2] {
            views.push(Value::from(self.u64()?));
        }
        let mut out = Map::new();
        out.insert("imageInfos".to_owned(), Value::Array(images));
        out.insert("bufferInfos".to_owned(), Value::Array(buffers));
        out.insert("bufferViews".to_owned(), Value::Array(views));
        while self.left() > 0 {
            let count = self.u64()?;
            let ty = self.u32()?;
            match ty {
                ACCELERATION_STRUCTURES => {
                    let n = self.count(count.saturating_mul(8))? / 8;
                    let handles = (0..n)
                        .map(|_| self.u64().map(Value::from))
                        .collect::<Res<Vec<_>>>()?;
                    out.insert("accelStructViews".to_owned(), Value::Array(handles));
                }
                INLINE_UNIFORM_BLOCK => {
                    let n = self.count(count)?;
                    let bytes = self.take(n)?.iter().map(|b| Value::from(*b)).collect();
                    out.insert("inlineUniformBlock".to_owned(), Value::Array(bytes));
                }
                other => {
                    return Err(format!(
                        "{}: a template data section of descriptor type {other} this decoder does not know",
                        self.at()
                    ));
                }
            }
        }
        Ok(Value::Object(out))
    }
}

/// Decodes `params` (the bytes after the thread id) as the parameters of `def`.
pub fn decode_call(def: &CommandDef, params: &[u8]) -> Result<Decoded, String> {
    decode(def, params, None).map(|(d, _)| d)
}

/// Where the scalar parameter at `path` (`pImageMemoryBarriers[0].oldLayout`) lies in
/// `params`: its byte offset and width.
pub fn locate(def: &CommandDef, params: &[u8], path: &str) -> Result<(usize, usize), String> {
    match decode(def, params, Some(path))? {
        (_, Some(found)) => Ok(found),
        (_, None) => Err(format!(
            "{} has no number at `{path}` (a path is spelt like `pImageMemoryBarriers[0].oldLayout`)",
            def.name
        )),
    }
}

fn decode<'a>(
    def: &CommandDef,
    params: &'a [u8],
    seek: Option<&'a str>,
) -> Result<(Decoded, Option<(usize, usize)>), String> {
    let mut r = Reader {
        buf: params,
        pos: 0,
        depth: 0,
        path: Vec::with_capacity(8),
        blobs: Vec::new(),
        seek,
        found: None,
    };
    let mut args = Map::new();
    for p in def.params {
        let v = if p.name == "pData" && TEMPLATE_CALLS.contains(&def.name) {
            r.within(Part::Name(p.name), Reader::template_data)?
        } else {
            r.within(Part::Name(p.name), |r| r.value(p.ty))?
        };
        args.insert(p.name.to_owned(), v);
    }
    let ret = match def.ret {
        Some(ty) => Some(r.value(ty)?),
        None => None,
    };
    Ok((
        Decoded {
            args: Value::Object(args),
            ret,
            blobs: r.blobs,
        },
        r.found,
    ))
}
