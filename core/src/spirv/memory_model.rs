//! Modules written for the Vulkan memory model (`OpMemoryModel ... Vulkan`, as Mesa's zink
//! writes every shader) need `vulkanMemoryModel`, which wgpu's device never turns on. The
//! model differs from GLSL450's only where invocations share memory through explicit
//! availability and visibility: a module that asks for none (no `MakePointerAvailable`,
//! `MakePointerVisible`, `MakeTexelAvailable`, `MakeTexelVisible` operand, no `Volatile`
//! access, no barrier or atomic with availability, visibility, output-memory or volatile
//! semantics) means the same under GLSL450's model, and is declared so; `NonPrivatePointer`
//! and `NonPrivateTexel`, which only the Vulkan model has, are dropped. A module that asks for
//! any of those is refused with the instruction named.

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{
    Capability, ImageOperands, MemoryAccess, MemoryModel, MemorySemantics, Op, Word,
};

use super::SpirvError;

fn refuse(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "Vulkan memory model availability or visibility",
        detail,
    }
}

/// The semantics bits that only the Vulkan memory model gives meaning to, and that change what
/// a barrier or an atomic makes visible.
fn vulkan_only_semantics() -> MemorySemantics {
    MemorySemantics::OUTPUT_MEMORY
        | MemorySemantics::MAKE_AVAILABLE
        | MemorySemantics::MAKE_VISIBLE
        | MemorySemantics::VOLATILE
}

/// The operands of an instruction that are memory semantics ids.
fn semantics_operands(op: Op) -> &'static [usize] {
    match op {
        Op::ControlBarrier => &[2],
        Op::MemoryBarrier => &[1],
        Op::AtomicCompareExchange | Op::AtomicCompareExchangeWeak => &[2, 3],
        Op::AtomicLoad
        | Op::AtomicStore
        | Op::AtomicExchange
        | Op::AtomicIIncrement
        | Op::AtomicIDecrement
        | Op::AtomicIAdd
        | Op::AtomicISub
        | Op::AtomicSMin
        | Op::AtomicUMin
        | Op::AtomicSMax
        | Op::AtomicUMax
        | Op::AtomicAnd
        | Op::AtomicOr
        | Op::AtomicXor
        | Op::AtomicFAddEXT
        | Op::AtomicFMinEXT
        | Op::AtomicFMaxEXT
        | Op::AtomicFlagTestAndSet
        | Op::AtomicFlagClear => &[2],
        _ => &[],
    }
}

/// Declares a Vulkan-model module under GLSL450's model where that changes nothing it does;
/// whether it was a Vulkan-model module.
pub(super) fn as_glsl450(module: &mut Module) -> Result<bool, SpirvError> {
    let Some(model) = module.memory_model.as_mut() else {
        return Ok(false);
    };
    if model.operands.get(1) != Some(&Operand::MemoryModel(MemoryModel::Vulkan)) {
        return Ok(false);
    }
    let constants: std::collections::HashMap<Word, u32> = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::Constant)
        .filter_map(|i| match (i.result_id, i.operands.first()) {
            (Some(id), Some(Operand::LiteralBit32(v))) => Some((id, *v)),
            _ => None,
        })
        .collect();
    for f in &mut module.functions {
        for b in &mut f.blocks {
            for i in &mut b.instructions {
                check_semantics(i, &constants)?;
                strip_private_flags(i)?;
            }
        }
    }
    if let Some(model) = module.memory_model.as_mut() {
        model.operands[1] = Operand::MemoryModel(MemoryModel::GLSL450);
    }
    module.capabilities.retain(|i| {
        !matches!(
            i.operands.first(),
            Some(Operand::Capability(
                Capability::VulkanMemoryModel | Capability::VulkanMemoryModelDeviceScope
            ))
        )
    });
    module.extensions.retain(|i| {
        !matches!(i.operands.first(),
            Some(Operand::LiteralString(s)) if s == "SPV_KHR_vulkan_memory_model")
    });
    Ok(true)
}

fn check_semantics(
    i: &Instruction,
    constants: &std::collections::HashMap<Word, u32>,
) -> Result<(), SpirvError> {
    for &n in semantics_operands(i.class.opcode) {
        // rspirv types the operand as semantics; a hand-made module may give a plain id.
        let Some(Operand::IdMemorySemantics(id) | Operand::IdRef(id)) = i.operands.get(n) else {
            continue;
        };
        // Semantics come from constants; one computed at run time could be anything.
        let bits = constants.get(id).copied().ok_or_else(|| {
            refuse(format!(
                "Op{:?} takes its memory semantics from %{id}, which is no constant",
                i.class.opcode
            ))
        })?;
        let asked = MemorySemantics::from_bits_truncate(bits) & vulkan_only_semantics();
        if !asked.is_empty() {
            return Err(refuse(format!(
                "Op{:?} with memory semantics {asked:?}",
                i.class.opcode
            )));
        }
    }
    Ok(())
}

/// Drops `NonPrivatePointer` / `NonPrivateTexel` from memory and image operands; refuses the
/// flags that make memory available or visible, or volatile.
fn strip_private_flags(i: &mut Instruction) -> Result<(), SpirvError> {
    let op = i.class.opcode;
    let refused_access = MemoryAccess::MAKE_POINTER_AVAILABLE
        | MemoryAccess::MAKE_POINTER_VISIBLE
        | MemoryAccess::VOLATILE;
    let refused_image = ImageOperands::MAKE_TEXEL_AVAILABLE
        | ImageOperands::MAKE_TEXEL_VISIBLE
        | ImageOperands::VOLATILE_TEXEL;
    for operand in &mut i.operands {
        match operand {
            Operand::MemoryAccess(a) => {
                if a.intersects(refused_access) {
                    return Err(refuse(format!(
                        "Op{op:?} with memory access {:?}",
                        *a & refused_access
                    )));
                }
                a.remove(MemoryAccess::NON_PRIVATE_POINTER);
            }
            Operand::ImageOperands(m) => {
                if m.intersects(refused_image) {
                    return Err(refuse(format!(
                        "Op{op:?} with image operands {:?}",
                        *m & refused_image
                    )));
                }
                m.remove(ImageOperands::NON_PRIVATE_TEXEL);
            }
            _ => {}
        }
    }
    Ok(())
}
