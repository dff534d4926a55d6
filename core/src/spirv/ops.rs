//! Making instructions for a rewrite: fresh ids past every one in use, instructions, and
//! global types found or added once. Shared by the rewrites that add code.

use std::collections::{HashMap, HashSet};

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Op, Word};

use super::SpirvError;

/// Hands out ids past every one in use.
pub(super) struct Ids {
    pub(super) next: Word,
}

impl Ids {
    pub(super) fn fresh(&mut self) -> Result<Word, SpirvError> {
        let id = self.next;
        self.next = id
            .checked_add(1)
            .ok_or(SpirvError::IdsExhausted { bound: id })?;
        Ok(id)
    }
}

pub(super) fn inst(
    op: Op,
    ty: Option<Word>,
    id: Option<Word>,
    operands: Vec<Operand>,
) -> Instruction {
    Instruction::new(op, ty, id, operands)
}

/// An existing global type with this opcode and these operands, or a new one appended to
/// `added` (global types are appended after everything they could refer to).
pub(super) fn type_id(
    module: &Module,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    op: Op,
    operands: Vec<Operand>,
) -> Result<Word, SpirvError> {
    let existing = module
        .types_global_values
        .iter()
        .chain(added.iter())
        .find(|i| i.class.opcode == op && i.operands == operands)
        .and_then(|i| i.result_id);
    if let Some(id) = existing {
        return Ok(id);
    }
    let id = ids.fresh()?;
    added.push(inst(op, None, Some(id), operands));
    Ok(id)
}

/// An `OpName` giving `id` the debug name `text`.
pub(super) fn name(id: Word, text: String) -> Instruction {
    inst(
        Op::Name,
        None,
        None,
        vec![Operand::IdRef(id), Operand::LiteralString(text)],
    )
}

/// The module's 32-bit integer types of either signedness, in the order it declares them.
pub(super) fn int32_types(module: &Module) -> Vec<Word> {
    module
        .types_global_values
        .iter()
        .filter(|i| {
            i.class.opcode == Op::TypeInt && super::index::literal(i.operands.first()) == Some(32)
        })
        .filter_map(|i| i.result_id)
        .collect()
}

/// The 32-bit integer type (`signed`), found or added.
pub(super) fn int32(
    module: &Module,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    signed: bool,
) -> Result<Word, SpirvError> {
    let operands = vec![
        Operand::LiteralBit32(32),
        Operand::LiteralBit32(u32::from(signed)),
    ];
    type_id(module, added, ids, rspirv::spirv::Op::TypeInt, operands)
}

/// The 32-bit float type, found or added.
pub(super) fn float32(
    module: &Module,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
) -> Result<Word, SpirvError> {
    let operands = vec![Operand::LiteralBit32(32)];
    type_id(module, added, ids, rspirv::spirv::Op::TypeFloat, operands)
}

/// The vector of `n` `component`s, found or added.
pub(super) fn vector(
    module: &Module,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    component: Word,
    n: u32,
) -> Result<Word, SpirvError> {
    let operands = vec![Operand::IdRef(component), Operand::LiteralBit32(n)];
    type_id(module, added, ids, rspirv::spirv::Op::TypeVector, operands)
}

/// A 32-bit constant of type `ty` with the bits `bits`, made once per (type, bits) in `cache`
/// and added to `added`.
pub(super) fn constant(
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    cache: &mut HashMap<(Word, u32), Word>,
    ty: Word,
    bits: u32,
) -> Result<Word, SpirvError> {
    if let Some(&id) = cache.get(&(ty, bits)) {
        return Ok(id);
    }
    let id = ids.fresh()?;
    added.push(inst(
        Op::Constant,
        Some(ty),
        Some(id),
        vec![Operand::LiteralBit32(bits)],
    ));
    cache.insert((ty, bits), id);
    Ok(id)
}

/// Whether `op` samples through a sampler, its sampled image operand 0 and its coordinate
/// operand 1: the instructions a sampler's state reaches (its coordinate rewrites).
pub(super) fn samples_through_sampler(op: Op) -> bool {
    matches!(
        op,
        Op::ImageSampleImplicitLod
            | Op::ImageSampleExplicitLod
            | Op::ImageSampleDrefImplicitLod
            | Op::ImageSampleDrefExplicitLod
            | Op::ImageSampleProjImplicitLod
            | Op::ImageSampleProjExplicitLod
            | Op::ImageSampleProjDrefImplicitLod
            | Op::ImageSampleProjDrefExplicitLod
            | Op::ImageGather
            | Op::ImageDrefGather
            | Op::ImageSparseSampleImplicitLod
            | Op::ImageSparseSampleExplicitLod
            | Op::ImageSparseSampleDrefImplicitLod
            | Op::ImageSparseSampleDrefExplicitLod
            | Op::ImageSparseSampleProjImplicitLod
            | Op::ImageSparseSampleProjExplicitLod
            | Op::ImageSparseSampleProjDrefImplicitLod
            | Op::ImageSparseSampleProjDrefExplicitLod
            | Op::ImageSparseGather
            | Op::ImageSparseDrefGather
    )
}

/// The module's GLSL.std.450 import, if it has one.
pub(super) fn glsl_import(module: &Module) -> Option<Word> {
    module
        .ext_inst_imports
        .iter()
        .find(|i| {
            matches!(i.operands.first(), Some(Operand::LiteralString(n)) if n == "GLSL.std.450")
        })
        .and_then(|i| i.result_id)
}

/// Imports GLSL.std.450 as `id` where a rewrite took a fresh id for it (`glsl_import` found
/// none).
pub(super) fn add_glsl_import(module: &mut Module, id: Option<Word>) {
    let imported = module.ext_inst_imports.iter().any(|i| i.result_id == id);
    if let Some(id) = id.filter(|_| !imported) {
        module.ext_inst_imports.push(inst(
            Op::ExtInstImport,
            None,
            Some(id),
            vec![Operand::LiteralString("GLSL.std.450".to_owned())],
        ));
    }
}

/// An access chain (in bounds or not).
pub(super) fn is_chain(i: &Instruction) -> bool {
    matches!(i.class.opcode, Op::AccessChain | Op::InBoundsAccessChain)
}

/// The 32-bit integer constants, by id, with their values.
pub(super) fn int_constants(module: &Module) -> HashMap<Word, u32> {
    let ints: HashSet<Word> = int32_types(module).into_iter().collect();
    module
        .types_global_values
        .iter()
        .filter(|c| {
            c.class.opcode == Op::Constant && c.result_type.is_some_and(|t| ints.contains(&t))
        })
        .filter_map(|c| Some((c.result_id?, super::index::literal(c.operands.first())?)))
        .collect()
}
