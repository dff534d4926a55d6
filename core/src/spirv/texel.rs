//! Texel buffers for wgpu, which binds none: each becomes a read-only storage buffer
//! of 32-bit words (a struct holding a runtime array, `Block`), and each `OpImageRead` (storage) or `OpImageFetch` (uniform, in the buffer view's format) of it
//! loads the word holding its texel and unpacks it as the format says (unorm bytes scaled to
//! 0..1, integers as they are), missing channels filled as Vulkan fills them (0, 0, 1). The
//! variable keeps its id, set and binding, and moves after the new types. Only reads are
//! rewritten: a write, a size query or any other use is refused.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Decoration, ImageFormat, Op, StorageClass, Word};

use super::index::id_ref;
use super::ops::{Ids, constant, inst, type_id};
use super::{ScalarKind, SpirvError};

/// A storage texel buffer wgpu has no binding for: it becomes a storage buffer of 32-bit
/// words, and each `OpImageRead` of it unpacks its texel from them.
pub(super) struct Texel {
    pub(super) var: Word,
    pub(super) format: ImageFormat,
    pub(super) set: u32,
    pub(super) binding: u32,
}

/// Bytes per texel and (bits per channel, channels, numeric kind) of the texel buffer formats
/// the rewrite reads.
pub(super) fn texel_layout(f: ImageFormat) -> Option<(u32, u32, ScalarKind)> {
    use ScalarKind as K;
    Some(match f {
        ImageFormat::R8 => (8, 1, K::Float),
        ImageFormat::R8ui => (8, 1, K::Uint),
        ImageFormat::Rg8 => (8, 2, K::Float),
        ImageFormat::Rg8ui => (8, 2, K::Uint),
        ImageFormat::Rgba8 => (8, 4, K::Float),
        ImageFormat::Rgba8ui => (8, 4, K::Uint),
        // Two 16-bit texels a word, or one of two channels: a 64-bit texel would span two
        // words, which the unpacking below does not follow.
        ImageFormat::R16 => (16, 1, K::Float),
        ImageFormat::R16ui => (16, 1, K::Uint),
        ImageFormat::Rg16 => (16, 2, K::Float),
        ImageFormat::Rg16ui => (16, 2, K::Uint),
        ImageFormat::R32f => (32, 1, K::Float),
        ImageFormat::R32ui => (32, 1, K::Uint),
        ImageFormat::R32i => (32, 1, K::Sint),
        ImageFormat::Rg32f => (32, 2, K::Float),
        ImageFormat::Rg32ui => (32, 2, K::Uint),
        ImageFormat::Rg32i => (32, 2, K::Sint),
        ImageFormat::Rgba32f => (32, 4, K::Float),
        ImageFormat::Rgba32ui => (32, 4, K::Uint),
        ImageFormat::Rgba32i => (32, 4, K::Sint),
        _ => return None,
    })
}

fn unsupported(t: &Texel, detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "use of a storage texel buffer other than reading a texel",
        detail: format!(
            "the storage texel buffer at set {} binding {} (%{}): {detail}",
            t.set, t.binding, t.var
        ),
    }
}

/// The word buffer's types: the 32-bit scalars a read unpacks to, the pointer a texel buffer
/// variable becomes and the pointer to one of its words.
struct WordTypes {
    uint: Word,
    float: Word,
    int: Word,
    block_ptr: Word,
    word_ptr: Word,
}

/// Declares a storage block of 32-bit words (fresh array and struct types, which carry their
/// own layout) and the scalar types reads unpack to.
fn word_buffer(
    module: &Module,
    added: &mut Vec<Instruction>,
    decorations: &mut Vec<Instruction>,
    ids: &mut Ids,
) -> Result<WordTypes, SpirvError> {
    let uint = type_id(
        module,
        added,
        ids,
        Op::TypeInt,
        vec![Operand::LiteralBit32(32), Operand::LiteralBit32(0)],
    )?;
    let float = type_id(
        module,
        added,
        ids,
        Op::TypeFloat,
        vec![Operand::LiteralBit32(32)],
    )?;
    let int = type_id(
        module,
        added,
        ids,
        Op::TypeInt,
        vec![Operand::LiteralBit32(32), Operand::LiteralBit32(1)],
    )?;
    // Arrays and structs may be declared more than once: fresh ones carry their own layout.
    let words = ids.fresh()?;
    added.push(inst(
        Op::TypeRuntimeArray,
        None,
        Some(words),
        vec![Operand::IdRef(uint)],
    ));
    let block = ids.fresh()?;
    added.push(inst(
        Op::TypeStruct,
        None,
        Some(block),
        vec![Operand::IdRef(words)],
    ));
    let block_ptr = ids.fresh()?;
    added.push(inst(
        Op::TypePointer,
        None,
        Some(block_ptr),
        vec![
            Operand::StorageClass(StorageClass::StorageBuffer),
            Operand::IdRef(block),
        ],
    ));
    let word_ptr = type_id(
        module,
        added,
        ids,
        Op::TypePointer,
        vec![
            Operand::StorageClass(StorageClass::StorageBuffer),
            Operand::IdRef(uint),
        ],
    )?;
    let decorate = |target: Word, d: Decoration, extra: Vec<Operand>| {
        let mut ops = vec![Operand::IdRef(target), Operand::Decoration(d)];
        ops.extend(extra);
        inst(Op::Decorate, None, None, ops)
    };
    decorations.push(decorate(
        words,
        Decoration::ArrayStride,
        vec![Operand::LiteralBit32(4)],
    ));
    decorations.push(decorate(block, Decoration::Block, vec![]));
    decorations.push(inst(
        Op::MemberDecorate,
        None,
        None,
        vec![
            Operand::IdRef(block),
            Operand::LiteralBit32(0),
            Operand::Decoration(Decoration::Offset),
            Operand::LiteralBit32(0),
        ],
    ));
    decorations.push(inst(
        Op::MemberDecorate,
        None,
        None,
        vec![
            Operand::IdRef(block),
            Operand::LiteralBit32(0),
            Operand::Decoration(Decoration::NonWritable),
        ],
    ));
    Ok(WordTypes {
        uint,
        float,
        int,
        block_ptr,
        word_ptr,
    })
}

/// Each vector type's scalar type and width, and each 32-bit scalar type's kind: what a
/// read's result is made of.
fn scalar_types(module: &Module) -> (HashMap<Word, (Word, u32)>, HashMap<Word, ScalarKind>) {
    let components = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::TypeVector)
        .filter_map(|i| {
            let n = match i.operands.get(1) {
                Some(Operand::LiteralBit32(n)) => *n,
                _ => return None,
            };
            Some((i.result_id?, (id_ref(i.operands.first())?, n)))
        })
        .collect();
    let kinds = module
        .types_global_values
        .iter()
        .filter_map(|i| {
            let kind = match (i.class.opcode, i.operands.as_slice()) {
                (Op::TypeFloat, [Operand::LiteralBit32(32)]) => ScalarKind::Float,
                (Op::TypeInt, [Operand::LiteralBit32(32), Operand::LiteralBit32(0)]) => {
                    ScalarKind::Uint
                }
                (Op::TypeInt, [Operand::LiteralBit32(32), Operand::LiteralBit32(1)]) => {
                    ScalarKind::Sint
                }
                _ => return None,
            };
            Some((i.result_id?, kind))
        })
        .collect();
    (components, kinds)
}

/// Where a rewritten read's instructions go: constants and types to the module's globals
/// (each constant once), the unpacking to the block being rewritten.
struct Emit<'a> {
    added: &'a mut Vec<Instruction>,
    consts: &'a mut HashMap<(Word, u32), Word>,
    ids: &'a mut Ids,
    out: &'a mut Vec<Instruction>,
}

impl Emit<'_> {
    fn op(&mut self, op: Op, ty: Word, operands: Vec<Operand>) -> Result<Word, SpirvError> {
        let id = self.ids.fresh()?;
        self.out.push(inst(op, Some(ty), Some(id), operands));
        Ok(id)
    }

    fn constant(&mut self, ty: Word, bits: u32) -> Result<Word, SpirvError> {
        constant(self.added, self.ids, self.consts, ty, bits)
    }

    /// Word `index` of texel buffer `t`'s words (`zero` the block's one member).
    fn load_word(
        &mut self,
        w: &WordTypes,
        t: &Texel,
        zero: Word,
        index: Word,
    ) -> Result<Word, SpirvError> {
        let chain = vec![
            Operand::IdRef(t.var),
            Operand::IdRef(zero),
            Operand::IdRef(index),
        ];
        let ptr = self.op(Op::AccessChain, w.word_ptr, chain)?;
        self.op(Op::Load, w.uint, vec![Operand::IdRef(ptr)])
    }
}

/// One read of texel buffer `t` at `coord` in format (`bits` a channel, `channels`): the
/// word holding the texel loaded, each channel unpacked, the missing ones filled as Vulkan
/// fills them, into a vector of `n` of `kind` (the read's `result` of type `result_ty`).
fn unpack_read(
    e: &mut Emit<'_>,
    w: &WordTypes,
    t: &Texel,
    coord: Word,
    (bits, channels, kind): (u32, u32, ScalarKind),
    (result, result_ty, n): (Word, Word, u32),
) -> Result<(), SpirvError> {
    let uint = w.uint;
    let zero = e.constant(uint, 0)?;
    let texel_index = e.op(Op::Bitcast, uint, vec![Operand::IdRef(coord)])?;
    let per_word = 32 / (bits * channels).min(32);
    let (word_index, shift) = if per_word > 1 {
        let log = per_word.trailing_zeros();
        let log_c = e.constant(uint, log)?;
        let mask = e.constant(uint, per_word - 1)?;
        let three = e.constant(uint, (bits * channels).trailing_zeros())?;
        let word = e.op(
            Op::ShiftRightLogical,
            uint,
            vec![Operand::IdRef(texel_index), Operand::IdRef(log_c)],
        )?;
        let lane = e.op(
            Op::BitwiseAnd,
            uint,
            vec![Operand::IdRef(texel_index), Operand::IdRef(mask)],
        )?;
        let sh = e.op(
            Op::ShiftLeftLogical,
            uint,
            vec![Operand::IdRef(lane), Operand::IdRef(three)],
        )?;
        (word, Some(sh))
    } else {
        (texel_index, None)
    };
    let word = e.load_word(w, t, zero, word_index)?;
    let mut values = Vec::new();
    for ch in 0..channels {
        let v = if bits == 32 {
            whole_word_channel(e, w, t, (texel_index, word, zero), (channels, ch, kind))?
        } else {
            packed_channel(e, w, (word, shift), (bits, ch, kind))?
        };
        values.push(v);
    }
    let (fill, one) = match kind {
        ScalarKind::Float => (
            e.constant(w.float, 0.0f32.to_bits())?,
            e.constant(w.float, 1.0f32.to_bits())?,
        ),
        ScalarKind::Uint => (zero, e.constant(uint, 1)?),
        ScalarKind::Sint => (e.constant(w.int, 0)?, e.constant(w.int, 1)?),
    };
    while values.len() < 3 {
        values.push(fill);
    }
    if values.len() < 4 {
        values.push(one);
    }
    values.truncate(n as usize);
    e.out.push(inst(
        Op::CompositeConstruct,
        Some(result_ty),
        Some(result),
        values.into_iter().map(Operand::IdRef).collect(),
    ));
    Ok(())
}

/// Channel `ch` of a format with a channel a word: texel i's channel c is word
/// i * channels + c, bitcast to the read's kind.
fn whole_word_channel(
    e: &mut Emit<'_>,
    w: &WordTypes,
    t: &Texel,
    (texel_index, word, zero): (Word, Word, Word),
    (channels, ch, kind): (u32, u32, ScalarKind),
) -> Result<Word, SpirvError> {
    let uint = w.uint;
    let word = if channels == 1 {
        word
    } else {
        let n = e.constant(uint, channels)?;
        let c = e.constant(uint, ch)?;
        let first = e.op(
            Op::IMul,
            uint,
            vec![Operand::IdRef(texel_index), Operand::IdRef(n)],
        )?;
        let at = e.op(
            Op::IAdd,
            uint,
            vec![Operand::IdRef(first), Operand::IdRef(c)],
        )?;
        e.load_word(w, t, zero, at)?
    };
    match kind {
        ScalarKind::Uint => Ok(word),
        ScalarKind::Sint => e.op(Op::Bitcast, w.int, vec![Operand::IdRef(word)]),
        ScalarKind::Float => e.op(Op::Bitcast, w.float, vec![Operand::IdRef(word)]),
    }
}

/// Channel `ch` of a packed format: `bits` bits from the texel's place in its word (`shift`
/// where several texels share it), unorm scaled to 0..1.
fn packed_channel(
    e: &mut Emit<'_>,
    w: &WordTypes,
    (word, shift): (Word, Option<Word>),
    (bits, ch, kind): (u32, u32, ScalarKind),
) -> Result<Word, SpirvError> {
    let uint = w.uint;
    let width = e.constant(uint, bits)?;
    let offset = match shift {
        Some(sh) if ch == 0 => sh,
        Some(sh) => {
            let k = e.constant(uint, ch * bits)?;
            e.op(Op::IAdd, uint, vec![Operand::IdRef(sh), Operand::IdRef(k)])?
        }
        None => e.constant(uint, ch * bits)?,
    };
    let raw = e.op(
        Op::BitFieldUExtract,
        uint,
        vec![
            Operand::IdRef(word),
            Operand::IdRef(offset),
            Operand::IdRef(width),
        ],
    )?;
    match kind {
        ScalarKind::Float => {
            let f = e.op(Op::ConvertUToF, w.float, vec![Operand::IdRef(raw)])?;
            let scale = e.constant(w.float, (1.0f32 / ((1u32 << bits) - 1) as f32).to_bits())?;
            e.op(
                Op::FMul,
                w.float,
                vec![Operand::IdRef(f), Operand::IdRef(scale)],
            )
        }
        _ => Ok(raw),
    }
}

pub(super) fn texel_buffers(
    module: &mut Module,
    texels: &[Texel],
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    let mut added = Vec::new();
    let mut decorations = Vec::new();
    let mut consts = HashMap::new();
    let types = word_buffer(module, &mut added, &mut decorations, ids)?;
    let by_var: HashMap<Word, &Texel> = texels.iter().map(|t| (t.var, t)).collect();
    let (components, kinds) = scalar_types(module);

    // The variables become storage buffers, defined after the types they now point to.
    let mut moved = Vec::new();
    module.types_global_values.retain(|i| {
        let texel = i.class.opcode == Op::Variable
            && i.result_id.is_some_and(|id| by_var.contains_key(&id));
        if texel {
            moved.push(inst(
                Op::Variable,
                Some(types.block_ptr),
                i.result_id,
                vec![Operand::StorageClass(StorageClass::StorageBuffer)],
            ));
        }
        !texel
    });

    for function in &mut module.functions {
        // Loaded images of a texel buffer -> the buffer.
        let mut loaded: HashMap<Word, &Texel> = HashMap::new();
        for b in &mut function.blocks {
            let mut out = Vec::with_capacity(b.instructions.len());
            for i in b.instructions.drain(..) {
                let uses: Vec<Word> = i.operands.iter().filter_map(|o| id_ref(Some(o))).collect();
                if i.class.opcode == Op::Load
                    && let Some(t) = id_ref(i.operands.first()).and_then(|v| by_var.get(&v))
                {
                    if let Some(r) = i.result_id {
                        loaded.insert(r, t);
                    }
                    continue;
                }
                if let Some(t) = uses.iter().find_map(|u| by_var.get(u)) {
                    return Err(unsupported(t, format!("used by Op{:?}", i.class.opcode)));
                }
                let Some(t) = uses.iter().find_map(|u| loaded.get(u)).copied() else {
                    out.push(i);
                    continue;
                };
                // A samplerBuffer's image, taken from the loaded sampled image.
                if i.class.opcode == Op::Image
                    && id_ref(i.operands.first()).is_some_and(|x| loaded.contains_key(&x))
                {
                    if let Some(r) = i.result_id {
                        loaded.insert(r, t);
                    }
                    continue;
                }
                if !matches!(i.class.opcode, Op::ImageRead | Op::ImageFetch)
                    || id_ref(i.operands.first()).is_none_or(|img| !loaded.contains_key(&img))
                {
                    return Err(unsupported(
                        t,
                        format!("its image is used by Op{:?}", i.class.opcode),
                    ));
                }
                let (Some(result), Some(result_ty)) = (i.result_id, i.result_type) else {
                    return Err(unsupported(t, "a read without a result".to_owned()));
                };
                let coord = id_ref(i.operands.get(1))
                    .ok_or_else(|| unsupported(t, "a read without a coordinate".to_owned()))?;
                let (scalar, n) = components.get(&result_ty).copied().ok_or_else(|| {
                    unsupported(t, "a read whose result is not a vector".to_owned())
                })?;
                let kind = *kinds.get(&scalar).ok_or_else(|| {
                    unsupported(t, "a read whose result is not 32-bit".to_owned())
                })?;
                let Some((bits, channels, format_kind)) = texel_layout(t.format) else {
                    return Err(unsupported(t, format!("format {:?}", t.format)));
                };
                if format_kind != kind {
                    return Err(unsupported(
                        t,
                        format!("format {:?} read as {kind:?}", t.format),
                    ));
                }
                let mut e = Emit {
                    added: &mut added,
                    consts: &mut consts,
                    ids,
                    out: &mut out,
                };
                unpack_read(
                    &mut e,
                    &types,
                    t,
                    coord,
                    (bits, channels, kind),
                    (result, result_ty, n),
                )?;
            }
            b.instructions = out;
        }
    }
    module.types_global_values.extend(added);
    module.types_global_values.extend(moved);
    module.annotations.extend(decorations);
    // SPIR-V before 1.3 names the storage class by an extension.
    let version = module.header.as_ref().map_or((1, 0), |h| h.version());
    if version < (1, 3)
        && !module.extensions.iter().any(|e| {
            matches!(e.operands.first(), Some(Operand::LiteralString(s)) if s == "SPV_KHR_storage_buffer_storage_class")
        })
    {
        module.extensions.push(inst(
            Op::Extension,
            None,
            None,
            vec![Operand::LiteralString("SPV_KHR_storage_buffer_storage_class".to_owned())],
        ));
    }
    Ok(())
}
