//! The shapes of Vulkan calls and structures as GFXReconstruct encodes them, for the
//! table-driven decoder. The tables themselves (`tables.rs`) are generated from the Vulkan
//! registry (`vk.xml`) and GFXReconstruct's call ids by `tools/vkregistry`, so a new call or
//! structure costs a regenerated line, not a hand-written function.

use std::sync::OnceLock;

use super::super::calls::Func;

/// How one parameter or structure member is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    /// Plain little-endian values. `VkBool32` and `VkSampleMask` are `U32`; `size_t`,
    /// `VkDeviceSize` and `VkDeviceAddress` are `U64`.
    U8,
    U16,
    U32,
    I32,
    U64,
    I64,
    F32,
    // No call or structure of the 1.3.239 registry holds a `double`; a later one may.
    #[allow(dead_code)]
    F64,
    /// A 32-bit enumerant of `ENUMS[i]`, written by name.
    Enum(u16),
    /// A 32-bit or 64-bit flags value, written as a number.
    Flags32,
    Flags64,
    /// A 64-bit handle id.
    Handle,
    /// A host address without data: `void*` with no length, function and platform pointers.
    Address,
    /// A structure `STRUCTS[i]` encoded inline, member after member.
    Struct(u16),
    /// The `pNext` chain: a pointer preamble, then a structure found by its `sType`.
    PNext,
    /// A pointer or a fixed-size array: the attribute mask, the address when flagged, the
    /// length for arrays and strings, then the elements when flagged. The element type is
    /// the pointee; `void*` with a length is bytes (`U8`).
    Ptr(&'static Ty),
    /// A pointer the registry gives a length, or a fixed array: encoded like `Ptr`, decoded
    /// as a list even where the writer flagged a single element (a trimmed capture's
    /// re-recorded submissions point at one structure).
    Arr(&'static Ty),
    /// `char*` and `char[N]`: a pointer preamble with a length, then UTF-8 bytes.
    Str,
    /// `const char* const*`: an array of strings, each with its own preamble.
    Strs,
    /// Something the decoder cannot read (a pointer to pointers of structures, a bit field);
    /// a call that holds one is counted as not decoded.
    Opaque,
}

/// One parameter of a call or member of a structure.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    pub name: &'static str,
    pub ty: Ty,
}

/// A structure (or a union GFXReconstruct encodes as one of its members).
#[derive(Clone, Copy, Debug)]
pub struct StructDef {
    pub name: &'static str,
    pub members: &'static [Field],
}

/// A Vulkan command with its GFXReconstruct call id.
#[derive(Clone, Copy, Debug)]
pub struct CommandDef {
    /// `(api family << 16) | call`, as in the block header.
    pub id: u32,
    pub name: &'static str,
    pub params: &'static [Field],
    /// The return value, encoded after the parameters; `None` for `void`.
    pub ret: Option<Ty>,
}

/// An enumerated type's values, sorted by value.
#[derive(Clone, Copy, Debug)]
pub struct EnumDef {
    pub name: &'static str,
    pub values: &'static [(i32, &'static str)],
}

impl EnumDef {
    /// The name of `value`, or `None` for a value the registry does not list.
    pub fn name_of(&self, value: i32) -> Option<&'static str> {
        self.values
            .binary_search_by_key(&value, |(v, _)| *v)
            .ok()
            .map(|i| self.values[i].1)
    }
}

pub use super::tables::{COMMANDS, ENUMS, STRUCTS, STYPES};

/// The command with call id `id`, if the tables know it (`COMMANDS` is sorted by id).
pub fn command(id: u32) -> Option<&'static CommandDef> {
    command_index(id).map(|i| &COMMANDS[i])
}

/// Where in `COMMANDS` the command with call id `id` is. Looked up once per call block of
/// a capture, so by a table indexed by id (the ids are dense) rather than a search.
pub fn command_index(id: u32) -> Option<usize> {
    static BY_ID: OnceLock<(u32, Vec<u16>)> = OnceLock::new();
    let (first, slots) = BY_ID.get_or_init(|| {
        let first = COMMANDS.first().map_or(0, |c| c.id);
        let last = COMMANDS.last().map_or(0, |c| c.id);
        let mut slots = vec![u16::MAX; (last - first) as usize + 1];
        for (i, c) in COMMANDS.iter().enumerate() {
            if let (Some(slot), Ok(i)) = (slots.get_mut((c.id - first) as usize), u16::try_from(i))
            {
                *slot = i;
            }
        }
        (first, slots)
    });
    let slot = *slots.get(id.checked_sub(*first)? as usize)?;
    (slot != u16::MAX).then_some(usize::from(slot))
}

/// What the importer makes of the command at `index` in `COMMANDS`, worked out once per
/// command rather than by matching its name for every call.
pub fn func(index: usize) -> Option<Func> {
    static FUNCS: OnceLock<Vec<Func>> = OnceLock::new();
    FUNCS
        .get_or_init(|| COMMANDS.iter().map(|c| Func::of(c.name)).collect())
        .get(index)
        .copied()
}

/// The index in `STRUCTS` of the structure a `pNext` element with this `sType` value is
/// (`STYPES` is sorted by value).
pub fn struct_index_of_stype(stype: u32) -> Option<u16> {
    STYPES
        .binary_search_by_key(&stype, |(v, _)| *v)
        .ok()
        .map(|i| STYPES[i].1)
}

/// The enumeration named `name` (`VkDescriptorType`), if the tables know it.
pub fn enum_named(name: &str) -> Option<&'static EnumDef> {
    ENUMS.iter().find(|e| e.name == name)
}

/// The command named `name` (`vkCreateImage`), if the tables know it.
pub fn command_named(name: &str) -> Option<&'static CommandDef> {
    static BY_NAME: std::sync::OnceLock<std::collections::HashMap<&'static str, usize>> =
        std::sync::OnceLock::new();
    BY_NAME
        .get_or_init(|| {
            COMMANDS
                .iter()
                .enumerate()
                .map(|(i, c)| (c.name, i))
                .collect()
        })
        .get(name)
        .map(|&i| &COMMANDS[i])
}

/// The index in `STRUCTS` of the structure named `name` (`STRUCTS` is sorted by name).
pub fn struct_named(name: &str) -> Option<u16> {
    STRUCTS
        .binary_search_by(|s| s.name.cmp(name))
        .ok()
        .and_then(|i| u16::try_from(i).ok())
}
