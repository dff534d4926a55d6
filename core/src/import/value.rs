//! Typed reads of a call's JSON arguments in both converter dialects: handles and 64-bit
//! values as numbers or strings, flags as integers, hex strings or `A|B` symbols, enums as
//! names. A value of the wrong shape is a `Skip` naming the argument, never a panic.

use std::borrow::Cow;

use super::tree::{Node, Tree};
use crate::capture::vulkan::{AccessFlags, ImageLayout, PipelineStages};

/// Why a call could not be used: the argument path and what is wrong with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skip(pub String);

pub type Got<T> = Result<T, Skip>;

/// One argument (or part of one). Its path for messages (`pCreateInfo.extent.width`) is
/// found from the call's root only when a message needs it: reads far outnumber errors, and
/// spelling a path out for every read was a large part of an import's time.
#[derive(Clone, Copy, Debug)]
pub struct Arg<'a> {
    tree: &'a Tree,
    node: usize,
}

/// The path from node `from` to node `to`, if it lies inside.
fn find(tree: &Tree, from: usize, to: usize, path: &mut String) -> bool {
    if from == to {
        return true;
    }
    let len = path.len();
    match tree.node(from) {
        Node::Object(run) => {
            for k in tree.kids(run) {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(tree.text(k.key));
                if find(tree, k.node, to, path) {
                    return true;
                }
                path.truncate(len);
            }
        }
        Node::Array(run) => {
            for (i, k) in tree.kids(run).iter().enumerate() {
                path.push_str(&format!("[{i}]"));
                if find(tree, k.node, to, path) {
                    return true;
                }
                path.truncate(len);
            }
        }
        _ => {}
    }
    false
}

impl<'a> Arg<'a> {
    pub fn root(tree: &'a Tree) -> Self {
        Arg {
            tree,
            node: tree.root(),
        }
    }

    fn value(&self) -> Node {
        self.tree.node(self.node)
    }

    /// The argument's path, e.g. `pCreateInfo.extent.width` or `pRegions[2].size`.
    pub fn path(&self) -> String {
        let mut path = String::new();
        find(self.tree, self.tree.root(), self.node, &mut path);
        path
    }

    /// The path of member `key` of this argument.
    fn member_path(&self, key: &str) -> String {
        let path = self.path();
        if path.is_empty() {
            key.to_owned()
        } else {
            format!("{path}.{key}")
        }
    }

    fn skip<T>(&self, what: &str) -> Got<T> {
        let shown = match self.value() {
            Node::Str(t) => {
                let s = self.tree.text(t);
                if s.len() > 40 {
                    format!("\"{}...\"", &s[..s.floor_char_boundary(40)])
                } else {
                    serde_json::Value::from(s).to_string()
                }
            }
            Node::Object(_) => "an object".to_owned(),
            Node::Array(_) => "an array".to_owned(),
            _ => self.tree.to_json(self.node).to_string(),
        };
        Err(Skip(format!(
            "`{}` is {shown}, expected {what}",
            self.path()
        )))
    }

    fn child(&self, node: usize) -> Arg<'a> {
        Arg {
            tree: self.tree,
            node,
        }
    }

    /// A member; missing members are an error naming them.
    pub fn get(&self, key: &str) -> Got<Arg<'a>> {
        match self.tree.get(self.node, key) {
            Some(v) => Ok(self.child(v)),
            None => Err(Skip(format!("`{}` is missing", self.member_path(key)))),
        }
    }

    /// A member that may be absent or null.
    pub fn opt(&self, key: &str) -> Option<Arg<'a>> {
        self.tree
            .get(self.node, key)
            .filter(|v| self.tree.node(*v) != Node::Null)
            .map(|v| self.child(v))
    }

    pub fn is_array(&self) -> bool {
        matches!(self.value(), Node::Array(_))
    }

    /// The elements of an array; null or absent arrays are empty.
    pub fn items(&self) -> Got<Vec<Arg<'a>>> {
        match self.value() {
            Node::Null => Ok(Vec::new()),
            Node::Array(run) => Ok(self
                .tree
                .kids(run)
                .iter()
                .map(|k| self.child(k.node))
                .collect()),
            _ => self.skip("an array"),
        }
    }

    /// The elements of an optional array member (absent and null are empty).
    pub fn list(&self, key: &str) -> Got<Vec<Arg<'a>>> {
        match self.opt(key) {
            Some(a) => a.items(),
            None => Ok(Vec::new()),
        }
    }

    /// An unsigned integer: a JSON number, or a decimal or `0x` hex string.
    pub fn u64(&self) -> Got<u64> {
        match self.value() {
            Node::U64(v) => Ok(v),
            Node::Str(t) => {
                parse_uint(self.tree.text(t)).map_or_else(|| self.skip("an unsigned integer"), Ok)
            }
            _ => self.skip("an unsigned integer"),
        }
    }

    pub fn u32(&self) -> Got<u32> {
        let v = self.u64()?;
        u32::try_from(v).or_else(|_| self.skip("a 32-bit unsigned integer"))
    }

    pub fn i64(&self) -> Got<i64> {
        match self.value() {
            Node::U64(v) => i64::try_from(v).or_else(|_| self.skip("an integer")),
            Node::I64(v) => Ok(v),
            Node::Str(t) => self
                .tree
                .text(t)
                .trim()
                .parse()
                .or_else(|_| self.skip("an integer")),
            _ => self.skip("an integer"),
        }
    }

    pub fn f64(&self) -> Got<f64> {
        match self.value() {
            Node::U64(v) => Ok(v as f64),
            Node::I64(v) => Ok(v as f64),
            Node::F64(v) => Ok(v),
            _ => self.skip("a number"),
        }
    }

    pub fn str(&self) -> Got<&'a str> {
        match self.value() {
            Node::Str(t) => Ok(self.tree.text(t)),
            _ => self.skip("a string"),
        }
    }

    /// A handle id: a number, a hex string, or null / `VK_NULL_HANDLE` (0).
    pub fn handle(&self) -> Got<u64> {
        match self.value() {
            Node::Null => Ok(0),
            Node::Str(t) if self.tree.text(t) == "VK_NULL_HANDLE" => Ok(0),
            _ => self.u64().or_else(|_| self.skip("a handle")),
        }
    }

    /// A flags value: an integer, a hex string, or `|`-separated symbols from `table`
    /// (matched by their last words, so `VK_IMAGE_USAGE_SAMPLED_BIT` finds `SAMPLED`).
    pub fn flags(&self, table: &[(&str, u64)]) -> Got<u64> {
        if let Ok(v) = self.u64() {
            return Ok(v);
        }
        let Node::Str(t) = self.value() else {
            return self.skip("flags");
        };
        let mut mask = 0;
        for symbol in self
            .tree
            .text(t)
            .split('|')
            .map(str::trim)
            .filter(|x| !x.is_empty())
        {
            match symbol_value(symbol, table) {
                Some(v) => mask |= v,
                None => return Err(Skip(format!("`{}`: unknown flag {symbol}", self.path()))),
            }
        }
        Ok(mask)
    }

    /// A `VkPipelineStageFlags(2)` value.
    pub fn stages(&self) -> Got<PipelineStages> {
        self.flags(PipelineStages::NAMES)
            .map(PipelineStages::from_bits)
    }

    /// A `VkAccessFlags(2)` value.
    pub fn access(&self) -> Got<AccessFlags> {
        self.flags(AccessFlags::NAMES).map(AccessFlags::from_bits)
    }

    /// An image layout by name or value.
    pub fn layout(&self) -> Got<ImageLayout> {
        let known = match self.value() {
            Node::U64(v) => ImageLayout::from_value(v),
            Node::Str(t) => {
                let n = self.tree.text(t);
                n.parse::<u64>()
                    .ok()
                    .and_then(ImageLayout::from_value)
                    .or_else(|| ImageLayout::from_name(n))
            }
            _ => return self.skip("an image layout"),
        };
        known.ok_or_else(|| {
            Skip(format!(
                "`{}`: unknown image layout {}",
                self.path(),
                self.name().unwrap_or_default()
            ))
        })
    }

    /// An enumerant's name (`VK_FORMAT_R8G8B8A8_UNORM`); numbers are given back as text.
    pub fn name(&self) -> Got<String> {
        self.symbol().map(Cow::into_owned)
    }

    /// `name`, borrowed from the arguments where they hold it as text: for the many names
    /// that are only compared.
    pub fn symbol(&self) -> Got<Cow<'a, str>> {
        match self.value() {
            Node::Str(t) => Ok(Cow::Borrowed(self.tree.text(t))),
            Node::U64(_) | Node::I64(_) | Node::F64(_) => {
                Ok(Cow::Owned(self.tree.to_json(self.node).to_string()))
            }
            _ => self.skip("an enumerant"),
        }
    }
}

fn parse_uint(s: &str) -> Option<u64> {
    let t = s.trim();
    match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => t.parse().ok(),
    }
}

/// The bit a symbol names: its words after stripping `_BIT`/`_KHR`, matched against the
/// longest table name it ends with.
pub fn symbol_value(symbol: &str, table: &[(&str, u64)]) -> Option<u64> {
    let mut s = symbol.trim();
    for suffix in ["_BIT_KHR", "_BIT_EXT", "_BIT", "_KHR"] {
        if let Some(rest) = s.strip_suffix(suffix) {
            s = rest;
            break;
        }
    }
    if s.ends_with("_NONE") || s == "0" {
        return Some(0);
    }
    table
        .iter()
        .filter(|(n, _)| s == *n || s.ends_with(&format!("_{n}")))
        .max_by_key(|(n, _)| n.len())
        .map(|(_, v)| *v)
}

pub const IMAGE_USAGE: &[(&str, u64)] = &[
    ("TRANSFER_SRC", 0x1),
    ("TRANSFER_DST", 0x2),
    ("SAMPLED", 0x4),
    ("STORAGE", 0x8),
    ("COLOR_ATTACHMENT", 0x10),
    ("DEPTH_STENCIL_ATTACHMENT", 0x20),
    ("TRANSIENT_ATTACHMENT", 0x40),
    ("INPUT_ATTACHMENT", 0x80),
];

pub const BUFFER_USAGE: &[(&str, u64)] = &[
    ("TRANSFER_SRC", 0x1),
    ("TRANSFER_DST", 0x2),
    ("UNIFORM_TEXEL_BUFFER", 0x4),
    ("STORAGE_TEXEL_BUFFER", 0x8),
    ("UNIFORM_BUFFER", 0x10),
    ("STORAGE_BUFFER", 0x20),
    ("INDEX_BUFFER", 0x40),
    ("VERTEX_BUFFER", 0x80),
    ("INDIRECT_BUFFER", 0x100),
    ("SHADER_DEVICE_ADDRESS", 0x20000),
];

pub const QUEUE_FLAGS: &[(&str, u64)] = &[
    ("GRAPHICS", 0x1),
    ("COMPUTE", 0x2),
    ("TRANSFER", 0x4),
    ("SPARSE_BINDING", 0x8),
    ("PROTECTED", 0x10),
];

pub const MEMORY_PROPERTIES: &[(&str, u64)] = &[
    ("DEVICE_LOCAL", 0x1),
    ("HOST_VISIBLE", 0x2),
    ("HOST_COHERENT", 0x4),
    ("HOST_CACHED", 0x8),
    ("LAZILY_ALLOCATED", 0x10),
    ("PROTECTED", 0x20),
];

pub const IMAGE_CREATE: &[(&str, u64)] = &[
    ("SPARSE_BINDING", 0x1),
    ("SPARSE_RESIDENCY", 0x2),
    ("SPARSE_ALIASED", 0x4),
    ("MUTABLE_FORMAT", 0x8),
    ("CUBE_COMPATIBLE", 0x10),
    ("2D_ARRAY_COMPATIBLE", 0x20),
];

pub const ASPECTS: &[(&str, u64)] = &[("COLOR", 0x1), ("DEPTH", 0x2), ("STENCIL", 0x4)];

/// A 32-bit float as the shortest decimal that reads back as it (0.2, not 0.200000003):
/// the value the application wrote, as a text stream of the same call shows it.
pub fn shortest(f: f32) -> f64 {
    f.to_string().parse().unwrap_or(f64::from(f))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn numbers_strings_and_symbols() {
        let v = json!({"a": 18446744073709551615u64, "b": "0x00000006", "c": "VK_IMAGE_USAGE_SAMPLED_BIT|VK_IMAGE_USAGE_STORAGE_BIT", "d": [1, "x"], "h": "VK_NULL_HANDLE"});
        let tree = Tree::from_json(&v);
        let root = Arg::root(&tree);
        assert_eq!(root.get("a").unwrap().u64(), Ok(u64::MAX));
        assert!(root.get("a").unwrap().u32().is_err());
        assert_eq!(root.get("b").unwrap().flags(IMAGE_USAGE), Ok(6));
        assert_eq!(root.get("c").unwrap().flags(IMAGE_USAGE), Ok(12));
        assert_eq!(root.get("h").unwrap().handle(), Ok(0));
        let d = root.get("d").unwrap();
        let items = d.items().unwrap();
        let err = items[1].u64().unwrap_err();
        assert_eq!(err.0, "`d[1]` is \"x\", expected an unsigned integer");
        assert_eq!(root.get("zz").unwrap_err().0, "`zz` is missing");
        assert_eq!(
            symbol_value(
                "VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT",
                PipelineStages::NAMES
            ),
            Some(0x400)
        );
        assert_eq!(
            symbol_value("VK_ACCESS_SHADER_READ_BIT", AccessFlags::NAMES),
            Some(0x20)
        );
    }
}
