//! Moving variables to another storage class with every pointer derived from them (access
//! chains and copies), each retyped to a pointer of the new class to the same type. A pointer
//! that leaves the access chains, loads and stores (passed to a function, chosen by `OpPhi` or
//! `OpSelect`, stored as a value) cannot follow, since its type is shared with pointers that
//! stay: that use is returned for the caller to refuse by name.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Op, StorageClass, Word};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::{Ids, type_id};

/// Where an instruction may use a moved pointer: the pointer operand of a load or a store, an
/// access chain's base, a copy, a length query, and either side of a memory copy.
fn keeps_pointer(op: Op, operand: usize) -> bool {
    matches!(
        (op, operand),
        (Op::Load | Op::Store, 0)
            | (
                Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain | Op::CopyObject,
                0
            )
            | (Op::ArrayLength, 0)
            | (Op::CopyMemory | Op::CopyMemorySized, 0 | 1)
    )
}

/// Whether the instruction's result is a pointer derived from its operand 0.
fn derives(op: Op) -> bool {
    matches!(
        op,
        Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain | Op::CopyObject
    )
}

/// Moves the global variables `vars` (of class `from`) to class `to`. `Ok(Err((var, op,
/// operand)))` names a use of a pointer derived from `var` that cannot follow; nothing is
/// changed then.
pub(super) fn reclass(
    module: &mut Module,
    vars: &[Word],
    from: StorageClass,
    to: StorageClass,
) -> Result<Result<(), (Word, Op, usize)>, SpirvError> {
    // Every id carrying a pointer into a moved variable, with the variable.
    let mut derived: HashMap<Word, Word> = vars.iter().map(|&v| (v, v)).collect();
    loop {
        let before = derived.len();
        for i in module.functions.iter().flat_map(|f| f.all_inst_iter()) {
            if derives(i.class.opcode)
                && let (Some(id), Some(base)) = (i.result_id, id_ref(i.operands.first()))
                && let Some(&root) = derived.get(&base)
            {
                derived.insert(id, root);
            }
        }
        if derived.len() == before {
            break;
        }
    }
    for i in module.functions.iter().flat_map(|f| f.all_inst_iter()) {
        for (n, op) in i.operands.iter().enumerate() {
            if let Operand::IdRef(id) = op
                && let Some(&root) = derived.get(id)
                && !keeps_pointer(i.class.opcode, n)
            {
                return Ok(Err((root, i.class.opcode, n)));
            }
        }
    }
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let pointee: HashMap<Word, Word> = module
        .types_global_values
        .iter()
        .filter(|i| {
            i.class.opcode == Op::TypePointer
                && i.operands.first() == Some(&Operand::StorageClass(from))
        })
        .filter_map(|i| Some((i.result_id?, id_ref(i.operands.get(1))?)))
        .collect();
    let mut added = Vec::new();
    let mut moved_pointer: HashMap<Word, Word> = HashMap::new();
    // Sorted, so that the ids handed out do not depend on hashing.
    let mut types: Vec<(Word, Word)> = module
        .types_global_values
        .iter()
        .chain(module.functions.iter().flat_map(|f| f.all_inst_iter()))
        .filter_map(|i| {
            let id = i.result_id?;
            derived.contains_key(&id).then_some((id, i.result_type?))
        })
        .collect();
    types.sort_unstable();
    let mut new_types: HashMap<Word, Word> = HashMap::new();
    for (id, ty) in types {
        let Some(&target) = pointee.get(&ty) else {
            continue;
        };
        let t = match moved_pointer.get(&ty) {
            Some(&t) => t,
            None => {
                let t = type_id(
                    module,
                    &mut added,
                    &mut ids,
                    Op::TypePointer,
                    vec![Operand::StorageClass(to), Operand::IdRef(target)],
                )?;
                moved_pointer.insert(ty, t);
                t
            }
        };
        new_types.insert(id, t);
    }
    // The variables move after the pointer types they now have.
    let mut moved: Vec<Instruction> = Vec::new();
    module.types_global_values.retain(|i| {
        if i.result_id.is_some_and(|id| vars.contains(&id)) {
            moved.push(i.clone());
            false
        } else {
            true
        }
    });
    for mut v in moved {
        if let Some(id) = v.result_id {
            v.result_type = new_types.get(&id).copied().or(v.result_type);
        }
        v.operands[0] = Operand::StorageClass(to);
        added.push(v);
    }
    module.types_global_values.extend(added);
    for f in &mut module.functions {
        for b in &mut f.blocks {
            for i in &mut b.instructions {
                if let Some(id) = i.result_id
                    && let Some(&ty) = new_types.get(&id)
                {
                    i.result_type = Some(ty);
                }
            }
        }
    }
    Ok(Ok(()))
}
