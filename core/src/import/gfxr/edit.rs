//! What-if edits of a GFXReconstruct capture: one number in one call's parameters set to
//! another value (a barrier's access mask, stage mask or layout), the rest of the file kept
//! byte for byte, so the edited capture replays in `gfxrecon-replay` like the original.
//! This is how a barrier is removed or weakened in a real command stream to see what breaks
//! (framelab's synchronization check and the validation layer read the same edited stream).
//!
//! A field is found by its parameter path through the same registry-driven decoder the
//! import uses; the edited call is written back as an uncompressed block, which a
//! compressed capture may hold beside its compressed ones.

use std::io::Cursor;

use super::blocks::{BlockError, Blocks, Kind};
use super::decode;
use super::registry::{self, ENUMS};

/// One edit: in the call of block `block` (counted as `gfxrecon-convert` counts its
/// `index`), the number at `path` becomes `value`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldEdit {
    pub block: u64,
    pub path: String,
    pub value: u64,
}

/// Why an edit cannot be read or cannot land.
#[derive(Debug, thiserror::Error)]
pub enum EditError {
    #[error("`{0}`: an edit is BLOCK:PATH=VALUE, e.g. 233:srcStageMask=1")]
    Form(String),
    #[error("`{0}` is neither a number nor a Vulkan enum name")]
    Value(String),
    #[error("{}", .0.message)]
    Header(BlockError),
    #[error("block {:?}: {}", .0.at, .0.message)]
    Block(BlockError),
    #[error("block {block}: call id {id:#x} is not in the tables")]
    UnknownCall { block: u64, id: u32 },
    #[error("block {block} is {kind}, not a call")]
    NotACall { block: u64, kind: String },
    #[error("block {block} ({call}): {problem}")]
    NoField {
        block: u64,
        call: &'static str,
        problem: super::decode::DecodeError,
    },
    #[error("block {block} ({call}): {value} does not fit the {width}-byte field `{path}`")]
    TooWide {
        block: u64,
        call: &'static str,
        value: u64,
        width: usize,
        path: String,
    },
    #[error("the capture has no block {0}")]
    NoBlock(u64),
}

impl std::fmt::Display for FieldEdit {
    /// As it is written on the command line (the value as a number).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}={}", self.block, self.path, self.value)
    }
}

impl std::str::FromStr for FieldEdit {
    type Err = EditError;

    /// `BLOCK:PATH=VALUE`, the value a number (decimal or `0x` hex) or a Vulkan enum name
    /// (`VK_IMAGE_LAYOUT_GENERAL`).
    fn from_str(s: &str) -> Result<Self, EditError> {
        let form = || EditError::Form(s.to_owned());
        let (block, rest) = s.split_once(':').ok_or_else(form)?;
        let (path, value) = rest.split_once('=').ok_or_else(form)?;
        let block = block.trim().parse().map_err(|_| form())?;
        let value = value.trim();
        let number = match value.strip_prefix("0x") {
            Some(hex) => u64::from_str_radix(hex, 16).ok(),
            None => value.parse().ok(),
        };
        let value = match number {
            Some(v) => v,
            None => enum_value(value).ok_or_else(|| EditError::Value(value.to_owned()))?,
        };
        Ok(FieldEdit {
            block,
            path: path.trim().to_owned(),
            value,
        })
    }
}

/// The value of a Vulkan enum name in the registry's tables (as the field stores it).
fn enum_value(name: &str) -> Option<u64> {
    ENUMS
        .iter()
        .flat_map(|e| e.values.iter())
        .find(|(_, n)| *n == name)
        .map(|(v, _)| u64::from(*v as u32))
}

fn u64_at(b: &[u8], i: usize) -> u64 {
    let mut a = [0; 8];
    a.copy_from_slice(&b[i..i + 8]);
    u64::from_le_bytes(a)
}

/// `input` with `edits` applied. Every edit must land: a block that is not a call, a call
/// the tables do not know, a path with no number, or a value wider than its field is an
/// error naming the edit.
pub fn apply(input: &[u8], edits: &[FieldEdit]) -> Result<Vec<u8>, EditError> {
    let mut blocks =
        Blocks::new(Cursor::new(input), Some(input.len() as u64)).map_err(EditError::Header)?;
    // The header was read by `Blocks::new`: 16 bytes, then 8 per option.
    let mut options = [0u8; 4];
    options.copy_from_slice(&input[12..16]);
    let header_len = 16 + 8 * u32::from_le_bytes(options) as usize;
    let mut out = input[..header_len].to_vec();
    let mut done = vec![false; edits.len()];
    while let Some(block) = blocks.next_block() {
        let block = block.map_err(EditError::Block)?;
        let start = block.at.offset as usize;
        let end = start + 12 + u64_at(input, start) as usize;
        let mine: Vec<usize> = (0..edits.len())
            .filter(|&i| edits[i].block == block.at.block)
            .collect();
        if mine.is_empty() {
            out.extend_from_slice(&input[start..end]);
            continue;
        }
        let def = match block.kind {
            Kind::FunctionCall => registry::command(block.id).ok_or(EditError::UnknownCall {
                block: block.at.block,
                id: block.id,
            })?,
            other => {
                return Err(EditError::NotACall {
                    block: block.at.block,
                    kind: format!("{other:?}"),
                });
            }
        };
        // The body is the thread id, then the parameters.
        let mut body = block.body;
        for i in mine {
            let e = &edits[i];
            let (at, width) =
                decode::locate(def, &body[8..], &e.path).map_err(|problem| EditError::NoField {
                    block: e.block,
                    call: def.name,
                    problem,
                })?;
            if width < 8 && e.value >> (8 * width) != 0 {
                return Err(EditError::TooWide {
                    block: e.block,
                    call: def.name,
                    value: e.value,
                    width,
                    path: e.path.clone(),
                });
            }
            body[8 + at..8 + at + width].copy_from_slice(&e.value.to_le_bytes()[..width]);
            done[i] = true;
        }
        out.extend_from_slice(&(4 + body.len() as u64).to_le_bytes());
        out.extend_from_slice(&4u32.to_le_bytes());
        out.extend_from_slice(&block.id.to_le_bytes());
        out.extend_from_slice(&body);
    }
    if let Some(i) = done.iter().position(|d| !d) {
        return Err(EditError::NoBlock(edits[i].block));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edits_are_read_with_numbers_and_enum_names() {
        let e: FieldEdit = "233:pImageMemoryBarriers[0].oldLayout=VK_IMAGE_LAYOUT_GENERAL"
            .parse()
            .unwrap();
        assert_eq!(e.block, 233);
        assert_eq!(e.path, "pImageMemoryBarriers[0].oldLayout");
        assert_eq!(e.value, 1);
        let e: FieldEdit = "7:srcStageMask=0x400".parse().unwrap();
        assert_eq!(e.value, 1024);
        assert!("7:srcStageMask".parse::<FieldEdit>().is_err());
        assert!("x:a=1".parse::<FieldEdit>().is_err());
        assert!("7:a=VK_NOT_A_NAME".parse::<FieldEdit>().is_err());
    }
}
