//! Samplers with unnormalized coordinates, in the shader: wgpu's samplers always take
//! coordinates in [0, 1], where Vulkan's `unnormalizedCoordinates` takes them in texels. Each
//! sample through such a sampler has its coordinate divided by the size of the image's level
//! 0 (`OpImageQuerySizeLod`), which the sampler then multiplies back. Through a nearest
//! sampler the coordinate is first moved to its texel's centre (`floor(u) + 0.5`): Vulkan
//! reads texel `floor(u)`, and at a whole `u` the division and the multiplication back can
//! round just below it (FFmpeg's overlay samples at whole texels). Vulkan allows such a
//! sampler only level 0, one filter, clamping addresses and the plain explicit-LOD samples
//! of 1D and 2D images, so nothing else changes. Any other instruction sampling through it
//! is refused by name.
//!
//! Runs on the module as captured, before the split renumbers bindings.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Capability, Op, Word};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::{Ids, inst, int32, vector};

fn unsupported(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "a sample through a sampler with unnormalized coordinates",
        detail,
    }
}

/// Divides the coordinate of every sample taken through the samplers at `at` ((set, binding),
/// combined or separate) by its image's size.
pub(super) fn normalize_coordinates(
    module: &mut Module,
    at: &[(u32, u32, bool)],
) -> Result<(), SpirvError> {
    if at.is_empty() {
        return Ok(());
    }
    // Variable -> whether its sampler filters nearest.
    let vars: HashMap<Word, bool> = super::carry::variables_at(module, |s, b| {
        at.iter()
            .find(|&&(set, binding, _)| (set, binding) == (s, b))
            .map(|&(_, _, nearest)| nearest)
    });
    if vars.is_empty() {
        return Ok(());
    }
    // Every id carrying one of the samplers on (OpSampledImage's operand 1 is the sampler).
    let root = super::carry::carried(module, &vars, 1);
    let globals: HashMap<Word, Instruction> = module
        .types_global_values
        .iter()
        .filter_map(|i| Some((i.result_id?, i.clone())))
        .collect();
    let types = super::index::result_types(module);
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut added: Vec<Instruction> = Vec::new();
    let int = int32(module, &mut added, &mut ids, true)?;
    let zero = ids.fresh()?;
    added.push(inst(
        Op::Constant,
        Some(int),
        Some(zero),
        vec![Operand::LiteralBit32(0)],
    ));
    let mut touched = false;
    // GLSL.std.450, imported where a nearest sample needs its `Floor`, and one half of each
    // coordinate type.
    let mut glsl: Option<Word> = super::ops::glsl_import(module);
    let mut halves: HashMap<Word, Word> = HashMap::new();
    let mut functions = std::mem::take(&mut module.functions);
    for f in &mut functions {
        for block in &mut f.blocks {
            let mut out = Vec::with_capacity(block.instructions.len());
            for mut s in std::mem::take(&mut block.instructions) {
                let nearest = match id_ref(s.operands.first()).and_then(|x| root.get(&x)) {
                    Some(var) if super::ops::samples_through_sampler(s.class.opcode) => {
                        vars.get(var).copied().unwrap_or(false)
                    }
                    _ => {
                        out.push(s);
                        continue;
                    }
                };
                let what = format!("%{} (Op{:?})", s.result_id.unwrap_or(0), s.class.opcode);
                if !matches!(
                    s.class.opcode,
                    Op::ImageSampleExplicitLod | Op::ImageSparseSampleExplicitLod
                ) {
                    return Err(unsupported(format!(
                        "{what}: Vulkan allows such a sampler only plain explicit-LOD samples"
                    )));
                }
                let (Some(sampled), Some(coord)) =
                    (id_ref(s.operands.first()), id_ref(s.operands.get(1)))
                else {
                    return Err(unsupported(format!("{what} has no image or coordinate")));
                };
                let (coord_ty, size_ty) = coordinate_types(
                    module,
                    (&types, &globals),
                    (coord, int),
                    &mut added,
                    &mut ids,
                    &what,
                )?;
                // The image of the sampled image, its level 0's size, as floats.
                let sampled_ty = types
                    .get(&sampled)
                    .and_then(|t| globals.get(t))
                    .filter(|t| t.class.opcode == Op::TypeSampledImage)
                    .and_then(|t| id_ref(t.operands.first()))
                    .ok_or_else(|| unsupported(format!("{what}: not a sampled image")))?;
                let (image, size, fsize, normalized) =
                    (ids.fresh()?, ids.fresh()?, ids.fresh()?, ids.fresh()?);
                out.push(inst(
                    Op::Image,
                    Some(sampled_ty),
                    Some(image),
                    vec![Operand::IdRef(sampled)],
                ));
                out.push(inst(
                    Op::ImageQuerySizeLod,
                    Some(size_ty),
                    Some(size),
                    vec![Operand::IdRef(image), Operand::IdRef(zero)],
                ));
                out.push(inst(
                    Op::ConvertSToF,
                    Some(coord_ty),
                    Some(fsize),
                    vec![Operand::IdRef(size)],
                ));
                let coord = if nearest {
                    let at = (&globals, coord_ty);
                    let found = (&mut glsl, &mut halves);
                    texel_centre(coord, at, found, (&mut added, &mut out), &mut ids)?
                } else {
                    coord
                };
                out.push(inst(
                    Op::FDiv,
                    Some(coord_ty),
                    Some(normalized),
                    vec![Operand::IdRef(coord), Operand::IdRef(fsize)],
                ));
                s.operands[1] = Operand::IdRef(normalized);
                out.push(s);
                touched = true;
            }
            block.instructions = out;
        }
    }
    module.functions = functions;
    if touched {
        module.types_global_values.extend(added);
        super::ops::add_glsl_import(module, glsl);
        let has_query = module
            .capabilities
            .iter()
            .any(|c| c.operands.first() == Some(&Operand::Capability(Capability::ImageQuery)));
        if !has_query {
            module.capabilities.push(inst(
                Op::Capability,
                None,
                None,
                vec![Operand::Capability(Capability::ImageQuery)],
            ));
        }
    }
    Ok(())
}

/// The centre of the texel `coord` (of float type `ty`) falls in, `floor(coord) + 0.5`: a
/// nearest filter reads that texel whatever the size it is divided by. The GLSL.std.450
/// import and each type's half are made once, as first needed.
fn texel_centre(
    coord: Word,
    (globals, coord_ty): (&HashMap<Word, Instruction>, Word),
    (glsl, halves): (&mut Option<Word>, &mut HashMap<Word, Word>),
    (added, out): (&mut Vec<Instruction>, &mut Vec<Instruction>),
    ids: &mut Ids,
) -> Result<Word, SpirvError> {
    let set = match *glsl {
        Some(id) => id,
        None => {
            let id = ids.fresh()?;
            *glsl = Some(id);
            id
        }
    };
    let half = match halves.get(&coord_ty) {
        Some(&h) => h,
        None => {
            let h = half_of(globals, added, ids, coord_ty)?;
            halves.insert(coord_ty, h);
            h
        }
    };
    let (floor, centre) = (ids.fresh()?, ids.fresh()?);
    out.push(inst(
        Op::ExtInst,
        Some(coord_ty),
        Some(floor),
        vec![
            Operand::IdRef(set),
            Operand::LiteralExtInstInteger(GLSL_FLOOR),
            Operand::IdRef(coord),
        ],
    ));
    out.push(inst(
        Op::FAdd,
        Some(coord_ty),
        Some(centre),
        vec![Operand::IdRef(floor), Operand::IdRef(half)],
    ));
    Ok(centre)
}

/// A sample's coordinate type (a float for 1D, a vector of two floats for 2D) and the type
/// of its image's size query (`int` or a vector of two).
fn coordinate_types(
    module: &Module,
    (types, globals): (&HashMap<Word, Word>, &HashMap<Word, Instruction>),
    (coord, int): (Word, Word),
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    what: &str,
) -> Result<(Word, Word), SpirvError> {
    let coord_ty = types
        .get(&coord)
        .copied()
        .or_else(|| globals.get(&coord).and_then(|c| c.result_type))
        .ok_or_else(|| unsupported(format!("{what}: untyped coordinate")))?;
    let size_ty = match globals.get(&coord_ty).map(|t| t.class.opcode) {
        Some(Op::TypeFloat) => int,
        Some(Op::TypeVector)
            if globals[&coord_ty].operands.get(1) == Some(&Operand::LiteralBit32(2)) =>
        {
            vector(module, added, ids, int, 2)?
        }
        _ => {
            return Err(unsupported(format!(
                "{what} samples with a coordinate of more than two components"
            )));
        }
    };
    Ok((coord_ty, size_ty))
}

/// `Floor` of the GLSL.std.450 instruction set.
const GLSL_FLOOR: u32 = 8;

/// A constant one half of `ty` (a float, or a vector of floats), added to `added`.
fn half_of(
    globals: &HashMap<Word, Instruction>,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    ty: Word,
) -> Result<Word, SpirvError> {
    let t = globals
        .get(&ty)
        .ok_or_else(|| unsupported(format!("coordinate type %{ty} is not declared")))?;
    let (scalar, n) = match t.class.opcode {
        Op::TypeFloat => (ty, 1),
        Op::TypeVector => match (id_ref(t.operands.first()), t.operands.get(1)) {
            (Some(s), Some(Operand::LiteralBit32(n))) => (s, *n),
            _ => return Err(unsupported(format!("coordinate type %{ty} is malformed"))),
        },
        _ => return Err(unsupported(format!("coordinate type %{ty} is not a float"))),
    };
    let half = ids.fresh()?;
    added.push(inst(
        Op::Constant,
        Some(scalar),
        Some(half),
        vec![Operand::LiteralBit32(0.5f32.to_bits())],
    ));
    if n == 1 {
        return Ok(half);
    }
    let vector = ids.fresh()?;
    added.push(inst(
        Op::ConstantComposite,
        Some(ty),
        Some(vector),
        (0..n).map(|_| Operand::IdRef(half)).collect(),
    ));
    Ok(vector)
}
