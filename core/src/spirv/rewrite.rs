//! Reshaping a captured module to the layout wgpu will bind it with. wgpu has no combined image
//! sampler binding, so each one becomes a separate image and sampler variable, loaded where the
//! combined one was and joined again with OpSampledImage; every other descriptor keeps its
//! variable under a new binding number; and the final position's y is negated because wgpu's
//! Vulkan backend flips the viewport to make clip-space y point up.
//!
//! The whole module is planned against an immutable index first (everything that can be refused
//! is refused there), then edited in place; new ids come from past the highest one in use.

use std::collections::HashMap;

use rspirv::binary::Assemble;
use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{BuiltIn, Decoration, ExecutionModel, Op, StorageClass, Word};

use super::index::{self, Index, Loaded, id_ref, literal};
use super::ops::{Ids, inst, type_id};
use super::reflect::{describe, entry_point_parts, resources};
use super::texel::{Texel, texel_layout};
use super::{ResourceKind, RewriteOptions, Role, SpirvError};

/// Rewrites the module for the entry point `entry` of execution model `model` and returns the
/// new words. Binding changes apply to the whole module; the y flip to that entry point only.
pub fn rewrite(
    words: &[u32],
    model: ExecutionModel,
    entry: &str,
    opts: &RewriteOptions,
) -> Result<Vec<u32>, SpirvError> {
    let mut loaded = index::load(words)?;
    super::entry::keep_entry(&mut loaded.module, model, entry);
    let combined = super::params::combined_vars(&loaded.module);
    if !combined.is_empty() {
        super::params::inline_sampler_params(&mut loaded.module, &combined)?;
    }
    super::subpass::subpass_as_texture(&mut loaded.module)?;
    super::bias::add_lod_bias(&mut loaded.module, opts.lod_bias)?;
    super::unnormalized::normalize_coordinates(&mut loaded.module, opts.unnormalized)?;
    super::mirror_once::mirror_coordinates(&mut loaded.module, opts.mirror_once)?;
    if model == ExecutionModel::Vertex {
        super::scaled::scaled_inputs(&mut loaded.module, opts.scaled_inputs)?;
    }
    super::swizzle::apply_swizzles(&mut loaded.module, opts.swizzles)?;
    super::demote::demote_as_kill(&mut loaded.module)?;
    super::memory_model::as_glsl450(&mut loaded.module)?;
    super::std140::widen_uniform_blocks(&mut loaded, opts.std140_blocks)?;
    super::storage::uniform_as_storage(&mut loaded.module, opts.storage_blocks)?;
    super::outputs::layer_outputs_private(&mut loaded.module)?;
    if let Some(attached) = opts.attached_outputs {
        super::outputs::unattached_private(&mut loaded.module, model, attached)?;
    }
    super::unused::drop_unbound(&mut loaded.module, |set, binding| {
        [Role::Whole, Role::SplitImage]
            .into_iter()
            .any(|role| (opts.binding)(set, binding, role).is_some())
    });
    super::indexing::drop_needless_dynamic_indexing(&mut loaded.module);
    let plan = plan(&loaded, model, entry, opts)?;
    let mut module = loaded.module;
    apply(&mut module, plan)?;
    specialize(&mut module, opts.specialization);
    // The source language is only information; one newer than the driver's own tools know
    // (naga writes WGSL's, 10) makes older validation layers call the module invalid.
    module.debug_string_source.retain(|i| {
        !matches!(
            i.class.opcode,
            rspirv::spirv::Op::Source
                | rspirv::spirv::Op::SourceContinued
                | rspirv::spirv::Op::SourceExtension
        )
    });
    Ok(module.assemble())
}

/// Everything `apply` needs, decided before anything is edited.
struct Plan {
    /// The first id not in use.
    next_id: Word,
    /// Variables that keep their descriptor, with their new binding.
    renumber: HashMap<Word, u32>,
    splits: Vec<Split>,
    /// Storage texel buffers read as storage buffers of words.
    texels: Vec<Texel>,
    flip: Option<Flip>,
}

/// A combined image sampler to split.
struct Split {
    var: Word,
    set: u32,
    /// The binding it had, for errors.
    binding: u32,
    image_binding: u32,
    sampler_binding: u32,
    sampled_image_ty: Word,
    image_ty: Word,
    name: Option<String>,
}

/// Where gl_Position is and where its y is negated.
struct Flip {
    var: Word,
    /// The member of the gl_PerVertex block, or None for a variable that is the position.
    member: Option<u32>,
    vec4: Word,
    float: Word,
    /// Negate before each OpReturn of this function, or (None, geometry shaders) before each
    /// vertex is emitted: the outputs are undefined after an emit, so each emit gets its own.
    returns_of: Option<Word>,
    /// Negate y (`RewriteOptions::flip_y`).
    negate_y: bool,
    /// Map OpenGL's depth, -w to w, to Vulkan's 0 to w (`RewriteOptions::gl_depth`).
    gl_depth: bool,
}

fn plan(
    loaded: &Loaded,
    model: ExecutionModel,
    entry: &str,
    opts: &RewriteOptions,
) -> Result<Plan, SpirvError> {
    let module = &loaded.module;
    let index = Index::new(loaded);
    let not_found = || SpirvError::EntryPointNotFound {
        model,
        name: entry.to_owned(),
    };
    let (entry_inst, function) = module
        .entry_points
        .iter()
        .find_map(|inst| {
            let (m, function, name) = entry_point_parts(inst)?;
            (m == model && name == entry).then_some((inst, function))
        })
        .ok_or_else(not_found)?;

    let mut renumber = HashMap::new();
    let mut splits = Vec::new();
    let mut texels = Vec::new();
    for r in resources(module, &index)? {
        let what = describe(r.set, r.binding, r.id);
        if index.is_grouped(r.id) {
            return Err(SpirvError::Unsupported {
                feature: "descriptor decorated through a decoration group",
                detail: what,
            });
        }
        let new_binding = |role| {
            (opts.binding)(r.set, r.binding, role).ok_or(SpirvError::BindingNotInLayout {
                set: r.set,
                binding: r.binding,
                role,
            })
        };
        // A texel buffer is rewritten where it is only read, in a format the rewrite unpacks
        // (a storage one states it, a uniform one's comes from its buffer view); it is left as
        // it is otherwise, which the caller sees by reflecting the result.
        let texel_format = match r.kind {
            ResourceKind::StorageTexelBuffer(format) => Some(Some(format)),
            ResourceKind::UniformTexelBuffer => Some(
                opts.texel_formats
                    .iter()
                    .find(|(s, b, _)| (*s, *b) == (r.set, r.binding))
                    .map(|t| t.2),
            ),
            _ => None,
        };
        if let Some(format) = texel_format {
            if let Some(format) = format.filter(|&f| {
                r.count.is_none() && texel_layout(f).is_some() && only_read(module, r.id)
            }) {
                texels.push(Texel {
                    var: r.id,
                    format,
                    set: r.set,
                    binding: r.binding,
                });
            }
            renumber.insert(r.id, new_binding(Role::Whole)?);
            continue;
        }
        match r.kind {
            ResourceKind::CombinedImageSampler(_) => {}
            _ => {
                renumber.insert(r.id, new_binding(Role::Whole)?);
                continue;
            }
        }
        if r.count.is_some() {
            return Err(SpirvError::Unsupported {
                feature: "array of combined image samplers",
                detail: what,
            });
        }
        // `resources` has checked the chain variable -> pointer -> sampled image -> image.
        let sampled_image_ty = index
            .globals
            .get(&r.id)
            .and_then(|var| var.result_type)
            .and_then(|ptr| index.globals.get(&ptr))
            .and_then(|ptr| id_ref(ptr.operands.get(1)));
        let image_ty = sampled_image_ty
            .and_then(|ty| index.globals.get(&ty))
            .and_then(|ty| id_ref(ty.operands.first()));
        let (Some(sampled_image_ty), Some(image_ty)) = (sampled_image_ty, image_ty) else {
            return Err(index.malformed(r.id, format!("{what}: no sampled image type")));
        };
        splits.push(Split {
            var: r.id,
            set: r.set,
            binding: r.binding,
            image_binding: new_binding(Role::SplitImage)?,
            sampler_binding: new_binding(Role::SplitSampler)?,
            sampled_image_ty,
            image_ty,
            name: r.name.clone(),
        });
    }
    check_uses(module, &index, &splits)?;

    let flips = matches!(
        model,
        ExecutionModel::Vertex | ExecutionModel::TessellationEvaluation | ExecutionModel::Geometry
    );
    let flip = if (opts.flip_y || opts.gl_depth) && flips {
        let returns_of = (model != ExecutionModel::Geometry).then_some(function);
        find_position(&index, entry_inst, returns_of)?.map(|f| Flip {
            negate_y: opts.flip_y,
            gl_depth: opts.gl_depth,
            ..f
        })
    } else {
        None
    };
    if let Some(Flip {
        returns_of: Some(f),
        ..
    }) = flip
        && !module.functions.iter().any(|func| func.def_id() == Some(f))
    {
        return Err(SpirvError::Malformed {
            at_word: index.offset(f),
            detail: format!("entry point {entry:?} names %{f}, which is not a function"),
        });
    }

    let next_id =
        index::first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?;
    Ok(Plan {
        next_id,
        renumber,
        splits,
        texels,
        flip,
    })
}

/// Refuses any use of a combined image sampler variable the split cannot follow: only loading
/// it whole is rewritten; naming, decorating and listing it in an interface are updated.
fn check_uses(module: &Module, index: &Index, splits: &[Split]) -> Result<(), SpirvError> {
    let by_var: HashMap<Word, &Split> = splits.iter().map(|s| (s.var, s)).collect();
    let uses = |inst: &Instruction| {
        inst.operands
            .iter()
            .enumerate()
            .filter_map(|(n, op)| Some((n, *by_var.get(&id_ref(Some(op))?)?)))
            .collect::<Vec<_>>()
    };
    let unsupported = |opcode: Op, split: &Split| SpirvError::Unsupported {
        feature: "use of a combined image sampler other than loading it",
        detail: format!(
            "{} is used by Op{opcode:?}",
            describe(split.set, split.binding, split.var)
        ),
    };
    for inst in module.global_inst_iter() {
        for (n, split) in uses(inst) {
            let handled = match inst.class.opcode {
                Op::Name | Op::Decorate => n == 0,
                Op::EntryPoint => n >= 3,
                _ => false,
            };
            if !handled {
                return Err(unsupported(inst.class.opcode, split));
            }
        }
    }
    for inst in module.functions.iter().flat_map(|f| f.all_inst_iter()) {
        for (n, split) in uses(inst) {
            if inst.class.opcode != Op::Load || n != 0 {
                return Err(unsupported(inst.class.opcode, split));
            }
            if inst.result_type != Some(split.sampled_image_ty) {
                return Err(SpirvError::Malformed {
                    at_word: inst.result_id.map_or(0, |id| index.offset(id)),
                    detail: format!(
                        "a load of {} has a type other than the variable's",
                        describe(split.set, split.binding, split.var)
                    ),
                });
            }
        }
    }
    Ok(())
}

/// The entry point's gl_Position output, if it has one.
fn find_position(
    index: &Index,
    entry: &Instruction,
    returns_of: Option<Word>,
) -> Result<Option<Flip>, SpirvError> {
    let is_position =
        |ops: Option<&[Operand]>| matches!(ops, Some([Operand::BuiltIn(BuiltIn::Position), ..]));
    for id in entry
        .operands
        .iter()
        .skip(3)
        .filter_map(|op| id_ref(Some(op)))
    {
        let Some(var) = index.globals.get(&id) else {
            continue;
        };
        if var.class.opcode != Op::Variable
            || var.operands.first() != Some(&Operand::StorageClass(StorageClass::Output))
        {
            continue;
        }
        let Some(pointer) = var.result_type.map(|ty| index.def(ty, id)).transpose()? else {
            continue;
        };
        let pointee = index.operand_def(pointer, 1, id)?;
        let pointee_id = pointee.result_id.unwrap_or(0);
        let (member, vec4) = if is_position(index.decoration(id, Decoration::BuiltIn)) {
            (None, pointee)
        } else if pointee.class.opcode == Op::TypeStruct {
            let member = (0..pointee.operands.len()).find_map(|m| {
                let m = u32::try_from(m).ok()?;
                is_position(index.member_decoration(pointee_id, m, Decoration::BuiltIn))
                    .then_some(m)
            });
            let Some(m) = member else { continue };
            let ty = index.operand_def(pointee, m as usize, pointee_id)?;
            (Some(m), ty)
        } else {
            continue;
        };
        let vec4_id = vec4.result_id.unwrap_or(0);
        let float = (vec4.class.opcode == Op::TypeVector
            && literal(vec4.operands.get(1)) == Some(4))
        .then(|| index.operand_def(vec4, 0, vec4_id))
        .transpose()?
        .filter(|f| f.class.opcode == Op::TypeFloat && literal(f.operands.first()) == Some(32))
        .and_then(|f| f.result_id);
        let Some(float) = float else {
            return Err(SpirvError::Unsupported {
                feature: "gl_Position that is not a vec4 of 32-bit floats",
                detail: format!("%{id}"),
            });
        };
        return Ok(Some(Flip {
            var: id,
            member,
            vec4: vec4_id,
            float,
            returns_of,
            negate_y: true,
            gl_depth: false,
        }));
    }
    Ok(None)
}

/// Whether every use of variable `var` in the functions is a load whose image only
/// `OpImageRead` (storage) or `OpImageFetch` (uniform texel buffers) takes.
fn only_read(module: &Module, var: Word) -> bool {
    let mut loaded = std::collections::HashSet::new();
    let insts = || module.functions.iter().flat_map(|f| f.all_inst_iter());
    for i in insts() {
        if i.operands.iter().any(|o| id_ref(Some(o)) == Some(var)) {
            if i.class.opcode != Op::Load {
                return false;
            }
            loaded.extend(i.result_id);
        }
    }
    // A samplerBuffer's loaded value reaches its fetches through OpImage.
    for i in insts() {
        if i.class.opcode == Op::Image
            && id_ref(i.operands.first()).is_some_and(|x| loaded.contains(&x))
        {
            loaded.extend(i.result_id);
        }
    }
    insts().all(|i| {
        i.operands.iter().enumerate().all(|(n, o)| {
            id_ref(Some(o)).is_none_or(|id| !loaded.contains(&id))
                || (matches!(i.class.opcode, Op::ImageRead | Op::ImageFetch | Op::Image) && n == 0)
        })
    })
}

/// The ids one split produced.
struct SplitIds {
    sampled_image_ty: Word,
    image_ty: Word,
    image_var: Word,
    sampler_ty: Word,
    sampler_var: Word,
}

fn apply(module: &mut Module, plan: Plan) -> Result<(), SpirvError> {
    let mut ids = Ids { next: plan.next_id };

    for inst in &mut module.annotations {
        if inst.class.opcode != Op::Decorate {
            continue;
        }
        if let [
            Operand::IdRef(target),
            Operand::Decoration(Decoration::Binding),
            Operand::LiteralBit32(binding),
        ] = inst.operands.as_mut_slice()
            && let Some(new) = plan.renumber.get(target)
        {
            *binding = *new;
        }
    }

    if !plan.splits.is_empty() {
        split(module, &plan.splits, &mut ids)?;
    }
    if !plan.texels.is_empty() {
        super::texel::texel_buffers(module, &plan.texels, &mut ids)?;
    }
    if let Some(flip) = &plan.flip {
        flip_y(module, flip, &mut ids)?;
    }

    if let Some(header) = module.header.as_mut() {
        header.bound = ids.next;
    }
    Ok(())
}

fn split(module: &mut Module, splits: &[Split], ids: &mut Ids) -> Result<(), SpirvError> {
    let mut added = Vec::new();
    let mut decorations = Vec::new();
    let mut names = Vec::new();
    let sampler_ty = type_id(module, &mut added, ids, Op::TypeSampler, vec![])?;
    let uniform_constant = Operand::StorageClass(StorageClass::UniformConstant);
    let sampler_ptr = type_id(
        module,
        &mut added,
        ids,
        Op::TypePointer,
        vec![uniform_constant.clone(), Operand::IdRef(sampler_ty)],
    )?;
    // Looked up once rather than searched for each split: a module may hold many.
    let mut image_ptrs: HashMap<Word, Word> = HashMap::new();
    for i in &module.types_global_values {
        if let (Op::TypePointer, Some(ptr), [storage, Operand::IdRef(pointee)]) =
            (i.class.opcode, i.result_id, i.operands.as_slice())
            && *storage == uniform_constant
        {
            image_ptrs.entry(*pointee).or_insert(ptr);
        }
    }
    let mut made: HashMap<Word, SplitIds> = HashMap::new();
    for s in splits {
        let image_ptr = match image_ptrs.get(&s.image_ty) {
            Some(ptr) => *ptr,
            None => {
                let ptr = ids.fresh()?;
                added.push(inst(
                    Op::TypePointer,
                    None,
                    Some(ptr),
                    vec![uniform_constant.clone(), Operand::IdRef(s.image_ty)],
                ));
                image_ptrs.insert(s.image_ty, ptr);
                ptr
            }
        };
        let image_var = ids.fresh()?;
        let sampler_var = ids.fresh()?;
        for (var, ptr, binding, suffix) in [
            (image_var, image_ptr, s.image_binding, "image"),
            (sampler_var, sampler_ptr, s.sampler_binding, "sampler"),
        ] {
            added.push(inst(
                Op::Variable,
                Some(ptr),
                Some(var),
                vec![uniform_constant.clone()],
            ));
            for (d, value) in [
                (Decoration::DescriptorSet, s.set),
                (Decoration::Binding, binding),
            ] {
                decorations.push(inst(
                    Op::Decorate,
                    None,
                    None,
                    vec![
                        Operand::IdRef(var),
                        Operand::Decoration(d),
                        Operand::LiteralBit32(value),
                    ],
                ));
            }
            if let Some(name) = &s.name {
                names.push(super::ops::name(var, format!("{name}_{suffix}")));
            }
        }
        made.insert(
            s.var,
            SplitIds {
                sampled_image_ty: s.sampled_image_ty,
                image_ty: s.image_ty,
                image_var,
                sampler_ty,
                sampler_var,
            },
        );
    }

    let is_split = |op: Option<&Operand>| id_ref(op).is_some_and(|id| made.contains_key(&id));
    module.types_global_values.retain(|i| {
        !(i.class.opcode == Op::Variable && i.result_id.is_some_and(|id| made.contains_key(&id)))
    });
    module.types_global_values.extend(added);
    module
        .annotations
        .retain(|i| !(i.class.opcode == Op::Decorate && is_split(i.operands.first())));
    module.annotations.extend(decorations);
    module
        .debug_names
        .retain(|i| !(i.class.opcode == Op::Name && is_split(i.operands.first())));
    module.debug_names.extend(names);

    // SPIR-V 1.4 and later list every global an entry point uses.
    for entry in &mut module.entry_points {
        if !entry.operands.iter().skip(3).any(|op| is_split(Some(op))) {
            continue;
        }
        let mut operands = Vec::with_capacity(entry.operands.len() + splits.len());
        for (n, op) in entry.operands.drain(..).enumerate() {
            match id_ref(Some(&op)).and_then(|id| made.get(&id)) {
                Some(m) if n >= 3 => {
                    operands.push(Operand::IdRef(m.image_var));
                    operands.push(Operand::IdRef(m.sampler_var));
                }
                _ => operands.push(op),
            }
        }
        entry.operands = operands;
        if entry.assemble().len() > usize::from(u16::MAX) {
            return Err(SpirvError::Unsupported {
                feature: "interface list longer than one instruction can hold",
                detail: format!("{} words", entry.assemble().len()),
            });
        }
    }

    for function in &mut module.functions {
        split_loads(function, &made, ids)?;
    }
    Ok(())
}

/// Replaces `%r = OpLoad %sampledImage %combined` with loads of the image and the sampler and
/// `%r = OpSampledImage`. A sampled image may only be consumed in the block that made it, so a
/// block using %r elsewhere gets its own OpSampledImage from the same loads.
fn split_loads(
    function: &mut rspirv::dr::Function,
    made: &HashMap<Word, SplitIds>,
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    // %r -> (sampled image type, image, sampler, block that defines %r)
    let mut joined: HashMap<Word, (Word, Word, Word, usize)> = HashMap::new();
    for (b, block) in function.blocks.iter_mut().enumerate() {
        let old = std::mem::take(&mut block.instructions);
        let mut out = Vec::with_capacity(old.len());
        for i in old {
            let target = (i.class.opcode == Op::Load)
                .then(|| id_ref(i.operands.first()))
                .flatten()
                .and_then(|var| made.get(&var));
            let (Some(m), Some(r)) = (target, i.result_id) else {
                out.push(i);
                continue;
            };
            let memory = i.operands.get(1..).unwrap_or_default().to_vec();
            let image = ids.fresh()?;
            let sampler = ids.fresh()?;
            let load = |ty, id, var| {
                let mut operands = vec![Operand::IdRef(var)];
                operands.extend(memory.iter().cloned());
                inst(Op::Load, Some(ty), Some(id), operands)
            };
            out.push(load(m.image_ty, image, m.image_var));
            out.push(load(m.sampler_ty, sampler, m.sampler_var));
            out.push(inst(
                Op::SampledImage,
                Some(m.sampled_image_ty),
                Some(r),
                vec![Operand::IdRef(image), Operand::IdRef(sampler)],
            ));
            joined.insert(r, (m.sampled_image_ty, image, sampler, b));
        }
        block.instructions = out;
    }
    if joined.is_empty() {
        return Ok(());
    }
    for (b, block) in function.blocks.iter_mut().enumerate() {
        let mut local: HashMap<Word, Word> = HashMap::new();
        let old = std::mem::take(&mut block.instructions);
        let mut out = Vec::with_capacity(old.len());
        for mut i in old {
            for op in &mut i.operands {
                let Operand::IdRef(id) = op else { continue };
                let Some(&(ty, image, sampler, home)) = joined.get(id) else {
                    continue;
                };
                if home == b {
                    continue;
                }
                if i.class.opcode == Op::Phi {
                    return Err(SpirvError::Unsupported {
                        feature: "combined image sampler merged by OpPhi",
                        detail: format!("%{id}"),
                    });
                }
                let here = match local.get(id) {
                    Some(here) => *here,
                    None => {
                        let here = ids.fresh()?;
                        out.push(inst(
                            Op::SampledImage,
                            Some(ty),
                            Some(here),
                            vec![Operand::IdRef(image), Operand::IdRef(sampler)],
                        ));
                        local.insert(*id, here);
                        here
                    }
                };
                *op = Operand::IdRef(here);
            }
            out.push(i);
        }
        block.instructions = out;
    }
    Ok(())
}

fn flip_y(module: &mut Module, flip: &Flip, ids: &mut Ids) -> Result<(), SpirvError> {
    let mut added = Vec::new();
    let chain = match flip.member {
        Some(member) => {
            let pointer = type_id(
                module,
                &mut added,
                ids,
                Op::TypePointer,
                vec![
                    Operand::StorageClass(StorageClass::Output),
                    Operand::IdRef(flip.vec4),
                ],
            )?;
            Some((pointer, int_constant(module, &mut added, ids, member)?))
        }
        None => None,
    };
    let half = if flip.gl_depth {
        let c = ids.fresh()?;
        added.push(inst(
            Op::Constant,
            Some(flip.float),
            Some(c),
            vec![Operand::LiteralBit32(0.5f32.to_bits())],
        ));
        Some(c)
    } else {
        None
    };
    module.types_global_values.extend(added);

    for function in &mut module.functions {
        if flip
            .returns_of
            .is_some_and(|f| function.def_id() != Some(f))
        {
            continue;
        }
        for block in &mut function.blocks {
            let old = std::mem::take(&mut block.instructions);
            let mut out = Vec::with_capacity(old.len());
            for i in old {
                let here = match flip.returns_of {
                    Some(_) => i.class.opcode == Op::Return,
                    None => matches!(i.class.opcode, Op::EmitVertex | Op::EmitStreamVertex),
                };
                if here {
                    negate_y(&mut out, flip, chain, half, ids)?;
                }
                out.push(i);
            }
            block.instructions = out;
        }
    }
    Ok(())
}

/// Appends: pointer to gl_Position, load, extract y, negate, insert; with `half` (the
/// constant 0.5), extract z and w, z = (z + w) * 0.5, insert; store.
fn negate_y(
    out: &mut Vec<Instruction>,
    flip: &Flip,
    chain: Option<(Word, Word)>,
    half: Option<Word>,
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    let position = match chain {
        Some((pointer, member)) => {
            let p = ids.fresh()?;
            out.push(inst(
                Op::AccessChain,
                Some(pointer),
                Some(p),
                vec![Operand::IdRef(flip.var), Operand::IdRef(member)],
            ));
            p
        }
        None => flip.var,
    };
    let mut value = ids.fresh()?;
    out.push(inst(
        Op::Load,
        Some(flip.vec4),
        Some(value),
        vec![Operand::IdRef(position)],
    ));
    let extract = |out: &mut Vec<Instruction>, from: Word, c: u32, ids: &mut Ids| {
        let id = ids.fresh()?;
        out.push(inst(
            Op::CompositeExtract,
            Some(flip.float),
            Some(id),
            vec![Operand::IdRef(from), Operand::LiteralBit32(c)],
        ));
        Ok::<Word, SpirvError>(id)
    };
    let insert = |out: &mut Vec<Instruction>, into: Word, c: u32, part: Word, ids: &mut Ids| {
        let id = ids.fresh()?;
        out.push(inst(
            Op::CompositeInsert,
            Some(flip.vec4),
            Some(id),
            vec![
                Operand::IdRef(part),
                Operand::IdRef(into),
                Operand::LiteralBit32(c),
            ],
        ));
        Ok::<Word, SpirvError>(id)
    };
    let binary = |out: &mut Vec<Instruction>, op: Op, a: Word, b: Word, ids: &mut Ids| {
        let id = ids.fresh()?;
        out.push(inst(
            op,
            Some(flip.float),
            Some(id),
            vec![Operand::IdRef(a), Operand::IdRef(b)],
        ));
        Ok::<Word, SpirvError>(id)
    };
    if flip.negate_y {
        let y = extract(out, value, 1, ids)?;
        let negated = ids.fresh()?;
        out.push(inst(
            Op::FNegate,
            Some(flip.float),
            Some(negated),
            vec![Operand::IdRef(y)],
        ));
        value = insert(out, value, 1, negated, ids)?;
    }
    if let Some(half) = half {
        let z = extract(out, value, 2, ids)?;
        let w = extract(out, value, 3, ids)?;
        let sum = binary(out, Op::FAdd, z, w, ids)?;
        let mapped = binary(out, Op::FMul, sum, half, ids)?;
        value = insert(out, value, 2, mapped, ids)?;
    }
    out.push(inst(
        Op::Store,
        None,
        None,
        vec![Operand::IdRef(position), Operand::IdRef(value)],
    ));
    Ok(())
}

/// A 32-bit integer constant `value`: an existing one of either signedness, or a new one (with a
/// new `OpTypeInt 32 0` when the module has no 32-bit integer type).
fn int_constant(
    module: &Module,
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
    value: u32,
) -> Result<Word, SpirvError> {
    let int32 = super::ops::int32_types(module);
    let existing = module.types_global_values.iter().find(|i| {
        i.class.opcode == Op::Constant
            && i.result_type.is_some_and(|ty| int32.contains(&ty))
            && i.operands.first() == Some(&Operand::LiteralBit32(value))
    });
    if let Some(id) = existing.and_then(|i| i.result_id) {
        return Ok(id);
    }
    let ty = match int32.first() {
        Some(ty) => *ty,
        None => type_id(
            module,
            added,
            ids,
            Op::TypeInt,
            vec![Operand::LiteralBit32(32), Operand::LiteralBit32(0)],
        )?,
    };
    let id = ids.fresh()?;
    added.push(inst(
        Op::Constant,
        Some(ty),
        Some(id),
        vec![Operand::LiteralBit32(value)],
    ));
    Ok(id)
}

/// Turns each specialization constant the pipeline gave a value for into a plain constant of
/// that value, and drops its SpecId. Booleans take any non-zero value as true; numbers keep
/// their width (the value's low 32 bits for 32-bit constants).
fn specialize(module: &mut Module, values: &[(u32, u64)]) {
    if values.is_empty() {
        return;
    }
    let mut by_target: HashMap<Word, u64> = HashMap::new();
    module.annotations.retain(|a| {
        let spec = a.class.opcode == Op::Decorate
            && a.operands.get(1) == Some(&Operand::Decoration(Decoration::SpecId));
        let given = spec
            .then(|| {
                let target = id_ref(a.operands.first())?;
                let id = literal(a.operands.get(2))?;
                let value = values.iter().find(|(s, _)| *s == id)?.1;
                Some((target, value))
            })
            .flatten();
        match given {
            Some((target, value)) => {
                by_target.insert(target, value);
                false
            }
            None => true,
        }
    });
    for c in &mut module.types_global_values {
        let Some(&value) = c.result_id.and_then(|id| by_target.get(&id)) else {
            continue;
        };
        match c.class.opcode {
            Op::SpecConstantTrue | Op::SpecConstantFalse => {
                let op = if value != 0 {
                    Op::ConstantTrue
                } else {
                    Op::ConstantFalse
                };
                *c = inst(op, c.result_type, c.result_id, Vec::new());
            }
            Op::SpecConstant => {
                let operand = match c.operands.first() {
                    Some(Operand::LiteralBit64(_)) => Operand::LiteralBit64(value),
                    _ => Operand::LiteralBit32(value as u32),
                };
                *c = inst(Op::Constant, c.result_type, c.result_id, vec![operand]);
            }
            _ => {}
        }
    }
}
