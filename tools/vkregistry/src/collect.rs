//! Decides what goes into the tables: the commands GFXReconstruct has ids for, every
//! structure those reach, every structure a `pNext` chain can name (by its `sType`), and
//! every enumerated type any of them uses, each enum's values settled to one name per value.

use std::collections::{BTreeMap, BTreeSet};

use anyhow::{Result, anyhow};

use crate::mapping::{Mapper, Ty};
use crate::vkxml::Registry;

pub type Fields = Vec<(String, Ty)>;

#[derive(Debug)]
pub struct Command {
    pub id: u32,
    pub name: String,
    pub params: Fields,
    pub ret: Option<Ty>,
}

#[derive(Debug, Default)]
pub struct Tables {
    /// By name; a structure's table index is its position here.
    pub structs: BTreeMap<String, Fields>,
    /// By name; values sorted by value, one name each.
    pub enums: BTreeMap<String, Vec<(i32, String)>>,
    /// `sType` value to structure name, sorted by value.
    pub stypes: BTreeMap<u32, String>,
    /// Sorted by id.
    pub commands: Vec<Command>,
    /// Calls in `api_call_id.h` that this `vk.xml` does not define.
    pub unknown_calls: Vec<String>,
}

/// The unions GFXReconstruct writes by hand; listed whether or not a command reaches them,
/// since the decoder names them.
const UNIONS: [&str; 5] = [
    "VkClearColorValue",
    "VkClearValue",
    "VkPipelineExecutableStatisticValueKHR",
    "VkDeviceOrHostAddressKHR",
    "VkDeviceOrHostAddressConstKHR",
];

pub fn collect(reg: &Registry, calls: &[(u32, String)]) -> Result<Tables> {
    let mapper = Mapper { reg };
    let mut tables = Tables::default();
    let mut pending: Vec<String> = UNIONS.iter().map(|s| (*s).to_owned()).collect();
    let mut enum_names = BTreeSet::new();
    let mut note = |ty: &Ty, pending: &mut Vec<String>| {
        let mut found = Vec::new();
        Mapper::visit(ty, &mut found);
        for t in found {
            match t {
                Ty::Struct(name) => pending.push(name.clone()),
                Ty::Enum(name) => {
                    enum_names.insert(name.clone());
                }
                _ => {}
            }
        }
    };

    for (id, name) in calls {
        let Some((ret, params)) = reg.resolve_command(name) else {
            tables.unknown_calls.push(name.clone());
            continue;
        };
        let params: Fields = params
            .iter()
            .map(|p| (p.decl.name.clone(), mapper.param(name, p)))
            .collect();
        let ret = mapper.ret(ret);
        for (_, ty) in &params {
            note(ty, &mut pending);
        }
        if let Some(ty) = &ret {
            note(ty, &mut pending);
        }
        tables.commands.push(Command {
            id: *id,
            name: name.clone(),
            params,
            ret,
        });
    }
    tables.commands.sort_by_key(|c| c.id);

    // Every extending structure, so that a `pNext` element can be found by its `sType`.
    let mut stypes = BTreeMap::new();
    for (name, info) in &reg.types {
        if info.category.as_deref() != Some("struct") || info.alias.is_some() {
            continue;
        }
        let Some(values) = info
            .members
            .iter()
            .find(|m| m.decl.name == "sType")
            .and_then(|m| m.values.as_deref())
        else {
            continue;
        };
        let first = values.split(',').next().unwrap_or(values).trim();
        // Structures of disabled extensions have no value; they cannot appear in a capture.
        let Some(value) = reg.enumerants.get(first) else {
            continue;
        };
        let value =
            u32::try_from(*value).map_err(|_| anyhow!("{name}: sType {first} = {value}"))?;
        if let Some(other) = stypes.insert(value, name.clone()) {
            eprintln!("warning: {name} and {other} share sType {first}; keeping {name}");
        }
        pending.push(name.clone());
    }

    while let Some(name) = pending.pop() {
        let name = reg.resolve_type(&name).to_owned();
        if tables.structs.contains_key(&name) {
            continue;
        }
        let info = reg
            .types
            .get(&name)
            .ok_or_else(|| anyhow!("unknown structure {name}"))?;
        let fields: Fields = match info.category.as_deref() {
            Some("union") => mapper.union_members(&name),
            _ => info
                .members
                .iter()
                .map(|m| (m.decl.name.clone(), mapper.member(m)))
                .collect(),
        };
        for (_, ty) in &fields {
            note(ty, &mut pending);
        }
        tables.structs.insert(name, fields);
    }
    tables.stypes = stypes;

    for name in enum_names {
        let mut values: Vec<(i32, String)> = Vec::new();
        match reg.enums.get(&name) {
            Some(block) => {
                for (enumerant, value) in &block.values {
                    // The registry's 32-bit enumerants, as the capture stores them (bit 31
                    // set reads as negative).
                    let value = *value as i32;
                    if !values.iter().any(|(v, _)| *v == value) {
                        values.push((value, enumerant.clone()));
                    }
                }
            }
            None => eprintln!("warning: no <enums> block for {name}"),
        }
        values.sort_by_key(|(v, _)| *v);
        tables.enums.insert(name, values);
    }
    Ok(tables)
}
