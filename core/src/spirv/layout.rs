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

/// Where a block's layout breaks a rule of std430 (or both layouts' rule for vectors).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LayoutBreak {
    #[error("nests too deep")]
    TooDeep,
    #[error("type %{0} is not defined")]
    Undefined(Word),
    #[error("has an array with stride {stride}, not a multiple of its element's alignment {align}")]
    ArrayStride { stride: u32, align: u32 },
    #[error("has a member at offset {offset}, not a multiple of its alignment {align}")]
    MemberOffset { offset: u32, align: u32 },
    #[error("has a matrix with stride {stride}, not a multiple of its alignment {align}")]
    MatrixStride { stride: u32, align: u32 },
    #[error("holds a {0:?}")]
    Holds(Op),
    #[error("has a {size}-byte vector at offset {offset}")]
    Vector { size: u32, offset: u32 },
}

/// A uniform block laid out past std140.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BeyondStd140 {
    pub set: u32,
    pub binding: u32,
    /// The first place it breaks std140's 16-byte rule for arrays and structs.
    pub problem: String,
    /// The first place it breaks std430's rules too (each member, array stride and matrix
    /// stride a multiple of its type's base alignment), where it does: scalar layout, which
    /// no binding wgpu makes reads.
    pub beyond_std430: Option<LayoutBreak>,
    /// Where the block's widened arrays end, where its only breaks are arrays of 32-bit
    /// scalars that `std140` widens to vectors in place (the block then stays uniform).
    pub widened_end: Option<u64>,
}

/// The module's uniform blocks that break std140's 16-byte rule for arrays and structs, in
/// declaration order; none where every block keeps it (or the module does not parse: the other
/// checks say why).
pub fn uniform_blocks_beyond_std140(words: &[u32]) -> Vec<BeyondStd140> {
    let Ok(loaded) = index::load(words) else {
        return Vec::new();
    };
    let index = Index::new(&loaded);
    let mut out = Vec::new();
    for var in &loaded.module.types_global_values {
        if var.class.opcode != Op::Variable
            || var.operands.first() != Some(&Operand::StorageClass(StorageClass::Uniform))
        {
            continue;
        }
        let Some(block_id) = block_of(&index, var) else {
            continue;
        };
        if !index.has_decoration(block_id, Decoration::Block) {
            continue;
        }
        let Some(problem) = walk(&index, block_id, 0) else {
            continue;
        };
        let Some(id) = var.result_id else { continue };
        let widened_end = super::std140::plan(&loaded, id)
            .ok()
            .flatten()
            .filter(|w| {
                let skip: Vec<u32> = w.members().collect();
                members_problem(&index, block_id, 0, &skip).is_none()
            })
            .map(|w| w.end);
        out.push(BeyondStd140 {
            set: index
                .decoration_literal(id, Decoration::DescriptorSet)
                .unwrap_or(0),
            binding: index
                .decoration_literal(id, Decoration::Binding)
                .unwrap_or(0),
            problem,
            beyond_std430: align430(&index, block_id, 0).err(),
            widened_end,
        });
    }
    out
}

/// The block struct a uniform variable points at (through one array of blocks).
fn block_of(index: &Index, var: &rspirv::dr::Instruction) -> Option<Word> {
    let id = var.result_id?;
    let pointer = index.def(var.result_type?, id).ok()?;
    let mut block = index.operand_def(pointer, 1, id).ok()?;
    if block.class.opcode == Op::TypeArray {
        block = index.operand_def(block, 0, id).ok()?;
    }
    block.result_id
}

/// The base alignment of `ty` by std430's rules, or the first place its layout breaks them.
fn align430(index: &Index, ty: Word, depth: usize) -> Result<u32, LayoutBreak> {
    if depth > MAX_DEPTH {
        return Err(LayoutBreak::TooDeep);
    }
    let inst = index.globals.get(&ty).ok_or(LayoutBreak::Undefined(ty))?;
    let lit = |n: usize| literal(inst.operands.get(n)).unwrap_or(0);
    match inst.class.opcode {
        Op::TypeInt | Op::TypeFloat => Ok(lit(0) / 8),
        Op::TypeVector => {
            let component = align430(index, id_ref(inst.operands.first()).unwrap_or(0), depth + 1)?;
            Ok(component * if lit(1) == 2 { 2 } else { 4 })
        }
        // A matrix is laid out as an array of its columns (or rows, row-major); the member's
        // MatrixStride is checked where the member is.
        Op::TypeMatrix => align430(index, id_ref(inst.operands.first()).unwrap_or(0), depth + 1),
        Op::TypeArray | Op::TypeRuntimeArray => {
            let element = align430(index, id_ref(inst.operands.first()).unwrap_or(0), depth + 1)?;
            if let Some(stride) = index.decoration_literal(ty, Decoration::ArrayStride)
                && stride % element.max(1) != 0
            {
                return Err(LayoutBreak::ArrayStride {
                    stride,
                    align: element,
                });
            }
            Ok(element)
        }
        Op::TypeStruct => {
            let mut align = 1;
            for (m, member) in inst.operands.iter().enumerate() {
                let member = id_ref(Some(member)).unwrap_or(0);
                let m = u32::try_from(m).unwrap_or(u32::MAX);
                let a = align430(index, member, depth + 1)?;
                let decoration = |d| {
                    index
                        .member_decoration(ty, m, d)
                        .and_then(|ops| literal(ops.first()))
                };
                let vector = index
                    .globals
                    .get(&member)
                    .is_some_and(|t| t.class.opcode == Op::TypeVector);
                if let Some(offset) = decoration(Decoration::Offset) {
                    if vector {
                        if let Some(problem) = vector_placement(index, member, offset) {
                            return Err(problem);
                        }
                    } else if offset % a.max(1) != 0 {
                        return Err(LayoutBreak::MemberOffset { offset, align: a });
                    }
                }
                if let Some(stride) = decoration(Decoration::MatrixStride)
                    && stride % a.max(1) != 0
                {
                    return Err(LayoutBreak::MatrixStride { stride, align: a });
                }
                align = align.max(a);
            }
            Ok(align)
        }
        op => Err(LayoutBreak::Holds(op)),
    }
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
        Op::TypeStruct => members_problem(index, ty, depth, &[]),
        _ => None,
    }
}

/// The first break of std140 in the members of struct `ty`, the members in `skip` left out.
fn members_problem(index: &Index, ty: Word, depth: usize, skip: &[u32]) -> Option<String> {
    let inst = index.globals.get(&ty)?;
    for (m, member) in inst.operands.iter().enumerate() {
        let member = id_ref(Some(member))?;
        let m = u32::try_from(m).ok()?;
        if skip.contains(&m) {
            continue;
        }
        let opcode = index.globals.get(&member).map(|t| t.class.opcode);
        let decoration = |d| {
            index
                .member_decoration(ty, m, d)
                .and_then(|ops| literal(ops.first()))
        };
        let offset = decoration(Decoration::Offset);
        let aggregate = matches!(
            opcode,
            Some(Op::TypeArray | Op::TypeRuntimeArray | Op::TypeStruct | Op::TypeMatrix)
        );
        if aggregate && offset.is_some_and(|o| o % 16 != 0) {
            return Some(format!(
                "has an array, struct or matrix member at offset {}",
                offset.unwrap_or(0)
            ));
        }
        if let Some(stride) = decoration(Decoration::MatrixStride)
            && stride % 16 != 0
        {
            return Some(format!("has a matrix with stride {stride}"));
        }
        if let Some(problem) = offset.and_then(|o| vector_placement(index, member, o)) {
            return Some(problem.to_string());
        }
        if let Some(problem) = walk(index, member, depth + 1) {
            return Some(problem);
        }
    }
    None
}

/// Where a vector member at `offset` breaks the relaxed rule both layouts share (Vulkan 1.1's
/// relaxed block layout): at a multiple of its component's size, and not across a 16-byte
/// boundary unless it starts on one. `None` for other types.
fn vector_placement(index: &Index, ty: Word, offset: u32) -> Option<LayoutBreak> {
    let inst = index.globals.get(&ty)?;
    if inst.class.opcode != Op::TypeVector {
        return None;
    }
    let component = index.globals.get(&id_ref(inst.operands.first())?)?;
    let c = literal(component.operands.first())? / 8;
    let size = c * literal(inst.operands.get(1))?;
    let straddles = if size <= 16 {
        offset % 16 + size > 16
    } else {
        !offset.is_multiple_of(16)
    };
    (!offset.is_multiple_of(c.max(1)) || straddles).then_some(LayoutBreak::Vector { size, offset })
}
