//! Samplers that mirror once and then clamp (`VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE`,
//! OpenGL's `GL_MIRROR_CLAMP_TO_EDGE` through zink), in the shader: wgpu has no such address
//! mode. Mirroring once maps texel `i` of the mirrored side to texel `-1 - i`, which is where
//! the coordinate `-u` falls, so the texels a sample at `u` picks and weighs (nearest or linear)
//! are those a sample at `|u|` picks and weighs; past the far edge both clamp. Each sample
//! through such a sampler has the mirrored components of its coordinate replaced by their
//! absolute value (GLSL.std.450 `FAbs`), and the sampler clamps to the edge. Cube maps ignore
//! address modes and are left alone; an array layer is never mirrored. The level of detail an
//! implicit sample derives from the coordinate's derivatives keeps their magnitude.
//!
//! Runs on the module as captured, before the split renumbers bindings.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Dim, Op, Word};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::{Ids, inst};

fn unsupported(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "a sample through a sampler that mirrors once",
        detail,
    }
}

/// `FAbs` of the GLSL.std.450 instruction set.
const GLSL_FABS: u32 = 4;

/// The spatial dimensions of an image type (`None` for a cube map, which ignores address
/// modes).
fn spatial(dim: Option<&Operand>) -> Option<u32> {
    match dim {
        Some(Operand::Dim(Dim::Dim1D | Dim::DimBuffer)) => Some(1),
        Some(Operand::Dim(Dim::Dim2D | Dim::DimRect)) => Some(2),
        Some(Operand::Dim(Dim::Dim3D)) => Some(3),
        _ => None,
    }
}

/// Mirrors the coordinate components (`axes`: bit 0 `u`, 1 `v`, 2 `w`) of every sample taken
/// through the samplers at `at` ((set, binding, axes), combined or separate).
pub(super) fn mirror_coordinates(
    module: &mut Module,
    at: &[(u32, u32, u8)],
) -> Result<(), SpirvError> {
    if at.is_empty() {
        return Ok(());
    }
    let vars: HashMap<Word, u8> = super::carry::variables_at(module, |s, b| {
        at.iter()
            .find(|&&(set, binding, _)| (set, binding) == (s, b))
            .map(|&(_, _, axes)| axes)
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
    let mut glsl: Option<Word> = super::ops::glsl_import(module);
    let mut touched = false;
    let mut functions = std::mem::take(&mut module.functions);
    for f in &mut functions {
        for block in &mut f.blocks {
            let mut out = Vec::with_capacity(block.instructions.len());
            for mut s in std::mem::take(&mut block.instructions) {
                let axes = match id_ref(s.operands.first()).and_then(|x| root.get(&x)) {
                    Some(var) if super::ops::samples_through_sampler(s.class.opcode) => {
                        vars.get(var).copied().unwrap_or(0)
                    }
                    _ => 0,
                };
                if axes == 0 {
                    out.push(s);
                    continue;
                }
                let what = format!("%{} (Op{:?})", s.result_id.unwrap_or(0), s.class.opcode);
                let (Some(sampled), Some(coord)) =
                    (id_ref(s.operands.first()), id_ref(s.operands.get(1)))
                else {
                    return Err(unsupported(format!("{what} has no image or coordinate")));
                };
                // The image's spatial dimensions: components past them (an array layer, a
                // projective divisor) are never mirrored.
                let image_ty = types
                    .get(&sampled)
                    .and_then(|t| globals.get(t))
                    .filter(|t| t.class.opcode == Op::TypeSampledImage)
                    .and_then(|t| id_ref(t.operands.first()))
                    .and_then(|t| globals.get(&t))
                    .ok_or_else(|| unsupported(format!("{what}: not a sampled image")))?;
                let Some(dims) = spatial(image_ty.operands.get(1)) else {
                    out.push(s);
                    continue;
                };
                let mask = axes & ((1u8 << dims) - 1);
                let coord_ty = types
                    .get(&coord)
                    .copied()
                    .or_else(|| globals.get(&coord).and_then(|c| c.result_type))
                    .ok_or_else(|| unsupported(format!("{what}: untyped coordinate")))?;
                let n = match globals.get(&coord_ty) {
                    Some(t) if t.class.opcode == Op::TypeFloat => 1,
                    Some(t) if t.class.opcode == Op::TypeVector => match t.operands.get(1) {
                        Some(Operand::LiteralBit32(n)) => *n,
                        _ => return Err(unsupported(format!("{what}: malformed coordinate"))),
                    },
                    _ => {
                        return Err(unsupported(format!(
                            "{what}: the coordinate is not of floats"
                        )));
                    }
                };
                if mask == 0 {
                    out.push(s);
                    continue;
                }
                let set = match glsl {
                    Some(id) => id,
                    None => {
                        let id = ids.fresh()?;
                        glsl = Some(id);
                        id
                    }
                };
                let abs = ids.fresh()?;
                out.push(inst(
                    Op::ExtInst,
                    Some(coord_ty),
                    Some(abs),
                    vec![
                        Operand::IdRef(set),
                        Operand::LiteralExtInstInteger(GLSL_FABS),
                        Operand::IdRef(coord),
                    ],
                ));
                let all = (0..n).all(|i| i < 8 && mask & (1 << i) != 0);
                let mirrored = if n == 1 || all {
                    abs
                } else {
                    // Each component from the absolute value where mirrored, else as it was.
                    let picked = ids.fresh()?;
                    let mut operands = vec![Operand::IdRef(coord), Operand::IdRef(abs)];
                    operands.extend((0..n).map(|i| {
                        let from_abs = i < 8 && mask & (1 << i) != 0;
                        Operand::LiteralBit32(if from_abs { n + i } else { i })
                    }));
                    out.push(inst(
                        Op::VectorShuffle,
                        Some(coord_ty),
                        Some(picked),
                        operands,
                    ));
                    picked
                };
                s.operands[1] = Operand::IdRef(mirrored);
                out.push(s);
                touched = true;
            }
            block.instructions = out;
        }
    }
    module.functions = functions;
    if touched {
        super::ops::add_glsl_import(module, glsl);
    }
    Ok(())
}
