//! Reads `vk.xml` (through `vk-parse`) into the few facts the tables need: each type's
//! category and declaration, each enumerated type's values with the extensions' additions
//! folded in, and each command's prototype. Everything Vulkan SC only is dropped here, so
//! the rest of the generator sees one API.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use vk_parse::{
    CommandDefinition, EnumSpec, EnumsChild, ExtensionChild, InterfaceItem, RegistryChild,
    TypeCodeMarkup, TypeMember, TypeMemberMarkup, TypeSpec, TypesChild,
};

use crate::decl::Decl;

/// One `<type>`, reduced to what the mapping looks at.
#[derive(Debug, Default)]
pub struct TypeInfo {
    pub category: Option<String>,
    pub alias: Option<String>,
    /// The C text of a non-struct type (a bitmask's `typedef VkFlags64 ...`, a basetype's
    /// typedef), to tell 32-bit from 64-bit flags and pointers from integers.
    pub code: String,
    pub members: Vec<Member>,
}

/// A structure member, or a command parameter: the same declaration grammar.
#[derive(Debug)]
pub struct Member {
    pub decl: Decl,
    /// The `len` attribute: a `void*` with a length is a byte array, without one an address.
    pub len: Option<String>,
    /// The `values` attribute; on `sType` it names the structure's `VkStructureType`.
    pub values: Option<String>,
    /// The `optional` attribute: `true` where zero (a count) or null (a pointer) is allowed.
    pub optional: Option<String>,
}

#[derive(Debug)]
pub enum CommandInfo {
    Alias(String),
    Def { ret: Decl, params: Vec<Member> },
}

/// An enumerated type's values in registry order: the type's own block first, then what the
/// core versions and extensions add. Aliases are left out: they never name a value first.
#[derive(Debug, Default)]
pub struct EnumValues {
    pub bitwidth: Option<u32>,
    pub values: Vec<(String, i64)>,
}

#[derive(Debug)]
pub struct Registry {
    /// `major.minor.patch` of the registry, for the generated file's header.
    pub version: String,
    pub types: HashMap<String, TypeInfo>,
    pub enums: HashMap<String, EnumValues>,
    /// Every enumerant name, aliases included, to its value: `values=` may name either.
    pub enumerants: HashMap<String, i64>,
    pub commands: HashMap<String, CommandInfo>,
    /// Each command to what provides it: the first core version that has it, and every
    /// extension that does (a command of a core version needs no extension).
    pub provided: HashMap<String, Provided>,
}

/// What provides a command.
#[derive(Debug, Default)]
pub struct Provided {
    /// `1.0`, `1.1`, ...: the first core version with the command under this name.
    pub core: Option<String>,
    pub extensions: Vec<String>,
}

impl Registry {
    /// Follows `alias=` to the type that carries the definition.
    pub fn resolve_type<'a>(&'a self, mut name: &'a str) -> &'a str {
        for _ in 0..8 {
            match self.types.get(name).and_then(|t| t.alias.as_deref()) {
                Some(target) => name = target,
                None => break,
            }
        }
        name
    }

    pub fn resolve_command<'a>(&'a self, mut name: &'a str) -> Option<(&'a Decl, &'a [Member])> {
        for _ in 0..8 {
            match self.commands.get(name)? {
                CommandInfo::Alias(target) => name = target,
                CommandInfo::Def { ret, params } => return Some((ret, params)),
            }
        }
        None
    }
}

/// Whether an `api=` / `supported=` list admits plain Vulkan (absent means every API).
fn for_vulkan(api: Option<&str>) -> bool {
    api.is_none_or(|list| list.split(',').any(|a| a.trim() == "vulkan"))
}

pub fn read(path: &Path) -> Result<Registry> {
    let (parsed, errors) = vk_parse::parse_file(path)
        .map_err(|e| anyhow!("{e:?}"))
        .with_context(|| format!("reading {}", path.display()))?;
    for error in errors.iter().take(5) {
        eprintln!("warning: {}: {error:?}", path.display());
    }

    let mut reg = Registry {
        version: String::new(),
        types: HashMap::new(),
        enums: HashMap::new(),
        enumerants: HashMap::new(),
        commands: HashMap::new(),
        provided: HashMap::new(),
    };
    let mut header_version = None;
    let mut complete_version = None;

    for child in &parsed.0 {
        match child {
            RegistryChild::Types(types) => {
                for t in &types.children {
                    let TypesChild::Type(t) = t else { continue };
                    if !for_vulkan(t.api.as_deref()) {
                        continue;
                    }
                    let (name, info) = read_type(t)?;
                    match name.as_str() {
                        "VK_HEADER_VERSION" => header_version = Some(info.code.clone()),
                        "VK_HEADER_VERSION_COMPLETE" => complete_version = Some(info.code.clone()),
                        _ => {}
                    }
                    reg.types.insert(name, info);
                }
            }
            RegistryChild::Enums(block) => {
                // `API Constants` are array sizes and limits, not an enumerated type.
                let Some(name) = &block.name else { continue };
                if !matches!(block.kind.as_deref(), Some("enum" | "bitmask")) {
                    continue;
                }
                let mut values = EnumValues {
                    bitwidth: block.bitwidth,
                    values: Vec::new(),
                };
                for item in &block.children {
                    let EnumsChild::Enum(e) = item else { continue };
                    if !for_vulkan(e.api.as_deref()) {
                        continue;
                    }
                    if let Some(v) = own_value(&e.spec)? {
                        values.values.push((e.name.clone(), v));
                        reg.enumerants.insert(e.name.clone(), v);
                    }
                }
                for item in &block.children {
                    if let EnumsChild::Enum(e) = item
                        && let EnumSpec::Alias { alias, .. } = &e.spec
                        && let Some(v) = reg.enumerants.get(alias).copied()
                    {
                        reg.enumerants.insert(e.name.clone(), v);
                    }
                }
                reg.enums.insert(name.clone(), values);
            }
            RegistryChild::Commands(commands) => {
                for c in &commands.children {
                    match c {
                        vk_parse::Command::Alias { name, alias } => {
                            reg.commands
                                .insert(name.clone(), CommandInfo::Alias(alias.clone()));
                        }
                        vk_parse::Command::Definition(def) => {
                            if !for_vulkan(def.api.as_deref()) {
                                continue;
                            }
                            let (name, info) = read_command(def)?;
                            reg.commands.insert(name, info);
                        }
                        _ => {}
                    }
                }
            }
            _ => {}
        }
    }

    // The additions come after every `<enums>` block is known, features before extensions
    // (document order), so a core name wins over the extension name it was promoted from.
    let mut aliases = Vec::new();
    for child in &parsed.0 {
        match child {
            RegistryChild::Feature(f) if for_vulkan(Some(&f.api)) => {
                add_extends(&mut reg, &f.children, None, &mut aliases)?;
                for command in required_commands(&f.children) {
                    let p = reg.provided.entry(command).or_default();
                    if p.core.is_none() {
                        p.core.clone_from(&f.number);
                    }
                }
            }
            RegistryChild::Extensions(exts) => {
                for ext in &exts.children {
                    if for_vulkan(ext.supported.as_deref()) {
                        add_extends(&mut reg, &ext.children, ext.number, &mut aliases)?;
                        for command in required_commands(&ext.children) {
                            let p = reg.provided.entry(command).or_default();
                            if !p.extensions.contains(&ext.name) {
                                p.extensions.push(ext.name.clone());
                            }
                        }
                    }
                }
            }
            _ => {}
        }
    }
    // An alias may name an enumerant defined by a later extension; two passes settle that.
    for _ in 0..2 {
        for (name, target) in &aliases {
            if let Some(v) = reg.enumerants.get(target).copied() {
                reg.enumerants.insert(name.clone(), v);
            }
        }
    }

    reg.version = version(header_version.as_deref(), complete_version.as_deref())?;
    Ok(reg)
}

fn read_type(t: &vk_parse::Type) -> Result<(String, TypeInfo)> {
    let mut info = TypeInfo {
        category: t.category.clone(),
        alias: t.alias.clone(),
        ..TypeInfo::default()
    };
    let mut name = t.name.clone();
    match &t.spec {
        TypeSpec::Code(code) => {
            info.code = code.code.clone();
            if name.is_none() {
                name = code.markup.iter().find_map(|m| match m {
                    TypeCodeMarkup::Name(n) => Some(n.clone()),
                    _ => None,
                });
            }
        }
        TypeSpec::Members(members) => {
            for m in members {
                let TypeMember::Definition(def) = m else {
                    continue;
                };
                if !for_vulkan(def.api.as_deref()) {
                    continue;
                }
                let mut type_name = None;
                let mut member_name = None;
                for markup in &def.markup {
                    match markup {
                        TypeMemberMarkup::Type(t) if type_name.is_none() => {
                            type_name = Some(t.clone())
                        }
                        TypeMemberMarkup::Name(n) if member_name.is_none() => {
                            member_name = Some(n.clone())
                        }
                        _ => {}
                    }
                }
                let (Some(type_name), Some(member_name)) = (type_name, member_name) else {
                    bail!(
                        "a member of {name:?} without a type or a name: {:?}",
                        def.code
                    );
                };
                info.members.push(Member {
                    decl: Decl::parse(&def.code, &type_name, &member_name)?,
                    len: def.len.clone(),
                    values: def.values.clone(),
                    optional: def.optional.clone(),
                });
            }
        }
        _ => {}
    }
    let name = name.ok_or_else(|| anyhow!("a <type> without a name: {:?}", t.spec))?;
    Ok((name, info))
}

fn read_command(def: &CommandDefinition) -> Result<(String, CommandInfo)> {
    let ret_type = def.proto.type_name.as_deref().unwrap_or("void");
    let ret = Decl::parse(&def.proto.code, ret_type, &def.proto.name)?;
    let mut params = Vec::new();
    for p in &def.params {
        if !for_vulkan(p.api.as_deref()) {
            continue;
        }
        let d = &p.definition;
        let type_name = d
            .type_name
            .as_deref()
            .ok_or_else(|| anyhow!("a parameter of {} without a type", def.proto.name))?;
        params.push(Member {
            decl: Decl::parse(&d.code, type_name, &d.name)?,
            len: p.len.clone(),
            values: None,
            optional: p.optional.clone(),
        });
    }
    Ok((def.proto.name.clone(), CommandInfo::Def { ret, params }))
}

/// A value written in an enumerated type's own block (`value=` or `bitpos=`).
fn own_value(spec: &EnumSpec) -> Result<Option<i64>> {
    Ok(match spec {
        EnumSpec::Value { value, .. } => Some(parse_int(value)?),
        EnumSpec::Bitpos { bitpos, .. } => Some(1i64 << bitpos),
        _ => None,
    })
}

/// The commands a feature's or an extension's `<require>` blocks for Vulkan name.
fn required_commands(children: &[ExtensionChild]) -> Vec<String> {
    let mut out = Vec::new();
    for child in children {
        let ExtensionChild::Require { api, items, .. } = child else {
            continue;
        };
        if !for_vulkan(api.as_deref()) {
            continue;
        }
        for item in items {
            if let InterfaceItem::Command { name, .. } = item {
                out.push(name.clone());
            }
        }
    }
    out
}

/// The `<enum extends=...>` of one feature's or extension's `<require>` blocks.
fn add_extends(
    reg: &mut Registry,
    children: &[ExtensionChild],
    ext_number: Option<i64>,
    aliases: &mut Vec<(String, String)>,
) -> Result<()> {
    for child in children {
        let ExtensionChild::Require { api, items, .. } = child else {
            continue;
        };
        if !for_vulkan(api.as_deref()) {
            continue;
        }
        for item in items {
            let InterfaceItem::Enum(e) = item else {
                continue;
            };
            if !for_vulkan(e.api.as_deref()) {
                continue;
            }
            let (extends, value) = match &e.spec {
                EnumSpec::Offset {
                    offset,
                    extends,
                    extnumber,
                    dir,
                } => {
                    let number = extnumber.or(ext_number).ok_or_else(|| {
                        anyhow!("{}: an offset without an extension number", e.name)
                    })?;
                    let v = 1_000_000_000 + (number - 1) * 1000 + offset;
                    (extends, if *dir { v } else { -v })
                }
                EnumSpec::Value {
                    value,
                    extends: Some(extends),
                } => (extends, parse_int(value)?),
                EnumSpec::Bitpos {
                    bitpos,
                    extends: Some(extends),
                } => (extends, 1i64 << bitpos),
                EnumSpec::Alias { alias, .. } => {
                    aliases.push((e.name.clone(), alias.clone()));
                    continue;
                }
                _ => continue,
            };
            reg.enumerants.insert(e.name.clone(), value);
            let block = reg.enums.entry(extends.clone()).or_default();
            if !block.values.iter().any(|(n, _)| *n == e.name) {
                block.values.push((e.name.clone(), value));
            }
        }
    }
    Ok(())
}

/// Integers as the registry writes them: decimal, `0x` hexadecimal, negative, `U` suffixes.
fn parse_int(text: &str) -> Result<i64> {
    let t = text.trim().trim_end_matches(['U', 'u', 'L', 'l']);
    let (negative, digits) = match t.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, t),
    };
    let magnitude = match digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
    {
        Some(hex) => i64::from_str_radix(hex, 16),
        None => digits.parse(),
    }
    .with_context(|| format!("not an integer: {text:?}"))?;
    Ok(if negative { -magnitude } else { magnitude })
}

/// `1.3.239` from `VK_HEADER_VERSION_COMPLETE`'s `VK_MAKE_API_VERSION(0, 1, 3, ...)` and
/// `VK_HEADER_VERSION`'s number.
fn version(header: Option<&str>, complete: Option<&str>) -> Result<String> {
    let patch = header
        .and_then(|code| code.split_whitespace().last())
        .ok_or_else(|| anyhow!("vk.xml defines no VK_HEADER_VERSION"))?;
    let args: Vec<&str> = complete
        .and_then(|code| code.split_once('(')?.1.split_once(')'))
        .map(|(inside, _)| inside.split(',').map(str::trim).collect())
        .unwrap_or_default();
    match args.as_slice() {
        [_, major, minor, _] => Ok(format!("{major}.{minor}.{patch}")),
        _ => Ok(patch.to_owned()),
    }
}
