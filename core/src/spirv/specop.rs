//! OpSpecConstantOp instructions rspirv cannot read, rewritten on the raw words to ones of the
//! same value that it can. rspirv's parser decodes each operand of the computed instruction
//! once, ignoring the grammar's "zero or more": a `VectorShuffle` with two components or a
//! `CompositeExtract` with two indexes leaves words over and the whole module fails to load.
//! Shader compilers emit exactly these (HLSL's `static const float2 x = v.xy` of a spec
//! constant vector, as in SMAA), and drivers run them, so they are rewritten before loading:
//! - a shuffle of n components becomes n single-index `CompositeExtract`s and an
//!   `OpSpecConstantComposite` of them, under the shuffle's own result id;
//! - an extract with k indexes becomes a chain of k single-index extracts through the
//!   intermediate member types.
//!
//! Both are the same value by the specification's definitions of the operations. Everything else
//! with more than one "zero or more" operand (a nested `CompositeInsert`, kernels' access
//! chains) is refused by name. Each instruction's original word offset is kept so errors still
//! point into the captured module.

use std::collections::HashMap;

use rspirv::grammar::{INSTRUCTION_TABLE, OperandQuantifier};
use rspirv::spirv::Op;

use super::HEADER_WORDS;
use super::SpirvError;

/// A module whose spec-constant operations were split, with where each of its instructions
/// came from.
pub(super) struct Split {
    pub words: Vec<u32>,
    /// (offset in `words`, offset in the input) for every instruction, in order.
    starts: Vec<(usize, usize)>,
}

impl Split {
    /// The input offset of the instruction at or before `at` in the split words.
    pub fn original(&self, at: usize) -> usize {
        match self.starts.binary_search_by_key(&at, |&(new, _)| new) {
            Ok(i) => self.starts[i].1,
            Err(0) => at,
            Err(i) => self.starts[i - 1].1,
        }
    }
}

/// What a global id is, as far as the split needs to know.
#[derive(Clone)]
enum Def {
    /// OpTypeVector / OpTypeMatrix / OpTypeArray: element type and element count (arrays' count
    /// only where the length is a plain 32-bit constant).
    Sequence {
        element: u32,
        count: Option<u32>,
    },
    Struct {
        members: Vec<u32>,
    },
    /// Anything with a result type: that type.
    Value {
        ty: u32,
    },
    /// An OpConstant of one word, for array lengths.
    Literal {
        value: u32,
    },
}

/// Rewrites what rspirv cannot read; `None` when there is nothing to rewrite (the common case,
/// which costs one scan). The stream's word counts must already have been checked.
pub(super) fn split_spec_ops(words: &[u32]) -> Result<Option<Split>, SpirvError> {
    if !instructions(words).any(|(_, inst)| needs_split(inst)) {
        return Ok(None);
    }
    let mut defs: HashMap<u32, Def> = HashMap::new();
    let mut next_id = words[3];
    let mut out = words[..HEADER_WORDS].to_vec();
    let mut starts = Vec::new();
    for (at, inst) in instructions(words) {
        if needs_split(inst) {
            let unsupported = |detail: String| SpirvError::Unsupported {
                feature: "OpSpecConstantOp",
                detail: format!("{detail} (word {at})"),
            };
            let mut fresh = || {
                let id = next_id;
                next_id = next_id
                    .checked_add(1)
                    .ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?;
                Ok::<u32, SpirvError>(id)
            };
            let (ty, id, op, args) = (inst[1], inst[2], inst[3], &inst[4..]);
            let mut emitted = Vec::new();
            if op == Op::VectorShuffle as u32 {
                let [a, b, components @ ..] = args else {
                    return Err(unsupported(
                        "a VectorShuffle without its two vectors".into(),
                    ));
                };
                let width = |v: u32| match defs.get(&v) {
                    Some(Def::Value { ty }) => match defs.get(ty) {
                        Some(Def::Sequence { count: Some(n), .. }) => Some(*n),
                        _ => None,
                    },
                    _ => None,
                };
                let scalar = match defs.get(&ty) {
                    Some(Def::Sequence { element, .. }) => *element,
                    _ => {
                        return Err(unsupported(
                            "a VectorShuffle whose type is not a vector".into(),
                        ));
                    }
                };
                let first = width(*a).ok_or_else(|| {
                    unsupported(format!(
                        "a VectorShuffle of %{a}, which is not a vector constant"
                    ))
                })?;
                let mut parts = Vec::with_capacity(components.len());
                for &c in components {
                    let (source, index) = if c == u32::MAX {
                        return Err(unsupported(
                            "a VectorShuffle with an undefined component".into(),
                        ));
                    } else if c < first {
                        (*a, c)
                    } else {
                        (*b, c - first)
                    };
                    let part = fresh()?;
                    emitted.extend(extract(scalar, part, source, index));
                    parts.push(part);
                }
                let count = u32::try_from(3 + parts.len()).unwrap_or(u32::MAX);
                emitted.extend([(count << 16) | Op::SpecConstantComposite as u32, ty, id]);
                emitted.extend(parts);
            } else if op == Op::CompositeExtract as u32 {
                let [composite, indexes @ ..] = args else {
                    return Err(unsupported(
                        "a CompositeExtract without its composite".into(),
                    ));
                };
                let mut current = *composite;
                let mut current_ty = match defs.get(composite) {
                    Some(Def::Value { ty }) => *ty,
                    _ => {
                        return Err(unsupported(format!(
                            "a CompositeExtract of %{composite}, which is not a constant"
                        )));
                    }
                };
                for (n, &index) in indexes.iter().enumerate() {
                    if n + 1 == indexes.len() {
                        emitted.extend(extract(ty, id, current, index));
                        break;
                    }
                    let member = member_type(&defs, current_ty, index).ok_or_else(|| {
                        unsupported(format!(
                            "a CompositeExtract whose index {index} is outside %{current_ty}"
                        ))
                    })?;
                    let part = fresh()?;
                    emitted.extend(extract(member, part, current, index));
                    current = part;
                    current_ty = member;
                }
            } else {
                let name = INSTRUCTION_TABLE
                    .lookup_opcode(op)
                    .map_or_else(|| format!("opcode {op}"), |g| format!("Op{}", g.opname));
                return Err(unsupported(format!(
                    "{name} with more than one of a repeated operand, which the SPIR-V reader cannot decode"
                )));
            }
            for piece in instructions_of(&emitted) {
                starts.push((out.len(), at));
                out.extend_from_slice(piece);
            }
            defs.insert(id, Def::Value { ty });
            continue;
        }
        record(&mut defs, inst);
        starts.push((out.len(), at));
        out.extend_from_slice(inst);
    }
    out[3] = next_id;
    Ok(Some(Split { words: out, starts }))
}

/// `OpSpecConstantOp %ty %id CompositeExtract %composite index`.
fn extract(ty: u32, id: u32, composite: u32, index: u32) -> [u32; 6] {
    [
        (6 << 16) | Op::SpecConstantOp as u32,
        ty,
        id,
        Op::CompositeExtract as u32,
        composite,
        index,
    ]
}

/// The type of member `index` of composite type `ty`.
fn member_type(defs: &HashMap<u32, Def>, ty: u32, index: u32) -> Option<u32> {
    match defs.get(&ty)? {
        Def::Sequence { element, count } => count.is_none_or(|n| index < n).then_some(*element),
        Def::Struct { members } => members.get(index as usize).copied(),
        _ => None,
    }
}

/// Whether `inst` is an OpSpecConstantOp that rspirv would misread: its computed instruction
/// has a "zero or more" operand and the instruction holds more words than one of each.
fn needs_split(inst: &[u32]) -> bool {
    if inst[0] & 0xffff != Op::SpecConstantOp as u32 {
        return false;
    }
    let Some(grammar) = inst
        .get(3)
        .and_then(|op| INSTRUCTION_TABLE.lookup_opcode(*op))
    else {
        return false;
    };
    let repeated = grammar
        .operands
        .iter()
        .any(|o| o.quantifier == OperandQuantifier::ZeroOrMore);
    // Result type and id are the OpSpecConstantOp's own, not the computed instruction's.
    let one_each = grammar
        .operands
        .iter()
        .filter(|o| {
            !matches!(
                o.kind,
                rspirv::grammar::OperandKind::IdResultType | rspirv::grammar::OperandKind::IdResult
            )
        })
        .count();
    repeated && inst.len() > 4 + one_each
}

/// Remembers the types and constants a later split may ask about.
fn record(defs: &mut HashMap<u32, Def>, inst: &[u32]) {
    let opcode = inst[0] & 0xffff;
    let get = |i: usize| inst.get(i).copied();
    let def = match opcode {
        o if o == Op::TypeVector as u32 || o == Op::TypeMatrix as u32 => {
            let (Some(id), Some(element), Some(count)) = (get(1), get(2), get(3)) else {
                return;
            };
            (
                id,
                Def::Sequence {
                    element,
                    count: Some(count),
                },
            )
        }
        o if o == Op::TypeArray as u32 => {
            let (Some(id), Some(element), Some(length)) = (get(1), get(2), get(3)) else {
                return;
            };
            let count = match defs.get(&length) {
                Some(Def::Literal { value }) => Some(*value),
                _ => None,
            };
            (id, Def::Sequence { element, count })
        }
        o if o == Op::TypeStruct as u32 => {
            let Some(id) = get(1) else { return };
            (
                id,
                Def::Struct {
                    members: inst[2..].to_vec(),
                },
            )
        }
        o if o == Op::Constant as u32 && inst.len() == 4 => {
            (inst[2], Def::Literal { value: inst[3] })
        }
        _ => {
            let has_type = INSTRUCTION_TABLE.lookup_opcode(opcode).is_some_and(|g| {
                g.operands.first().map(|o| o.kind)
                    == Some(rspirv::grammar::OperandKind::IdResultType)
            });
            let (true, Some(ty), Some(id)) = (has_type, get(1), get(2)) else {
                return;
            };
            (id, Def::Value { ty })
        }
    };
    defs.insert(def.0, def.1);
}

/// Each instruction of a checked stream after the header, with its word offset.
fn instructions(words: &[u32]) -> impl Iterator<Item = (usize, &[u32])> {
    let mut at = HEADER_WORDS;
    std::iter::from_fn(move || {
        let first = *words.get(at)?;
        let count = ((first >> 16) as usize).max(1);
        let inst = words.get(at..at + count)?;
        let start = at;
        at += count;
        Some((start, inst))
    })
}

/// The instructions of words built here.
fn instructions_of(words: &[u32]) -> impl Iterator<Item = &[u32]> {
    let mut at = 0;
    std::iter::from_fn(move || {
        let count = ((*words.get(at)? >> 16) as usize).max(1);
        let inst = words.get(at..at + count)?;
        at += count;
        Some(inst)
    })
}
