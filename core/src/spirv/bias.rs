//! A sampler's LOD bias in the shader: wgpu's samplers have no `mipLodBias`, and Vulkan adds
//! it to the level of detail of every sample taken through the sampler, as it adds a shader's
//! own `Bias` operand (`λ' = λ + clamp(sampler bias + shader bias)`). So each sample whose
//! sampler comes from a biased binding gets that bias in its instruction: a `Bias` image
//! operand on an implicit-LOD sample, or added (`OpFAdd`) to the shader's own bias or to the
//! `Lod` of an explicit one. A sample that takes gradients is refused by name.
//!
//! Runs on the module as captured, before the split renumbers bindings, so the bindings are
//! the application's.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{ImageOperands, Op, Word};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::{Ids, float32, inst};

fn unsupported(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "sampler LOD bias on this sample",
        detail,
    }
}

/// Operands before the image operands of a sampling instruction, and whether its LOD is
/// implicit; `None` for instructions that sample nothing through a sampler's LOD.
fn sampling(op: Op) -> Option<(usize, bool)> {
    Some(match op {
        Op::ImageSampleImplicitLod
        | Op::ImageSampleProjImplicitLod
        | Op::ImageSparseSampleImplicitLod
        | Op::ImageSparseSampleProjImplicitLod => (2, true),
        Op::ImageSampleDrefImplicitLod
        | Op::ImageSampleProjDrefImplicitLod
        | Op::ImageSparseSampleDrefImplicitLod
        | Op::ImageSparseSampleProjDrefImplicitLod => (3, true),
        Op::ImageSampleExplicitLod
        | Op::ImageSampleProjExplicitLod
        | Op::ImageSparseSampleExplicitLod
        | Op::ImageSparseSampleProjExplicitLod => (2, false),
        Op::ImageSampleDrefExplicitLod
        | Op::ImageSampleProjDrefExplicitLod
        | Op::ImageSparseSampleDrefExplicitLod
        | Op::ImageSparseSampleProjDrefExplicitLod => (3, false),
        _ => return None,
    })
}

/// Adds `biases` ((set, binding, bias) of the samplers bound there, combined or separate) to
/// every sample taken through them.
pub(super) fn add_lod_bias(
    module: &mut Module,
    biases: &[(u32, u32, f32)],
) -> Result<(), SpirvError> {
    if biases.is_empty() {
        return Ok(());
    }
    // Variable -> its bias, from its DescriptorSet and Binding decorations.
    let bias_of: HashMap<Word, f32> = super::carry::variables_at(module, |s, b| {
        biases
            .iter()
            .find(|(bs, bb, _)| (*bs, *bb) == (s, b))
            .map(|(_, _, bias)| *bias)
    });
    if bias_of.is_empty() {
        return Ok(());
    }
    // Every id carrying a biased sampler on (OpSampledImage's operand 1 is the sampler).
    let root = super::carry::carried(module, &bias_of, 1);
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut added: Vec<Instruction> = Vec::new();
    let float = float32(module, &mut added, &mut ids)?;
    let mut constants: HashMap<u32, Word> = HashMap::new();
    let mut constant = |bias: f32, ids: &mut Ids, added: &mut Vec<Instruction>| {
        if let Some(&c) = constants.get(&bias.to_bits()) {
            return Ok::<Word, SpirvError>(c);
        }
        let c = ids.fresh()?;
        added.push(inst(
            Op::Constant,
            Some(float),
            Some(c),
            vec![Operand::LiteralBit32(bias.to_bits())],
        ));
        constants.insert(bias.to_bits(), c);
        Ok(c)
    };
    for f in &mut module.functions {
        for block in &mut f.blocks {
            let mut i = 0;
            while i < block.instructions.len() {
                let s = &block.instructions[i];
                let Some((fixed, implicit)) = sampling(s.class.opcode) else {
                    i += 1;
                    continue;
                };
                let Some(bias) = id_ref(s.operands.first())
                    .and_then(|x| root.get(&x))
                    .and_then(|v| bias_of.get(v))
                    .copied()
                else {
                    i += 1;
                    continue;
                };
                let c = constant(bias, &mut ids, &mut added)?;
                let what = format!("%{} (Op{:?})", s.result_id.unwrap_or(0), s.class.opcode);
                let s = &mut block.instructions[i];
                let mask = match s.operands.get(fixed) {
                    Some(Operand::ImageOperands(m)) => *m,
                    _ => ImageOperands::NONE,
                };
                if mask.contains(ImageOperands::GRAD) {
                    return Err(unsupported(format!("{what} takes explicit gradients")));
                }
                // Bias and Lod are the lowest image operand bits: their argument comes first
                // after the mask. A bias or level of the shader's own gets the sampler's
                // added to it.
                if mask.intersects(ImageOperands::BIAS | ImageOperands::LOD) {
                    let Some(Operand::IdRef(own)) = s.operands.get(fixed + 1).cloned() else {
                        return Err(unsupported(format!("{what} has no argument for its mask")));
                    };
                    let sum = ids.fresh()?;
                    s.operands[fixed + 1] = Operand::IdRef(sum);
                    block.instructions.insert(
                        i,
                        inst(
                            Op::FAdd,
                            Some(float),
                            Some(sum),
                            vec![Operand::IdRef(own), Operand::IdRef(c)],
                        ),
                    );
                    i += 2;
                } else if implicit {
                    // Bias is the lowest image operand bit: its argument comes first.
                    if s.operands.len() <= fixed {
                        s.operands.push(Operand::ImageOperands(ImageOperands::BIAS));
                        s.operands.push(Operand::IdRef(c));
                    } else {
                        s.operands[fixed] = Operand::ImageOperands(mask | ImageOperands::BIAS);
                        s.operands.insert(fixed + 1, Operand::IdRef(c));
                    }
                    i += 1;
                } else {
                    // An explicit level with no Lod operand (a ConstOffset alone) is invalid
                    // SPIR-V; left as it is.
                    i += 1;
                }
            }
        }
    }
    module.types_global_values.extend(added);
    if let Some(h) = module.header.as_mut() {
        h.bound = h.bound.max(ids.next);
    }
    Ok(())
}
