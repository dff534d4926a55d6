//! A view's component swizzle (`VkImageViewCreateInfo::components`) in the shader: wgpu's
//! views read their channels as they are, so each texel read through a swizzled binding
//! gets the swizzle applied to its result, `OpVectorShuffle` of the read and a constant
//! (0, 0, 0, 1) of its component type, as the specification's "Image View Creation" maps
//! R, G, B and A. Gathers pick the swizzled component (or a constant vector where it is 0 or
//! 1). Depth comparisons and sparse reads through a swizzled view are refused by name.
//!
//! Runs on the module as captured, before the split renumbers bindings, so the bindings are
//! the application's. Views are the lowering's business; here a swizzle is four codes:
//! 0 to 3 a component, 4 zero, 5 one.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Op, Word};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::{Ids, inst};

/// A swizzle code for zero.
pub const ZERO: u8 = 4;
/// A swizzle code for one.
pub const ONE: u8 = 5;

fn unsupported(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "a swizzled view read this way",
        detail,
    }
}

/// What an image instruction reads through its image operand (operand 0).
enum Read {
    /// A vec4 texel: sampled or fetched.
    Texel,
    /// A gather: its component operand (operand 2) picks the channel.
    Gather,
    /// A depth comparison or a sparse read: refused where swizzled.
    Refused,
}

fn read(op: Op) -> Option<Read> {
    Some(match op {
        Op::ImageSampleImplicitLod
        | Op::ImageSampleExplicitLod
        | Op::ImageSampleProjImplicitLod
        | Op::ImageSampleProjExplicitLod
        | Op::ImageFetch
        | Op::ImageRead => Read::Texel,
        Op::ImageGather => Read::Gather,
        Op::ImageSampleDrefImplicitLod
        | Op::ImageSampleDrefExplicitLod
        | Op::ImageSampleProjDrefImplicitLod
        | Op::ImageSampleProjDrefExplicitLod
        | Op::ImageDrefGather
        | Op::ImageSparseSampleImplicitLod
        | Op::ImageSparseSampleExplicitLod
        | Op::ImageSparseSampleDrefImplicitLod
        | Op::ImageSparseSampleDrefExplicitLod
        | Op::ImageSparseFetch
        | Op::ImageSparseGather
        | Op::ImageSparseDrefGather
        | Op::ImageSparseRead => Read::Refused,
        _ => return None,
    })
}

/// Applies `swizzles` ((set, binding, codes) of the views bound there) to every texel read
/// through them.
pub(super) fn apply_swizzles(
    module: &mut Module,
    swizzles: &[(u32, u32, [u8; 4])],
) -> Result<(), SpirvError> {
    if swizzles.is_empty() {
        return Ok(());
    }
    let swizzle_of: HashMap<Word, [u8; 4]> = super::carry::variables_at(module, |s, b| {
        swizzles
            .iter()
            .find(|(ss, sb, _)| (*ss, *sb) == (s, b))
            .map(|(_, _, sw)| *sw)
    });
    if swizzle_of.is_empty() {
        return Ok(());
    }
    // Every id carrying a swizzled image on (OpSampledImage's operand 0 is the image, and
    // images are taken back out of sampled images).
    let root = super::carry::carried(module, &swizzle_of, 0);
    let globals: HashMap<Word, Instruction> = module
        .types_global_values
        .iter()
        .filter_map(|i| Some((i.result_id?, i.clone())))
        .collect();
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut added: Vec<Instruction> = Vec::new();
    // (0, 0, 0, 1) per vec4 type, and each scalar constant per (type, value).
    let mut zero_one: HashMap<Word, Word> = HashMap::new();
    let mut scalars: HashMap<(Word, u32), Word> = HashMap::new();
    for f in &mut module.functions {
        for block in &mut f.blocks {
            let mut i = 0;
            while i < block.instructions.len() {
                let s = &block.instructions[i];
                let (Some(kind), Some(sw)) = (
                    read(s.class.opcode),
                    id_ref(s.operands.first())
                        .and_then(|x| root.get(&x))
                        .and_then(|v| swizzle_of.get(v)),
                ) else {
                    i += 1;
                    continue;
                };
                let sw = *sw;
                let what = format!("%{} (Op{:?})", s.result_id.unwrap_or(0), s.class.opcode);
                let (vec4, result, scalar, one_bits) = read_types(s, &globals, &what)?;
                let mut scalar_const = |bits: u32, ids: &mut Ids, added: &mut Vec<Instruction>| {
                    if let Some(&c) = scalars.get(&(scalar, bits)) {
                        return Ok::<Word, SpirvError>(c);
                    }
                    let c = ids.fresh()?;
                    added.push(inst(
                        Op::Constant,
                        Some(scalar),
                        Some(c),
                        vec![Operand::LiteralBit32(bits)],
                    ));
                    scalars.insert((scalar, bits), c);
                    Ok(c)
                };
                match kind {
                    Read::Refused => {
                        return Err(unsupported(format!(
                            "{what}: a depth comparison or sparse read through a view swizzled {sw:?}"
                        )));
                    }
                    Read::Gather => {
                        let (component, component_ty) = gathered_component(s, &globals, &what)?;
                        let picked = sw[component as usize];
                        if picked < 4 {
                            let c = ids.fresh()?;
                            added.push(inst(
                                Op::Constant,
                                Some(component_ty),
                                Some(c),
                                vec![Operand::LiteralBit32(u32::from(picked))],
                            ));
                            block.instructions[i].operands[2] = Operand::IdRef(c);
                            i += 1;
                        } else {
                            // Every texel's swizzled channel is the same constant.
                            let bits = if picked == ONE { one_bits } else { 0 };
                            let k = scalar_const(bits, &mut ids, &mut added)?;
                            let fresh = ids.fresh()?;
                            block.instructions[i].result_id = Some(fresh);
                            block.instructions.insert(
                                i + 1,
                                inst(
                                    Op::CompositeConstruct,
                                    Some(vec4),
                                    Some(result),
                                    vec![Operand::IdRef(k); 4],
                                ),
                            );
                            i += 2;
                        }
                    }
                    Read::Texel => {
                        let constant = match zero_one.get(&vec4) {
                            Some(&c) => c,
                            None => {
                                let zero = scalar_const(0, &mut ids, &mut added)?;
                                let one = scalar_const(one_bits, &mut ids, &mut added)?;
                                let c = ids.fresh()?;
                                added.push(inst(
                                    Op::ConstantComposite,
                                    Some(vec4),
                                    Some(c),
                                    vec![
                                        Operand::IdRef(zero),
                                        Operand::IdRef(zero),
                                        Operand::IdRef(zero),
                                        Operand::IdRef(one),
                                    ],
                                ));
                                zero_one.insert(vec4, c);
                                c
                            }
                        };
                        // The read gets a fresh id; its old one is the swizzled value, so
                        // every use reads the view as Vulkan gives it.
                        let fresh = ids.fresh()?;
                        block.instructions[i].result_id = Some(fresh);
                        let mut operands = vec![Operand::IdRef(fresh), Operand::IdRef(constant)];
                        operands.extend(sw.iter().map(|&c| {
                            Operand::LiteralBit32(match c {
                                ZERO => 4,
                                ONE => 7,
                                c => u32::from(c),
                            })
                        }));
                        block.instructions.insert(
                            i + 1,
                            inst(Op::VectorShuffle, Some(vec4), Some(result), operands),
                        );
                        i += 2;
                    }
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

/// A swizzled read's result type and id, its scalar type, and that type's one as bits.
fn read_types(
    s: &Instruction,
    globals: &HashMap<Word, Instruction>,
    what: &str,
) -> Result<(Word, Word, Word, u32), SpirvError> {
    let (Some(vec4), Some(result)) = (s.result_type, s.result_id) else {
        return Err(unsupported(format!("{what} has no result")));
    };
    let scalar = match globals.get(&vec4) {
        Some(v) if v.class.opcode == Op::TypeVector => id_ref(v.operands.first()),
        _ => None,
    }
    .ok_or_else(|| unsupported(format!("{what} does not read a vector")))?;
    let one_bits = match globals.get(&scalar).map(|t| t.class.opcode) {
        Some(Op::TypeFloat) => 1.0f32.to_bits(),
        Some(Op::TypeInt) => 1,
        _ => return Err(unsupported(format!("{what} reads an unknown type"))),
    };
    Ok((vec4, result, scalar, one_bits))
}

/// The component a gather reads and its type: a constant, to be swizzled here.
fn gathered_component(
    s: &Instruction,
    globals: &HashMap<Word, Instruction>,
    what: &str,
) -> Result<(u32, Word), SpirvError> {
    let component = id_ref(s.operands.get(2))
        .and_then(|c| globals.get(&c))
        .filter(|c| c.class.opcode == Op::Constant)
        .and_then(|c| match c.operands.first() {
            Some(Operand::LiteralBit32(v)) => Some(*v),
            _ => None,
        })
        .filter(|&v| v < 4)
        .ok_or_else(|| unsupported(format!("{what} gathers a component not constant")))?;
    let component_ty = id_ref(s.operands.get(2))
        .and_then(|c| globals.get(&c))
        .and_then(|c| c.result_type)
        .ok_or_else(|| unsupported(format!("{what}: untyped component")))?;
    Ok((component, component_ty))
}
