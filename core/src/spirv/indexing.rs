//! The `*ArrayDynamicIndexing` capabilities let a shader index an array of descriptors with a
//! value known only at run time; each needs a device feature (`shaderUniformBufferArrayDynamicIndexing`,
//! ...) that wgpu turns on only for binding arrays. Compilers declare them by habit (Mesa's zink
//! on every module that has a block array, even of one block): where every array of
//! descriptors the module keeps has one element, the only index a valid module can use is 0,
//! so the permission means nothing and is dropped. Arrays of more than one descriptor are the
//! lowering's to refuse.

use std::collections::HashMap;

use rspirv::dr::{Module, Operand};
use rspirv::spirv::{Capability, Op, StorageClass, Word};

use super::index::id_ref;

const DYNAMIC_INDEXING: [Capability; 4] = [
    Capability::UniformBufferArrayDynamicIndexing,
    Capability::SampledImageArrayDynamicIndexing,
    Capability::StorageBufferArrayDynamicIndexing,
    Capability::StorageImageArrayDynamicIndexing,
];

/// Drops the dynamic-indexing capabilities where no descriptor array of the module has more
/// than one element; whether it dropped any.
pub(super) fn drop_needless_dynamic_indexing(module: &mut Module) -> bool {
    let declared = |m: &Module| {
        m.capabilities.iter().any(|i| {
            matches!(i.operands.first(), Some(Operand::Capability(c)) if DYNAMIC_INDEXING.contains(c))
        })
    };
    if !declared(module) || any_longer_array(module) {
        return false;
    }
    module.capabilities.retain(|i| {
        !matches!(i.operands.first(), Some(Operand::Capability(c)) if DYNAMIC_INDEXING.contains(c))
    });
    true
}

/// Whether a descriptor variable (uniform, uniform-constant or storage-buffer class) is an
/// array other than one of a single element with a constant length.
fn any_longer_array(module: &Module) -> bool {
    let globals: HashMap<Word, &rspirv::dr::Instruction> = module
        .types_global_values
        .iter()
        .filter_map(|i| Some((i.result_id?, i)))
        .collect();
    let pointee = |ptr: Word| {
        let p = globals.get(&ptr)?;
        (p.class.opcode == Op::TypePointer).then(|| id_ref(p.operands.get(1)))?
    };
    module.types_global_values.iter().any(|v| {
        if v.class.opcode != Op::Variable
            || !matches!(
                v.operands.first(),
                Some(Operand::StorageClass(
                    StorageClass::Uniform
                        | StorageClass::UniformConstant
                        | StorageClass::StorageBuffer
                ))
            )
        {
            return false;
        }
        let Some(ty) = v
            .result_type
            .and_then(pointee)
            .and_then(|t| globals.get(&t))
        else {
            return true;
        };
        match ty.class.opcode {
            Op::TypeRuntimeArray => true,
            Op::TypeArray => {
                let length = id_ref(ty.operands.get(1)).and_then(|l| globals.get(&l));
                !length.is_some_and(|l| {
                    l.class.opcode == Op::Constant
                        && l.operands.first() == Some(&Operand::LiteralBit32(1))
                })
            }
            _ => false,
        }
    })
}
