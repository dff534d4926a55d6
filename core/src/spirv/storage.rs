//! Uniform blocks read as storage blocks. wgpu's device binds uniform buffers by std140's
//! rules only; a block laid out more tightly (std430, as Mesa's zink packs every OpenGL
//! uniform block into an array of 32-bit words) reads the same bytes, by the same explicit
//! offsets and strides, as a read-only storage buffer, whose rules are std430's. This is the
//! fallback for blocks `std140` cannot widen in place (a storage read may be left undone in
//! helper invocations, which a uniform read never is). Each block the lowering names moves to the `StorageBuffer` storage class with every pointer into it,
//! and is decorated `NonWritable`.
//!
//! A pointer into such a block that leaves the access chains and loads (passed to a function,
//! chosen by `OpPhi` or `OpSelect`, stored) is refused: its type is shared with pointers that
//! stay uniform.

use std::collections::HashMap;

use rspirv::dr::{Module, Operand};
use rspirv::spirv::{Decoration, Op, StorageClass, Word};

use super::SpirvError;
use super::carry::variables_at;
use super::ops::inst;

/// The first SPIR-V version with the `StorageBuffer` storage class in core (1.3).
const STORAGE_BUFFER_CORE: u32 = 0x0001_0300;

fn refuse(set: u32, binding: u32, detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "use of a uniform block read as a storage block",
        detail: format!("the uniform block at set {set} binding {binding}: {detail}"),
    }
}

/// Moves the uniform blocks at each (set, binding) of `blocks` to the `StorageBuffer` storage
/// class, read-only. Blocks not in `blocks`, and bindings that hold no uniform block, are left.
pub(super) fn uniform_as_storage(
    module: &mut Module,
    blocks: &[(u32, u32)],
) -> Result<(), SpirvError> {
    if blocks.is_empty() {
        return Ok(());
    }
    let at = variables_at(module, |s, b| blocks.contains(&(s, b)).then_some((s, b)));
    let vars: HashMap<Word, (u32, u32)> = module
        .types_global_values
        .iter()
        .filter(|i| {
            i.class.opcode == Op::Variable
                && i.operands.first() == Some(&Operand::StorageClass(StorageClass::Uniform))
        })
        .filter_map(|i| {
            let id = i.result_id?;
            Some((id, *at.get(&id)?))
        })
        .collect();
    if vars.is_empty() {
        return Ok(());
    }
    let mut roots: Vec<Word> = vars.keys().copied().collect();
    roots.sort_unstable();
    super::reclass::reclass(
        module,
        &roots,
        StorageClass::Uniform,
        StorageClass::StorageBuffer,
    )?
    .map_err(|(var, op, n)| {
        let (set, binding) = vars[&var];
        refuse(
            set,
            binding,
            format!("a pointer into it is used by Op{op:?} (operand {n})"),
        )
    })?;
    for var in roots {
        module.annotations.push(inst(
            Op::Decorate,
            None,
            None,
            vec![
                Operand::IdRef(var),
                Operand::Decoration(Decoration::NonWritable),
            ],
        ));
    }
    let version = module.header.as_ref().map_or(0, |h| h.version);
    let extension = "SPV_KHR_storage_buffer_storage_class";
    if version < STORAGE_BUFFER_CORE
        && !module.extensions.iter().any(
            |i| matches!(i.operands.first(), Some(Operand::LiteralString(s)) if s == extension),
        )
    {
        module.extensions.push(inst(
            Op::Extension,
            None,
            None,
            vec![Operand::LiteralString(extension.to_owned())],
        ));
    }
    Ok(())
}
