//! Following a descriptor through a module's code: each variable at the (set, binding) a
//! rewrite is given, and every id that carries it on (loads, copies, access chains, sampled
//! images made with it), so that the instructions reading through it can be found. Shared by
//! the rewrites that change what is read through a binding (`bias`, `swizzle`).

use std::collections::HashMap;

use rspirv::dr::{Module, Operand};
use rspirv::spirv::{Decoration, Op, Word};

use super::index::id_ref;

/// Each variable decorated with a (set, binding) that `pick` gives a value for, with it.
pub(super) fn variables_at<T: Copy>(
    module: &Module,
    pick: impl Fn(u32, u32) -> Option<T>,
) -> HashMap<Word, T> {
    let mut at: HashMap<Word, (Option<u32>, Option<u32>)> = HashMap::new();
    for i in &module.annotations {
        if let [
            Operand::IdRef(t),
            Operand::Decoration(d),
            Operand::LiteralBit32(v),
        ] = i.operands.as_slice()
        {
            match d {
                Decoration::DescriptorSet => at.entry(*t).or_default().0 = Some(*v),
                Decoration::Binding => at.entry(*t).or_default().1 = Some(*v),
                _ => {}
            }
        }
    }
    at.into_iter()
        .filter_map(|(var, (s, b))| Some((var, pick(s?, b?)?)))
        .collect()
}

/// Every id of the module's code that carries one of `vars` on, mapped to the variable: loads,
/// copies and access chains of it, and the sampled images and images made from it, where
/// `sampled_image_operand` says which operand of OpSampledImage follows (0 the image, 1 the
/// sampler).
pub(super) fn carried<T>(
    module: &Module,
    vars: &HashMap<Word, T>,
    sampled_image_operand: usize,
) -> HashMap<Word, Word> {
    let mut root: HashMap<Word, Word> = vars.keys().map(|&v| (v, v)).collect();
    let all: Vec<(Op, &[Operand], Option<Word>)> = module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .map(|i| (i.class.opcode, i.operands.as_slice(), i.result_id))
        .collect();
    // Definitions may come after uses in layout order (loops): repeat until nothing is new.
    loop {
        let before = root.len();
        for &(op, ops, result) in &all {
            let from = match op {
                Op::Load | Op::CopyObject | Op::AccessChain | Op::InBoundsAccessChain => {
                    id_ref(ops.first())
                }
                Op::SampledImage => id_ref(ops.get(sampled_image_operand)),
                Op::Image if sampled_image_operand == 0 => id_ref(ops.first()),
                _ => None,
            };
            if let (Some(from), Some(result)) = (from, result)
                && let Some(&var) = root.get(&from)
            {
                root.insert(result, var);
            }
        }
        if root.len() == before {
            break;
        }
    }
    root
}
