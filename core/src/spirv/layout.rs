//! Whether a module's uniform blocks keep the layout rules every Vulkan device takes
//! (std140, relaxed as Vulkan 1.1 does for vectors): arrays and structs at offsets and
//! strides of whole 16 bytes. A block laid out more tightly (std430 or scalar layout, which
//! need `uniformBufferStandardLayout` or `scalarBlockLayout` on the device; Mesa's zink writes
//! them) is valid only where the device enabled those features, and wgpu enables neither.

use rspirv::dr::Operand;
use rspirv::spirv::{Decoration, Op, StorageClass, Word};

use super::index::{self, Index, id_ref, literal};

/// How deep a block's types may nest before the walk stops (malformed modules included).
const MAX_DEPTH: usize = 32;

/// The first place a Uniform block of the module breaks std140's 16-byte rule for arrays and
/// structs, described; `None` when every block keeps it (or the module does not parse: the
/// other checks say why).
pub fn uniform_block_beyond_std140(words: &[u32]) -> Option<String> {
    let loaded = index::load(words).ok()?;
    let index = Index::new(&loaded);
    for var in &loaded.module.types_global_values {
        if var.class.opcode != Op::Variable
            || var.operands.first() != Some(&Operand::StorageClass(StorageClass::Uniform))
        {
            continue;
        }
        let id = var.result_id?;
        let pointer = index.def(var.result_type?, id).ok()?;
        let mut block = index.operand_def(pointer, 1, id).ok()?;
        if block.class.opcode == Op::TypeArray {
            block = index.operand_def(block, 0, id).ok()?;
        }
        let block_id = block.result_id?;
        if !index.has_decoration(block_id, Decoration::Block) {
            continue;
        }
        let where_ = || {
            let set = index.decoration_literal(id, Decoration::DescriptorSet);
            let binding = index.decoration_literal(id, Decoration::Binding);
            format!(
                "the uniform block at set {} binding {}",
                set.map_or("?".to_owned(), |s| s.to_string()),
                binding.map_or("?".to_owned(), |b| b.to_string())
            )
        };
        if let Some(problem) = walk(&index, block_id, 0) {
            return Some(format!("{} {problem}", where_()));
        }
    }
    None
}

/// The first array stride or aggregate member offset in `ty` that is not a multiple of 16.
fn walk(index: &Index, ty: Word, depth: usize) -> Option<String> {
    if depth > MAX_DEPTH {
        return None;
    }
    let inst = index.globals.get(&ty)?;
    match inst.class.opcode {
        Op::TypeArray | Op::TypeRuntimeArray => {
            if let Some(stride) = index.decoration_literal(ty, Decoration::ArrayStride)
                && stride % 16 != 0
            {
                return Some(format!("has an array with stride {stride}"));
            }
            walk(index, id_ref(inst.operands.first())?, depth + 1)
        }
        Op::TypeStruct => {
            for (m, member) in inst.operands.iter().enumerate() {
                let member = id_ref(Some(member))?;
                let m = u32::try_from(m).ok()?;
                let aggregate = index.globals.get(&member).is_some_and(|t| {
                    matches!(
                        t.class.opcode,
                        Op::TypeArray | Op::TypeRuntimeArray | Op::TypeStruct
                    )
                });
                let offset = index
                    .member_decoration(ty, m, Decoration::Offset)
                    .and_then(|ops| literal(ops.first()));
                if aggregate && offset.is_some_and(|o| o % 16 != 0) {
                    return Some(format!(
                        "has an array or struct member at offset {}",
                        offset.unwrap_or(0)
                    ));
                }
                if let Some(problem) = walk(index, member, depth + 1) {
                    return Some(problem);
                }
            }
            None
        }
        _ => None,
    }
}
