//! Whether a module's code reads and writes each descriptor variable, found from its
//! instructions rather than its decorations (a storage binding without NonWritable may still
//! only be read): the synchronization check needs the access a shader really makes, as the
//! validation layer takes it from the same code.
//!
//! Pointers and images are followed from the variable through loads, access chains and copies;
//! image reads and writes, loads and stores, atomics and memory copies through them are the
//! accesses. A pointer handed to a function call counts as both, since the callee is not
//! followed.

use std::collections::{BTreeMap, HashMap};

use rspirv::dr::Operand;
use rspirv::spirv::{Decoration, Op, Word};

use super::SpirvError;
use super::index::{self, Index};

/// What the code does with one descriptor binding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Usage {
    pub reads: bool,
    pub writes: bool,
    /// The code names the variable at all: the specification's static use, which is what
    /// makes a bound descriptor an access (a feedback loop, a hazard) rather than a binding
    /// left in a set.
    pub used: bool,
}

/// Per (set, binding): what the module's code does with the variables bound there.
pub fn usage(words: &[u32]) -> Result<BTreeMap<(u32, u32), Usage>, SpirvError> {
    usage_loaded(&index::load(words)?, None)
}

/// [`usage`] per entry point name: what the functions each entry point reaches (through
/// calls) do, the specification's static use being per entry point. A module whose passes
/// are entry points of one module (vkBasalt's ReShade effects) binds everything to every pass
/// while each pass reads a few.
pub fn usage_by_entry(words: &[u32]) -> Result<BTreeMap<String, super::Usages>, SpirvError> {
    let loaded = index::load(words)?;
    let names: std::collections::BTreeSet<String> = loaded
        .module
        .entry_points
        .iter()
        .filter_map(|e| super::reflect::entry_point_parts(e).map(|(_, _, n)| n.to_owned()))
        .collect();
    names
        .into_iter()
        .map(|n| Ok((n.clone(), usage_loaded(&loaded, Some(&n))?)))
        .collect()
}

/// [`usage`] of a module already loaded, of the functions entry points named `entry` reach
/// (every function where `None`).
pub(super) fn usage_loaded(
    loaded: &index::Loaded,
    entry: Option<&str>,
) -> Result<BTreeMap<(u32, u32), Usage>, SpirvError> {
    let reach = entry.map(|e| {
        let roots = loaded
            .module
            .entry_points
            .iter()
            .filter_map(super::reflect::entry_point_parts)
            .filter(|(_, _, n)| *n == e)
            .map(|(_, f, _)| f)
            .collect();
        super::entry::reached(&loaded.module, roots)
    });
    let index = Index::new(loaded);
    let module = &loaded.module;
    let binding_of = descriptor_variables(module, &index);
    // Every id derived from a descriptor variable, mapped to the variable.
    let mut root: HashMap<Word, Word> = binding_of.keys().map(|&v| (v, v)).collect();
    // Per variable: (loaded, stored, image read, image written).
    let mut seen: HashMap<Word, [bool; 4]> = HashMap::new();
    let mut named: std::collections::HashSet<Word> = std::collections::HashSet::new();
    let id = |operands: &[Operand], i: usize| match operands.get(i) {
        Some(Operand::IdRef(x)) => Some(*x),
        _ => None,
    };
    for inst in module
        .functions
        .iter()
        .filter(|f| {
            reach.as_ref().is_none_or(|r| {
                f.def
                    .as_ref()
                    .and_then(|d| d.result_id)
                    .is_some_and(|id| r.contains(&id))
            })
        })
        .flat_map(|f| &f.blocks)
        .flat_map(|b| &b.instructions)
    {
        let ops = &inst.operands;
        for op in ops {
            if let Operand::IdRef(x) = op
                && binding_of.contains_key(x)
            {
                named.insert(*x);
            }
        }
        let mut mark = |operand: usize, what: &[usize]| {
            if let Some(var) = id(ops, operand).and_then(|x| root.get(&x).copied()) {
                let s = seen.entry(var).or_default();
                for &w in what {
                    s[w] = true;
                }
            }
        };
        match inst.class.opcode {
            Op::ImageRead | Op::ImageFetch | Op::ImageSparseRead | Op::ImageSparseFetch => {
                mark(0, &[2]);
            }
            Op::ImageWrite => mark(0, &[3]),
            Op::Store | Op::AtomicStore => mark(0, &[1]),
            Op::AtomicLoad => mark(0, &[0]),
            Op::AtomicExchange
            | Op::AtomicCompareExchange
            | Op::AtomicCompareExchangeWeak
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
            | Op::AtomicFlagTestAndSet
            | Op::AtomicFlagClear
            | Op::AtomicFAddEXT
            | Op::AtomicFMinEXT
            | Op::AtomicFMaxEXT => mark(0, &[0, 1, 2, 3]),
            Op::CopyMemory | Op::CopyMemorySized => {
                mark(0, &[1]);
                mark(1, &[0]);
            }
            Op::FunctionCall => {
                for i in 1..ops.len() {
                    mark(i, &[0, 1, 2, 3]);
                }
            }
            _ => {}
        }
        // Ids that carry the variable on: a load of it (the image, or the value), an access
        // chain into it, a copy, a texel pointer into its image.
        let from = match inst.class.opcode {
            Op::Load
            | Op::AccessChain
            | Op::InBoundsAccessChain
            | Op::PtrAccessChain
            | Op::InBoundsPtrAccessChain
            | Op::CopyObject
            | Op::ImageTexelPointer
            | Op::SampledImage
            | Op::Image => id(ops, 0),
            _ => None,
        };
        if let (Some(from), Some(result)) = (from, inst.result_id)
            && let Some(&var) = root.get(&from)
        {
            if inst.class.opcode == Op::Load {
                seen.entry(var).or_default()[0] = true;
            }
            root.insert(result, var);
        }
    }
    Ok(by_binding(&index, binding_of, &seen, &named))
}

/// Each descriptor variable's (set, binding).
fn descriptor_variables(module: &rspirv::dr::Module, index: &Index) -> HashMap<Word, (u32, u32)> {
    let mut binding_of: HashMap<Word, (u32, u32)> = HashMap::new();
    for inst in &module.types_global_values {
        if inst.class.opcode != Op::Variable {
            continue;
        }
        let var = inst.result_id.unwrap_or(0);
        if let (Some(set), Some(binding)) = (
            index.decoration_literal(var, Decoration::DescriptorSet),
            index.decoration_literal(var, Decoration::Binding),
        ) {
            binding_of.insert(var, (set, binding));
        }
    }
    binding_of
}

/// The usage of each (set, binding) from what was seen of its variables: loaded, stored,
/// image read, image written, named at all.
fn by_binding(
    index: &Index,
    binding_of: HashMap<Word, (u32, u32)>,
    seen: &HashMap<Word, [bool; 4]>,
    named: &std::collections::HashSet<Word>,
) -> BTreeMap<(u32, u32), Usage> {
    let mut out = BTreeMap::new();
    for (var, at) in binding_of {
        let [loaded, stored, image_read, image_written] =
            seen.get(&var).copied().unwrap_or_default();
        // An image variable is loaded to get the image; its texels are read and written by
        // the image instructions. A buffer's loads and stores are its reads and writes.
        let image = image_read || image_written || is_image(index, var);
        let u = if image {
            Usage {
                reads: image_read,
                writes: image_written,
                used: false,
            }
        } else {
            Usage {
                reads: loaded,
                writes: stored,
                used: false,
            }
        };
        let e: &mut Usage = out.entry(at).or_default();
        e.reads |= u.reads;
        e.writes |= u.writes;
        e.used |= named.contains(&var);
    }
    out
}

/// Whether the variable points at an image (or an array of them).
fn is_image(index: &Index, var: Word) -> bool {
    let mut ty = index
        .def(var, var)
        .ok()
        .and_then(|v| v.result_type)
        .and_then(|p| index.def(p, var).ok())
        .and_then(|p| match p.operands.get(1) {
            Some(Operand::IdRef(t)) => index.def(*t, var).ok(),
            _ => None,
        });
    for _ in 0..8 {
        match ty {
            Some(t) if t.class.opcode == Op::TypeImage => return true,
            Some(t) if matches!(t.class.opcode, Op::TypeArray | Op::TypeRuntimeArray) => {
                ty = match t.operands.first() {
                    Some(Operand::IdRef(e)) => index.def(*e, var).ok(),
                    _ => None,
                };
            }
            _ => return false,
        }
    }
    false
}
