//! Reading a module's interface: entry points, descriptor variables with their kinds, the
//! push-constant block's size, and capabilities. A layout for replaying the module through wgpu
//! is built from this, and `rewrite` uses the same descriptor list to find what it must split
//! and renumber, so both agree on what a binding is.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Decoration, Dim, ExecutionModel, Op, StorageClass, Word};

use super::index::{self, Index, MAX_TYPE_DEPTH, id_ref, literal};
use super::{EntryPoint, ImageInfo, Reflection, ResourceKind, ResourceVar, ScalarKind, SpirvError};

/// Reads the interface of a module (see [`Reflection`]).
pub fn reflect(words: &[u32]) -> Result<Reflection, SpirvError> {
    reflect_loaded(&index::load(words)?)
}

/// [`reflect`] of a module already loaded.
pub(super) fn reflect_loaded(loaded: &index::Loaded) -> Result<Reflection, SpirvError> {
    let index = Index::new(loaded);
    let module = &loaded.module;
    let mut entry_points = Vec::with_capacity(module.entry_points.len());
    for (n, inst) in module.entry_points.iter().enumerate() {
        let Some((model, _, name)) = entry_point_parts(inst) else {
            return Err(SpirvError::Malformed {
                at_word: loaded.entry_offsets.get(n).copied().unwrap_or(0),
                detail: "OpEntryPoint without model, function and name".to_owned(),
            });
        };
        entry_points.push(EntryPoint {
            model,
            name: name.to_owned(),
        });
    }
    let capabilities = module
        .capabilities
        .iter()
        .filter_map(|inst| match inst.operands.first() {
            Some(Operand::Capability(c)) => Some(*c),
            _ => None,
        })
        .collect();
    Ok(Reflection {
        entry_points,
        resources: resources(module, &index)?,
        push_constant_size: push_constant_size(module, &index)?,
        capabilities,
    })
}

/// An OpEntryPoint's execution model, function and name.
pub(super) fn entry_point_parts(inst: &Instruction) -> Option<(ExecutionModel, Word, &str)> {
    match inst.operands.get(..3)? {
        [
            Operand::ExecutionModel(model),
            Operand::IdRef(function),
            Operand::LiteralString(name),
        ] => Some((*model, *function, name.as_str())),
        _ => None,
    }
}

/// A result id; every instruction `Index` hands out has one.
fn rid(inst: &Instruction) -> Word {
    inst.result_id.unwrap_or(0)
}

/// Names a descriptor variable in errors.
pub(super) fn describe(set: u32, binding: u32, var: Word) -> String {
    format!("set {set} binding {binding} (%{var})")
}

/// Every global variable decorated with both DescriptorSet and Binding, sorted by (set, binding).
pub(super) fn resources(module: &Module, index: &Index) -> Result<Vec<ResourceVar>, SpirvError> {
    let mut out = Vec::new();
    let mut blocks = HashMap::new();
    for inst in &module.types_global_values {
        if inst.class.opcode != Op::Variable {
            continue;
        }
        let var = rid(inst);
        let (Some(set), Some(binding)) = (
            index.decoration_literal(var, Decoration::DescriptorSet),
            index.decoration_literal(var, Decoration::Binding),
        ) else {
            continue;
        };
        out.push(resource(index, &mut blocks, inst, set, binding)?);
    }
    out.sort_by_key(|r| (r.set, r.binding));
    Ok(out)
}

/// Whether every member of a block struct is NonWritable, and whether every one is
/// NonReadable, by struct id: many variables may share one block type.
type BlockAccess = HashMap<Word, (bool, bool)>;

fn resource(
    index: &Index,
    blocks: &mut BlockAccess,
    inst: &Instruction,
    set: u32,
    binding: u32,
) -> Result<ResourceVar, SpirvError> {
    let var = rid(inst);
    let what = describe(set, binding, var);
    let storage = match inst.operands.first() {
        Some(Operand::StorageClass(s)) => *s,
        _ => return Err(index.malformed(var, "OpVariable without a storage class".to_owned())),
    };
    let pointer = match inst.result_type {
        Some(ty) => index.def(ty, var)?,
        None => return Err(index.malformed(var, "OpVariable without a type".to_owned())),
    };
    if pointer.class.opcode != Op::TypePointer {
        return Err(index.malformed(var, "the type of a variable is not a pointer".to_owned()));
    }
    let mut ty = index.operand_def(pointer, 1, rid(pointer))?;
    let mut count = None;
    match ty.class.opcode {
        Op::TypeArray => {
            count = Some(array_length(index, ty, &what)?);
            ty = index.operand_def(ty, 0, rid(ty))?;
        }
        Op::TypeRuntimeArray => {
            count = Some(0);
            ty = index.operand_def(ty, 0, rid(ty))?;
        }
        _ => {}
    }
    if matches!(ty.class.opcode, Op::TypeArray | Op::TypeRuntimeArray) {
        return Err(SpirvError::Unsupported {
            feature: "array of arrays of descriptors",
            detail: what,
        });
    }
    let kind = match storage {
        StorageClass::Uniform => {
            let block = rid(ty);
            if ty.class.opcode != Op::TypeStruct {
                return Err(index.malformed(var, format!("{what} is a Uniform non-struct")));
            }
            if index.has_decoration(block, Decoration::BufferBlock) {
                ResourceKind::StorageBuffer
            } else if index.has_decoration(block, Decoration::Block) {
                ResourceKind::UniformBuffer
            } else {
                return Err(index.malformed(
                    var,
                    format!("{what} is a Uniform struct neither Block nor BufferBlock"),
                ));
            }
        }
        StorageClass::StorageBuffer => ResourceKind::StorageBuffer,
        StorageClass::UniformConstant => match ty.class.opcode {
            Op::TypeSampler => ResourceKind::Sampler { comparison: false },
            Op::TypeImage => image_kind(index, ty, var)?,
            Op::TypeSampledImage => {
                let image = index.operand_def(ty, 0, rid(ty))?;
                if image.class.opcode != Op::TypeImage {
                    return Err(
                        index.malformed(rid(ty), "OpTypeSampledImage of a non-image".to_owned())
                    );
                }
                let info = image_info(index, image)?;
                // GLSL's samplerBuffer: a sampled image over a buffer, bound as a uniform
                // texel buffer (no sampler).
                if info.dim == Dim::DimBuffer {
                    ResourceKind::UniformTexelBuffer
                } else {
                    ResourceKind::CombinedImageSampler(info)
                }
            }
            Op::TypeAccelerationStructureKHR => ResourceKind::AccelerationStructure,
            other => {
                return Err(SpirvError::Unsupported {
                    feature: "descriptor type",
                    detail: format!("{what} is a UniformConstant Op{other:?}"),
                });
            }
        },
        other => {
            return Err(SpirvError::Unsupported {
                feature: "descriptor storage class",
                detail: format!("{what} is in storage class {other:?}"),
            });
        }
    };
    let (members_non_writable, members_non_readable) = if ty.class.opcode == Op::TypeStruct {
        *blocks.entry(rid(ty)).or_insert_with(|| {
            let on_all = |d| {
                let members = ty.operands.len();
                members > 0
                    && (0..members).all(|m| {
                        u32::try_from(m)
                            .is_ok_and(|m| index.member_decoration(rid(ty), m, d).is_some())
                    })
            };
            (
                on_all(Decoration::NonWritable),
                on_all(Decoration::NonReadable),
            )
        })
    } else {
        (false, false)
    };
    // A block the sizer cannot lay out (a malformed matrix member) has no size here; the
    // bound range is then taken as it is.
    let block_size = matches!(
        kind,
        ResourceKind::UniformBuffer | ResourceKind::StorageBuffer
    )
    .then(|| {
        let mut sizer = Sizer {
            index,
            known: HashMap::new(),
        };
        sizer.size(ty, Layout::default(), 0).ok()
    })
    .flatten();
    Ok(ResourceVar {
        set,
        binding,
        count,
        kind,
        block_size,
        non_writable: members_non_writable || index.has_decoration(var, Decoration::NonWritable),
        non_readable: members_non_readable || index.has_decoration(var, Decoration::NonReadable),
        id: var,
        name: index.name(var).map(str::to_owned),
    })
}

/// The kind of a descriptor of image type `ty` held by `var`.
fn image_kind(index: &Index, ty: &Instruction, var: Word) -> Result<ResourceKind, SpirvError> {
    let info = image_info(index, ty)?;
    let sampled = literal(ty.operands.get(5));
    Ok(match (info.dim, sampled) {
        // Subpass inputs are Sampled = 2 yet read like textures; they are their own kind.
        (Dim::DimSubpassData, _) => ResourceKind::InputAttachment {
            index: index.decoration_literal(var, Decoration::InputAttachmentIndex),
        },
        (Dim::DimBuffer, Some(1)) => ResourceKind::UniformTexelBuffer,
        (Dim::DimBuffer, Some(2)) => ResourceKind::StorageTexelBuffer(info.format),
        (_, Some(1)) => ResourceKind::SampledImage(info),
        (_, Some(2)) => ResourceKind::StorageImage(info),
        _ => {
            return Err(SpirvError::Unsupported {
                feature: "image whose use is not known at compile time (Sampled 0)",
                detail: format!("%{var}"),
            });
        }
    })
}

/// The operands of an OpTypeImage.
pub(super) fn image_info(index: &Index, ty: &Instruction) -> Result<ImageInfo, SpirvError> {
    let id = rid(ty);
    let (
        Some(Operand::Dim(dim)),
        Some(depth),
        Some(arrayed),
        Some(ms),
        Some(Operand::ImageFormat(format)),
    ) = (
        ty.operands.get(1),
        literal(ty.operands.get(2)),
        literal(ty.operands.get(3)),
        literal(ty.operands.get(4)),
        ty.operands.get(6),
    )
    else {
        return Err(index.malformed(id, "OpTypeImage with missing operands".to_owned()));
    };
    let sampled = index.operand_def(ty, 0, id)?;
    let sampled_type = match (sampled.class.opcode, literal(sampled.operands.get(1))) {
        (Op::TypeFloat, _) => ScalarKind::Float,
        (Op::TypeInt, Some(1)) => ScalarKind::Sint,
        (Op::TypeInt, Some(0)) => ScalarKind::Uint,
        (other, _) => {
            return Err(SpirvError::Unsupported {
                feature: "image sampled type",
                detail: format!("%{id} is sampled as Op{other:?}"),
            });
        }
    };
    Ok(ImageInfo {
        dim: *dim,
        arrayed: arrayed == 1,
        multisampled: ms == 1,
        depth: match depth {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        },
        sampled_type,
        format: *format,
    })
}

/// The length of OpTypeArray `ty`. A specialization constant's value is only known when the
/// pipeline is created, so it is refused rather than guessed from its default.
fn array_length(index: &Index, ty: &Instruction, what: &str) -> Result<u32, SpirvError> {
    let id = rid(ty);
    let length = index.operand_def(ty, 1, id)?;
    let value = match (length.class.opcode, length.operands.first()) {
        (Op::Constant, Some(Operand::LiteralBit32(v))) => Some(u64::from(*v)),
        (Op::Constant, Some(Operand::LiteralBit64(v))) => Some(*v),
        (Op::SpecConstant | Op::SpecConstantOp, _) => {
            return Err(SpirvError::Unsupported {
                feature: "array length from a specialization constant",
                detail: format!("%{id} used by {what}"),
            });
        }
        _ => None,
    };
    value
        .and_then(|v| u32::try_from(v).ok())
        .ok_or_else(|| index.malformed(id, "array length is not a 32-bit constant".to_owned()))
}

/// The largest PushConstant block in the module. Each entry point has at most one; a module
/// with several entry points may have one each, and a layout for any of them fits the largest.
fn push_constant_size(module: &Module, index: &Index) -> Result<u32, SpirvError> {
    let mut sizer = Sizer {
        index,
        known: HashMap::new(),
    };
    let mut size = 0;
    for inst in &module.types_global_values {
        if inst.class.opcode != Op::Variable
            || inst.operands.first() != Some(&Operand::StorageClass(StorageClass::PushConstant))
        {
            continue;
        }
        let var = rid(inst);
        let Some(pointer) = inst.result_type.map(|ty| index.def(ty, var)).transpose()? else {
            return Err(index.malformed(var, "OpVariable without a type".to_owned()));
        };
        let block = index.operand_def(pointer, 1, rid(pointer))?;
        let bytes = sizer.size(block, Layout::default(), 0)?;
        let bytes = u32::try_from(bytes)
            .map_err(|_| index.malformed(var, format!("a push-constant block of {bytes} bytes")))?;
        size = size.max(bytes);
    }
    Ok(size)
}

/// How a struct member lays out matrices inside it (decorations on the member, which apply to
/// matrices nested in arrays too).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
struct Layout {
    matrix_stride: Option<u32>,
    row_major: bool,
}

/// Sizes types in explicitly laid-out blocks. Sizes are remembered: a struct of two copies of a
/// struct of two copies of... is small to write down and would take exponential time to walk.
struct Sizer<'i, 'm> {
    index: &'i Index<'m>,
    known: HashMap<(Word, Layout), u64>,
}

impl Sizer<'_, '_> {
    /// Bytes `ty` spans: for a struct, the furthest member end; for an array, stride times
    /// length; for a matrix, stride times its major count.
    fn size(&mut self, ty: &Instruction, layout: Layout, depth: usize) -> Result<u64, SpirvError> {
        let id = rid(ty);
        if let Some(size) = self.known.get(&(id, layout)) {
            return Ok(*size);
        }
        let index = self.index;
        if depth > MAX_TYPE_DEPTH {
            return Err(index.malformed(id, format!("types nest deeper than {MAX_TYPE_DEPTH}")));
        }
        let lit = |n| {
            literal(ty.operands.get(n))
                .map(u64::from)
                .ok_or_else(|| index.malformed(id, format!("operand {n} is not a literal")))
        };
        let size = match ty.class.opcode {
            Op::TypeInt | Op::TypeFloat => lit(0)? / 8,
            Op::TypeVector => {
                let component = index.operand_def(ty, 0, id)?;
                lit(1)?.saturating_mul(self.size(component, layout, depth + 1)?)
            }
            Op::TypeMatrix => {
                let Some(stride) = layout.matrix_stride else {
                    return Err(
                        index.malformed(id, "matrix in a block without MatrixStride".to_owned())
                    );
                };
                let columns = lit(1)?;
                let column = index.operand_def(ty, 0, id)?;
                let rows = literal(column.operands.get(1)).map(u64::from).unwrap_or(0);
                u64::from(stride).saturating_mul(if layout.row_major { rows } else { columns })
            }
            Op::TypeArray => {
                let Some(stride) = index.decoration_literal(id, Decoration::ArrayStride) else {
                    return Err(
                        index.malformed(id, "array in a block without ArrayStride".to_owned())
                    );
                };
                let length = array_length(index, ty, "a push-constant block")?;
                u64::from(stride).saturating_mul(u64::from(length))
            }
            // Only the fixed part of a block has a size.
            Op::TypeRuntimeArray => 0,
            Op::TypeStruct => {
                let mut end = 0;
                for (m, member) in ty.operands.iter().enumerate() {
                    let Ok(m) = u32::try_from(m) else { break };
                    let Some(member) = id_ref(Some(member)) else {
                        return Err(index.malformed(id, format!("member {m} is not an id")));
                    };
                    let decoration = |d| {
                        index
                            .member_decoration(id, m, d)
                            .and_then(|ops| literal(ops.first()))
                    };
                    let Some(offset) = decoration(Decoration::Offset) else {
                        return Err(index.malformed(id, format!("member {m} has no Offset")));
                    };
                    let inner = Layout {
                        matrix_stride: decoration(Decoration::MatrixStride),
                        row_major: index
                            .member_decoration(id, m, Decoration::RowMajor)
                            .is_some(),
                    };
                    let member = index.def(member, id)?;
                    let size = self.size(member, inner, depth + 1)?;
                    end = end.max(u64::from(offset).saturating_add(size));
                }
                end
            }
            // The only pointers a block may hold are buffer device addresses, 64-bit.
            Op::TypePointer => 8,
            other => {
                return Err(SpirvError::Unsupported {
                    feature: "type in a push-constant block",
                    detail: format!("%{id} is Op{other:?}"),
                });
            }
        };
        self.known.insert((id, layout), size);
        Ok(size)
    }
}
