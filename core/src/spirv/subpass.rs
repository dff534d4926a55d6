//! Input attachments read as textures. wgpu binds no input attachment, and each Vulkan subpass
//! is replayed as a render pass of its own, so an attachment an earlier subpass wrote is, by
//! the time a later one reads it, an ordinary texture. A `subpassLoad` reads the attachment at
//! the fragment's own framebuffer position (plus a constant offset, which the specification
//! allows only as zero in core Vulkan): each `OpImageRead` of subpass data becomes an
//! `OpImageFetch` at `ivec2(gl_FragCoord.xy) + offset`, level 0 (or the sample asked, for
//! multisampled subpass data), and the image type becomes a sampled 2D image.
//!
//! An input attachment that the same subpass also renders to (framebuffer fetch) would be a
//! feedback loop in wgpu: the lowering points it at a copy of the attachment taken before the
//! draw (`lower::vulkan::feedback`), which this fetch then reads.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{
    BuiltIn, Capability, Decoration, Dim, ExecutionModel, ImageOperands, Op, StorageClass, Word,
};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::{Ids, float32, inst, int32, type_id, vector};

fn unsupported(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "an input attachment read",
        detail,
    }
}

/// Rewrites every subpass-data image of the module into a sampled 2D image read by fetches at
/// the fragment's coordinates; a module without one is left as it is.
pub(super) fn subpass_as_texture(module: &mut Module) -> Result<(), SpirvError> {
    let subpass_types: Vec<Word> = module
        .types_global_values
        .iter()
        .filter(|i| {
            i.class.opcode == Op::TypeImage
                && i.operands.get(1) == Some(&Operand::Dim(Dim::DimSubpassData))
        })
        .filter_map(|i| i.result_id)
        .collect();
    if subpass_types.is_empty() {
        return Ok(());
    }
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut added: Vec<Instruction> = Vec::new();
    let replaced = retyped(module, &subpass_types, &mut added, &mut ids)?;
    // The subpass variables and every value loaded from them.
    let vars: HashMap<Word, ()> = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::Variable)
        .filter(|i| i.result_type.is_some_and(|t| replaced.contains_key(&t)))
        .filter_map(|i| Some((i.result_id?, ())))
        .collect();
    let carried = super::carry::carried(module, &vars, 0);
    let fragcoord = frag_coord(module, &mut added, &mut ids)?;
    let int = int32(module, &mut added, &mut ids, true)?;
    let ivec2 = vector(module, &mut added, &mut ids, int, 2)?;
    let float = float32(module, &mut added, &mut ids)?;
    let vec2 = vector(module, &mut added, &mut ids, float, 2)?;
    let vec4 = vector(module, &mut added, &mut ids, float, 4)?;
    let zero = ids.fresh()?;
    added.push(inst(
        Op::Constant,
        Some(int),
        Some(zero),
        vec![Operand::LiteralBit32(0)],
    ));
    let fetch = FetchTypes {
        fragcoord,
        ivec2,
        vec2,
        vec4,
        zero,
    };
    let ms: HashMap<Word, bool> = subpass_types
        .iter()
        .map(|&t| {
            let multisampled = module
                .types_global_values
                .iter()
                .find(|i| i.result_id == Some(t))
                .is_some_and(|i| i.operands.get(4) == Some(&Operand::LiteralBit32(1)));
            (replaced[&t], multisampled)
        })
        .collect();
    let image_type_of = super::index::result_types(module);
    for f in &mut module.functions {
        for b in &mut f.blocks {
            let mut out = Vec::with_capacity(b.instructions.len());
            for mut i in std::mem::take(&mut b.instructions) {
                if let Some(t) = i.result_type
                    && let Some(&n) = replaced.get(&t)
                {
                    i.result_type = Some(n);
                }
                let image = id_ref(i.operands.first());
                let from_subpass = image.is_some_and(|x| carried.contains_key(&x));
                if !from_subpass {
                    out.push(i);
                    continue;
                }
                match i.class.opcode {
                    Op::Load | Op::CopyObject => {}
                    Op::ImageRead => {
                        let img = image.unwrap_or(0);
                        let multisampled = image_type_of
                            .get(&img)
                            .and_then(|t| replaced.get(t).or(Some(t)))
                            .and_then(|t| ms.get(t))
                            .copied()
                            .unwrap_or(false);
                        fetch_at_fragment(&i, img, multisampled, &fetch, &mut ids, &mut out)?;
                        continue;
                    }
                    op => {
                        return Err(unsupported(format!(
                            "subpass data %{} used by Op{op:?}",
                            image.unwrap_or(0)
                        )));
                    }
                }
                out.push(i);
            }
            b.instructions = out;
        }
    }
    // Variables move after the pointer types they now have.
    let mut moved = Vec::new();
    module.types_global_values.retain(|i| {
        if i.class.opcode == Op::Variable
            && i.result_type.is_some_and(|t| replaced.contains_key(&t))
        {
            moved.push(i.clone());
            false
        } else {
            true
        }
    });
    for mut v in moved {
        v.result_type = v.result_type.map(|t| replaced[&t]);
        added.push(v);
    }
    module
        .types_global_values
        .retain(|i| !i.result_id.is_some_and(|id| replaced.contains_key(&id)));
    module.types_global_values.extend(added);
    module.annotations.retain(|a| {
        !matches!(
            a.operands.get(1),
            Some(Operand::Decoration(Decoration::InputAttachmentIndex))
        )
    });
    module
        .capabilities
        .retain(|c| c.operands.first() != Some(&Operand::Capability(Capability::InputAttachment)));
    Ok(())
}

/// The subpass-data image types as sampled 2D images, and pointers to them, found or added:
/// old type -> new. Refused where a function takes one (it would need retyping too).
fn retyped(
    module: &Module,
    subpass_types: &[Word],
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
) -> Result<HashMap<Word, Word>, SpirvError> {
    // The same type as a sampled 2D image (Sampled 1, format Unknown); a type declared so
    // already is used in its place, since SPIR-V declares each non-aggregate type once.
    let mut replaced: HashMap<Word, Word> = HashMap::new();
    for &t in subpass_types {
        let old = module
            .types_global_values
            .iter()
            .find(|i| i.result_id == Some(t))
            .cloned()
            .ok_or_else(|| unsupported(format!("type %{t} is not global")))?;
        let mut operands = old.operands.clone();
        operands[1] = Operand::Dim(Dim::Dim2D);
        operands[5] = Operand::LiteralBit32(1);
        let new = type_id(module, added, ids, Op::TypeImage, operands)?;
        replaced.insert(t, new);
    }
    // Pointers to the old types become pointers to the new ones (found or added).
    let pointers: Vec<(Word, StorageClass, Word)> = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::TypePointer)
        .filter_map(|i| match i.operands.as_slice() {
            [Operand::StorageClass(c), Operand::IdRef(to)] if replaced.contains_key(to) => {
                Some((i.result_id?, *c, replaced[to]))
            }
            _ => None,
        })
        .collect();
    for (old, class, to) in pointers {
        let new = type_id(
            module,
            added,
            ids,
            Op::TypePointer,
            vec![Operand::StorageClass(class), Operand::IdRef(to)],
        )?;
        replaced.insert(old, new);
    }
    // A subpass image passed to a function would need the function retyped too.
    if let Some(f) = module.types_global_values.iter().find(|i| {
        i.class.opcode == Op::TypeFunction
            && i.operands
                .iter()
                .any(|o| matches!(o, Operand::IdRef(t) if replaced.contains_key(t)))
    }) {
        return Err(unsupported(format!(
            "subpass data passed to a function (%{})",
            f.result_id.unwrap_or(0)
        )));
    }
    Ok(replaced)
}

/// The types and ids a rewritten subpass read uses.
struct FetchTypes {
    fragcoord: Word,
    ivec2: Word,
    vec2: Word,
    vec4: Word,
    zero: Word,
}

/// `i`, an `OpImageRead` of subpass data `img`, as a fetch at the fragment's coordinates plus
/// the read's offset (its sample, where multisampled; level 0 where not).
fn fetch_at_fragment(
    i: &Instruction,
    img: Word,
    multisampled: bool,
    t: &FetchTypes,
    ids: &mut Ids,
    out: &mut Vec<Instruction>,
) -> Result<(), SpirvError> {
    let what = format!("%{}", i.result_id.unwrap_or(0));
    let offset = id_ref(i.operands.get(1))
        .ok_or_else(|| unsupported(format!("{what} has no coordinate")))?;
    let (coord, xy, pos, at) = (ids.fresh()?, ids.fresh()?, ids.fresh()?, ids.fresh()?);
    out.push(inst(
        Op::Load,
        Some(t.vec4),
        Some(coord),
        vec![Operand::IdRef(t.fragcoord)],
    ));
    out.push(inst(
        Op::VectorShuffle,
        Some(t.vec2),
        Some(xy),
        vec![
            Operand::IdRef(coord),
            Operand::IdRef(coord),
            Operand::LiteralBit32(0),
            Operand::LiteralBit32(1),
        ],
    ));
    out.push(inst(
        Op::ConvertFToS,
        Some(t.ivec2),
        Some(pos),
        vec![Operand::IdRef(xy)],
    ));
    out.push(inst(
        Op::IAdd,
        Some(t.ivec2),
        Some(at),
        vec![Operand::IdRef(pos), Operand::IdRef(offset)],
    ));
    // A multisampled read names its sample; a single-sampled one gets level 0.
    let rest: Vec<Operand> = if multisampled {
        match i.operands.get(2..) {
            Some([Operand::ImageOperands(o), Operand::IdRef(s)]) if *o == ImageOperands::SAMPLE => {
                vec![
                    Operand::ImageOperands(ImageOperands::SAMPLE),
                    Operand::IdRef(*s),
                ]
            }
            _ => {
                return Err(unsupported(format!(
                    "{what} reads multisampled subpass data without a sample"
                )));
            }
        }
    } else {
        if i.operands.len() > 2 {
            return Err(unsupported(format!(
                "{what} reads subpass data with image operands"
            )));
        }
        vec![
            Operand::ImageOperands(ImageOperands::LOD),
            Operand::IdRef(t.zero),
        ]
    };
    let mut operands = vec![Operand::IdRef(img), Operand::IdRef(at)];
    operands.extend(rest);
    out.push(inst(Op::ImageFetch, i.result_type, i.result_id, operands));
    Ok(())
}

/// The module's `gl_FragCoord` input, declared (and listed by every fragment entry point)
/// where it has none.
fn frag_coord(
    module: &mut Module,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
) -> Result<Word, SpirvError> {
    let existing = module
        .annotations
        .iter()
        .find_map(|a| match a.operands.as_slice() {
            [
                Operand::IdRef(v),
                Operand::Decoration(Decoration::BuiltIn),
                Operand::BuiltIn(BuiltIn::FragCoord),
            ] => Some(*v),
            _ => None,
        });
    if let Some(v) = existing {
        return Ok(v);
    }
    let float = float32(module, added, ids)?;
    let vec4 = vector(module, added, ids, float, 4)?;
    let ptr = type_id(
        module,
        added,
        ids,
        Op::TypePointer,
        vec![
            Operand::StorageClass(StorageClass::Input),
            Operand::IdRef(vec4),
        ],
    )?;
    let v = ids.fresh()?;
    added.push(inst(
        Op::Variable,
        Some(ptr),
        Some(v),
        vec![Operand::StorageClass(StorageClass::Input)],
    ));
    module.annotations.push(inst(
        Op::Decorate,
        None,
        None,
        vec![
            Operand::IdRef(v),
            Operand::Decoration(Decoration::BuiltIn),
            Operand::BuiltIn(BuiltIn::FragCoord),
        ],
    ));
    for e in &mut module.entry_points {
        if e.operands.first() == Some(&Operand::ExecutionModel(ExecutionModel::Fragment)) {
            e.operands.push(Operand::IdRef(v));
        }
    }
    Ok(v)
}
