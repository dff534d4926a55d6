//! Uniform blocks of 32-bit scalar arrays made std140 in place. A block laid out by std430
//! keeps its arrays of `uint`, `int` or `float` at a stride of 4 bytes (Mesa's zink packs every
//! OpenGL uniform block as one `uint[N]`), which std140, the only layout wgpu's uniform bindings
//! take, does not allow. The same bytes are a `uvec4[ceil(N / 4)]` at a stride of 16: element
//! `i` is component `i & 3` of vector `i >> 2`. Each such array member becomes that vector
//! array and every access chain into it gets the two indices for the one, so the block stays a
//! uniform block, read as the program's driver reads it.
//!
//! This is preferred to binding the block as a read-only storage buffer (`storage`), which
//! reads the same bytes: a storage read is a memory access that a driver may mask off in
//! helper invocations (lavapipe does), and a value made from it then differs between the
//! pixels of a quad, so the derivatives behind implicit-LOD sampling go wrong at every
//! triangle's edge. A uniform read is the same in every invocation.
//!
//! A block whose array pointer is used otherwise than by access chains down to its elements
//! (loaded whole, passed to a function) is not widened: the caller reads it as storage.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Decoration, Op, StorageClass, Word};

use super::SpirvError;
use super::carry::variables_at;
use super::index::{Index, Loaded, first_free_id, id_ref, literal};
use super::ops::{Ids, inst, int32, type_id, vector};

/// How a uniform block variable is widened.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Widening {
    /// The variable's type is an array of blocks (its length id) rather than one block.
    outer: Option<Word>,
    block: Word,
    /// The members to widen: (member, scalar type, element count).
    members: Vec<(u32, Word, u32)>,
    /// Where the widened members end, in bytes from the block's start.
    pub(super) end: u64,
    /// Every pointer into the variable that the widening retypes, with where it points.
    pointers: HashMap<Word, At>,
}

impl Widening {
    /// The members widened, by index.
    pub(super) fn members(&self) -> impl Iterator<Item = u32> + '_ {
        self.members.iter().map(|m| m.0)
    }
}

/// Where a pointer into a widened block points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum At {
    /// The variable (an array of blocks, or the block).
    Root,
    Block,
    /// The widened array at this member.
    Array(u32),
}

/// A global's opcode and operands.
fn op<'m>(index: &Index<'m>, id: Word) -> Option<(Op, &'m [Operand])> {
    index
        .globals
        .get(&id)
        .map(|i| (i.class.opcode, i.operands.as_slice()))
}

/// The value of a 32-bit integer constant.
fn constant_value(index: &Index, id: Word) -> Option<u32> {
    match op(index, id)? {
        (Op::Constant, ops) => literal(ops.first()),
        _ => None,
    }
}

/// Why a uniform block cannot be widened to std140 in place.
#[derive(Debug, thiserror::Error)]
pub(super) enum NotWidened {
    #[error("not a variable")]
    NotVariable,
    #[error("not a uniform variable")]
    NotUniform,
    #[error("no pointee")]
    NoPointee,
    #[error("not a block")]
    NotBlock,
    #[error("too many members")]
    TooManyMembers,
    #[error("a member with no type")]
    MemberType,
    #[error("a member with no offset")]
    MemberOffset,
    #[error("an array whose length is not a constant")]
    LengthNotConstant,
    #[error("an array at offset {0}, not on 16 bytes")]
    Unaligned(u32),
    #[error("the array at offset {start} would reach past the member at offset {next}")]
    Overlaps { start: u64, next: u64 },
    #[error("a pointer to the block or an array in it is used by Op{op:?} (operand {operand})")]
    PointerUse { op: Op, operand: usize },
    #[error("a struct member chosen by a value that is not a constant")]
    MemberNotConstant,
}

/// How the uniform block variable `var` would be widened (`None`: it has no array to widen),
/// or why it cannot be (an array that would overlap the next member, a pointer used otherwise
/// than by access chains to elements).
pub(super) fn plan(loaded: &Loaded, var: Word) -> Result<Option<Widening>, NotWidened> {
    let index = Index::new(loaded);
    let g = &index;
    let ptr = g
        .globals
        .get(&var)
        .and_then(|v| v.result_type)
        .ok_or(NotWidened::NotVariable)?;
    let Some((Op::TypePointer, [Operand::StorageClass(StorageClass::Uniform), pointee])) =
        op(g, ptr)
    else {
        return Err(NotWidened::NotUniform);
    };
    let mut block = id_ref(Some(pointee)).ok_or(NotWidened::NoPointee)?;
    let mut outer = None;
    if let Some((Op::TypeArray, [Operand::IdRef(element), Operand::IdRef(len)])) = op(g, block) {
        outer = Some(*len);
        block = *element;
    }
    let Some((Op::TypeStruct, members)) = op(g, block) else {
        return Err(NotWidened::NotBlock);
    };
    let mut widen = Vec::new();
    let mut offsets = Vec::new();
    for (m, ty) in members.iter().enumerate() {
        let m = u32::try_from(m).map_err(|_| NotWidened::TooManyMembers)?;
        let ty = id_ref(Some(ty)).ok_or(NotWidened::MemberType)?;
        let offset = g
            .member_decoration(block, m, Decoration::Offset)
            .and_then(|ops| literal(ops.first()))
            .ok_or(NotWidened::MemberOffset)?;
        offsets.push(offset);
        let Some((Op::TypeArray, [Operand::IdRef(element), Operand::IdRef(len)])) = op(g, ty)
        else {
            continue;
        };
        let scalar32 = matches!(
            op(g, *element),
            Some((Op::TypeInt | Op::TypeFloat, [Operand::LiteralBit32(32), ..]))
        );
        if !scalar32 || g.decoration_literal(ty, Decoration::ArrayStride) != Some(4) {
            continue;
        }
        let n = constant_value(g, *len).ok_or(NotWidened::LengthNotConstant)?;
        if offset % 16 != 0 {
            return Err(NotWidened::Unaligned(offset));
        }
        widen.push((m, *element, n));
    }
    if widen.is_empty() {
        return Ok(None);
    }
    let mut end = 0u64;
    for &(m, _, n) in &widen {
        let start = u64::from(offsets[m as usize]);
        let stop = start + u64::from(n.div_ceil(4)) * 16;
        if let Some(o) = offsets
            .iter()
            .map(|&o| u64::from(o))
            .find(|&o| o > start && o < stop)
        {
            return Err(NotWidened::Overlaps { start, next: o });
        }
        end = end.max(stop);
    }
    let mut w = Widening {
        outer,
        block,
        members: widen,
        end,
        pointers: HashMap::new(),
    };
    w.pointers = pointers(&loaded.module, var, &w, g)?;
    Ok(Some(w))
}

/// Every pointer into `var` that a widening retypes, with where it points; an error names a
/// use the widening cannot follow.
fn pointers(
    module: &Module,
    var: Word,
    w: &Widening,
    g: &Index,
) -> Result<HashMap<Word, At>, NotWidened> {
    let mut at: HashMap<Word, At> = HashMap::from([(var, At::Root)]);
    // Blocks are laid out with each after its dominators, so a pointer is defined before
    // every use but a phi's, which is refused below.
    for i in module.functions.iter().flat_map(|f| f.all_inst_iter()) {
        let op = i.class.opcode;
        let base = id_ref(i.operands.first()).and_then(|b| at.get(&b).copied());
        match (op, base) {
            (Op::AccessChain | Op::InBoundsAccessChain, Some(start)) => {
                if let Some(end) = walk(start, &i.operands[1..], w, g)?
                    && let Some(id) = i.result_id
                {
                    at.insert(id, end);
                }
            }
            (Op::CopyObject, Some(start)) => {
                if let Some(id) = i.result_id {
                    at.insert(id, start);
                }
            }
            _ => {
                for (n, o) in i.operands.iter().enumerate() {
                    if let Operand::IdRef(id) = o
                        && at.contains_key(id)
                    {
                        return Err(NotWidened::PointerUse { op, operand: n });
                    }
                }
            }
        }
    }
    Ok(at)
}

/// Where an access chain from `start` through `indices` ends: `None` past the widened part
/// (an element, or a member left as it is).
fn walk(start: At, indices: &[Operand], w: &Widening, g: &Index) -> Result<Option<At>, NotWidened> {
    let mut at = Some(start);
    for index in indices {
        at = match at {
            Some(At::Root) if w.outer.is_some() => Some(At::Block),
            Some(At::Root | At::Block) => {
                let m = id_ref(Some(index))
                    .and_then(|i| constant_value(g, i))
                    .ok_or(NotWidened::MemberNotConstant)?;
                w.members().any(|x| x == m).then_some(At::Array(m))
            }
            Some(At::Array(_)) => None,
            // Past an element or an untouched member: nothing of the widening is left.
            None => return Ok(None),
        };
    }
    Ok(at)
}

/// Widens the uniform blocks at each (set, binding) of `blocks`; an error where one cannot be
/// (the lowering asks only for blocks `plan` accepted).
pub(super) fn widen_uniform_blocks(
    loaded: &mut Loaded,
    blocks: &[(u32, u32)],
) -> Result<(), SpirvError> {
    if blocks.is_empty() {
        return Ok(());
    }
    let at = variables_at(&loaded.module, |s, b| {
        blocks.contains(&(s, b)).then_some((s, b))
    });
    let mut vars: Vec<(Word, (u32, u32))> = at.into_iter().collect();
    vars.sort_unstable();
    for (var, (set, binding)) in vars {
        let refuse = |detail: NotWidened| SpirvError::Unsupported {
            feature: "a uniform block widened to std140",
            detail: format!("the uniform block at set {set} binding {binding}: {detail}"),
        };
        // Another stage's module may hold the block as std140 already.
        let Some(w) = plan(loaded, var).map_err(refuse)? else {
            continue;
        };
        apply(&mut loaded.module, var, &w)?;
    }
    Ok(())
}

/// Adds the widened types and retypes the variable and every chain into it.
fn apply(module: &mut Module, var: Word, w: &Widening) -> Result<(), SpirvError> {
    let at = &w.pointers;
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut added: Vec<Instruction> = Vec::new();
    let mut annotations: Vec<Instruction> = Vec::new();
    let uint = int32(module, &mut added, &mut ids, false)?;
    let (block, arrays) = widened_block(module, w, uint, (&mut added, &mut annotations), &mut ids)?;
    let root = match w.outer {
        Some(len) => {
            let r = ids.fresh()?;
            added.push(inst(
                Op::TypeArray,
                None,
                Some(r),
                vec![Operand::IdRef(block), Operand::IdRef(len)],
            ));
            r
        }
        None => block,
    };
    let mut pointer = |to: Word| {
        type_id(
            module,
            &mut added,
            &mut ids,
            Op::TypePointer,
            vec![
                Operand::StorageClass(StorageClass::Uniform),
                Operand::IdRef(to),
            ],
        )
    };
    let root_ptr = pointer(root)?;
    let block_ptr = pointer(block)?;
    let mut array_ptr = HashMap::new();
    for (&m, &a) in &arrays {
        array_ptr.insert(m, pointer(a)?);
    }
    // The variable moves after its new pointer type.
    let mut moved = None;
    module.types_global_values.retain(|i| {
        if i.result_id == Some(var) {
            moved = Some(i.clone());
            false
        } else {
            true
        }
    });
    let mut v = moved.ok_or(SpirvError::Unsupported {
        feature: "a uniform block widened to std140",
        detail: format!("variable %{var} is not global"),
    })?;
    v.result_type = Some(root_ptr);
    let type_of = |at: At| match at {
        At::Root => root_ptr,
        At::Block => block_ptr,
        At::Array(m) => array_ptr[&m],
    };
    let g_defs: HashMap<Word, (Option<Word>, Option<u32>)> = module
        .types_global_values
        .iter()
        .chain(added.iter())
        .filter_map(|i| {
            let value = (i.class.opcode == Op::Constant)
                .then(|| literal(i.operands.first()))
                .flatten();
            Some((i.result_id?, (i.result_type, value)))
        })
        .collect();
    let local_types = super::index::result_types(module);
    let mut functions = std::mem::take(&mut module.functions);
    for f in &mut functions {
        for b in &mut f.blocks {
            let mut out = Vec::with_capacity(b.instructions.len());
            for mut i in std::mem::take(&mut b.instructions) {
                let op = i.class.opcode;
                let base = id_ref(i.operands.first()).and_then(|x| at.get(&x).copied());
                if let (Op::AccessChain | Op::InBoundsAccessChain, Some(start)) = (op, base) {
                    let mut cur = Some(start);
                    let mut operands = vec![i.operands[0].clone()];
                    for index in &i.operands[1..] {
                        cur = match cur {
                            Some(At::Array(_)) => {
                                let id = id_ref(Some(index)).unwrap_or(0);
                                let (ty, value) = match g_defs.get(&id) {
                                    Some(&(ty, value)) => (ty, value),
                                    None => (local_types.get(&id).copied(), None),
                                };
                                let ty = ty.unwrap_or(uint);
                                let (q, r) = split_index(
                                    module,
                                    (&mut added, &mut out),
                                    &mut ids,
                                    (id, ty, value),
                                )?;
                                operands.push(Operand::IdRef(q));
                                operands.push(Operand::IdRef(r));
                                None
                            }
                            Some(At::Root) if w.outer.is_some() => {
                                operands.push(index.clone());
                                Some(At::Block)
                            }
                            Some(At::Root | At::Block) => {
                                operands.push(index.clone());
                                let m = id_ref(Some(index))
                                    .and_then(|x| g_defs.get(&x))
                                    .and_then(|d| d.1);
                                m.filter(|m| arrays.contains_key(m)).map(At::Array)
                            }
                            None => {
                                operands.push(index.clone());
                                None
                            }
                        };
                    }
                    i.operands = operands;
                }
                if let Some(id) = i.result_id
                    && id != var
                    && let Some(&a) = at.get(&id)
                {
                    i.result_type = Some(type_of(a));
                }
                out.push(i);
            }
            b.instructions = out;
        }
    }
    module.functions = functions;
    added.push(v);
    module.types_global_values.extend(added);
    module.annotations.extend(annotations);
    Ok(())
}

/// The block type with each widened array as an array of `vec4`s (stride 16), declared
/// anew with the old block's decorations: the new block and the widened arrays by member.
fn widened_block(
    module: &Module,
    w: &Widening,
    uint: Word,
    (added, annotations): (&mut Vec<Instruction>, &mut Vec<Instruction>),
    ids: &mut Ids,
) -> Result<(Word, HashMap<u32, Word>), SpirvError> {
    let old_members: Vec<Word> = module
        .types_global_values
        .iter()
        .find(|i| i.result_id == Some(w.block))
        .map(|i| i.operands.iter().filter_map(|o| id_ref(Some(o))).collect())
        .unwrap_or_default();
    let mut new_members = old_members.clone();
    let mut arrays: HashMap<u32, Word> = HashMap::new();
    for &(m, scalar, n) in &w.members {
        let vec4 = vector(module, added, ids, scalar, 4)?;
        let len = constant(module, added, ids, uint, n.div_ceil(4))?;
        let array = ids.fresh()?;
        added.push(inst(
            Op::TypeArray,
            None,
            Some(array),
            vec![Operand::IdRef(vec4), Operand::IdRef(len)],
        ));
        annotations.push(inst(
            Op::Decorate,
            None,
            None,
            vec![
                Operand::IdRef(array),
                Operand::Decoration(Decoration::ArrayStride),
                Operand::LiteralBit32(16),
            ],
        ));
        new_members[m as usize] = array;
        arrays.insert(m, array);
    }
    let block = ids.fresh()?;
    added.push(inst(
        Op::TypeStruct,
        None,
        Some(block),
        new_members.into_iter().map(Operand::IdRef).collect(),
    ));
    // The new block keeps the old one's decorations (Block, each member's Offset).
    for a in &module.annotations {
        if a.operands.first() == Some(&Operand::IdRef(w.block))
            && matches!(a.class.opcode, Op::Decorate | Op::MemberDecorate)
        {
            let mut copy = a.clone();
            copy.operands[0] = Operand::IdRef(block);
            annotations.push(copy);
        }
    }
    Ok((block, arrays))
}

/// A scalar array index `id` (of type `ty`, `value` where constant) as the `vec4` element
/// and the component in it: constants for a constant, a shift and a mask emitted otherwise.
fn split_index(
    module: &Module,
    (added, out): (&mut Vec<Instruction>, &mut Vec<Instruction>),
    ids: &mut Ids,
    (id, ty, value): (Word, Word, Option<u32>),
) -> Result<(Word, Word), SpirvError> {
    Ok(match value {
        Some(v) => (
            constant(module, added, ids, ty, v >> 2)?,
            constant(module, added, ids, ty, v & 3)?,
        ),
        None => {
            let two = constant(module, added, ids, ty, 2)?;
            let three = constant(module, added, ids, ty, 3)?;
            let (q, r) = (ids.fresh()?, ids.fresh()?);
            out.push(inst(
                Op::ShiftRightLogical,
                Some(ty),
                Some(q),
                vec![Operand::IdRef(id), Operand::IdRef(two)],
            ));
            out.push(inst(
                Op::BitwiseAnd,
                Some(ty),
                Some(r),
                vec![Operand::IdRef(id), Operand::IdRef(three)],
            ));
            (q, r)
        }
    })
}

/// A 32-bit constant of integer type `ty` with `value`, found or added.
fn constant(
    module: &Module,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    ty: Word,
    value: u32,
) -> Result<Word, SpirvError> {
    let operands = vec![Operand::LiteralBit32(value)];
    if let Some(id) = module
        .types_global_values
        .iter()
        .chain(added.iter())
        .find(|i| {
            i.class.opcode == Op::Constant && i.result_type == Some(ty) && i.operands == operands
        })
        .and_then(|i| i.result_id)
    {
        return Ok(id);
    }
    let id = ids.fresh()?;
    added.push(inst(Op::Constant, Some(ty), Some(id), operands));
    Ok(id)
}
