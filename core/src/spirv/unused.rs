//! Descriptor variables the code never names (no static use). Vulkan lets a pipeline layout
//! leave out what a shader declares but does not use, and the lowering builds wgpu's layout
//! from what the code uses; such a variable is removed with its decorations, names and
//! entry-point interface listing, so that the module keeps every binding it declares in the
//! layout it is run with.

use std::collections::{HashMap, HashSet};

use rspirv::dr::{Module, Operand};
use rspirv::spirv::{Decoration, Op, Word};

/// Removes the descriptor variables whose (set, binding) `bound` rejects and which no
/// function names. A variable the code uses is kept whatever `bound` says: the rewrite
/// refuses it by name if the layout lacks it.
pub(super) fn drop_unbound(module: &mut Module, bound: impl Fn(u32, u32) -> bool) {
    let mut set_of: HashMap<Word, u32> = HashMap::new();
    let mut binding_of: HashMap<Word, u32> = HashMap::new();
    for i in &module.annotations {
        let (Op::Decorate, [Operand::IdRef(target), Operand::Decoration(d), rest @ ..]) =
            (i.class.opcode, i.operands.as_slice())
        else {
            continue;
        };
        let Some(Operand::LiteralBit32(value)) = rest.first() else {
            continue;
        };
        match d {
            Decoration::DescriptorSet => set_of.insert(*target, *value),
            Decoration::Binding => binding_of.insert(*target, *value),
            _ => None,
        };
    }
    let named: HashSet<Word> = module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .flat_map(|i| i.operands.iter())
        .filter_map(|o| match o {
            Operand::IdRef(id) => Some(*id),
            _ => None,
        })
        .collect();
    let unbound: HashSet<Word> = set_of
        .iter()
        .filter_map(|(&var, &set)| Some((var, set, *binding_of.get(&var)?)))
        .filter(|&(var, set, binding)| !named.contains(&var) && !bound(set, binding))
        .map(|(var, ..)| var)
        .collect();
    if unbound.is_empty() {
        return;
    }
    let names = |i: &rspirv::dr::Instruction| matches!(i.operands.first(), Some(Operand::IdRef(t)) if unbound.contains(t));
    module.types_global_values.retain(|i| {
        !(i.class.opcode == Op::Variable && i.result_id.is_some_and(|r| unbound.contains(&r)))
    });
    module.annotations.retain(|i| !names(i));
    module.debug_names.retain(|i| !names(i));
    for e in &mut module.entry_points {
        // Operands: execution model, function, name, then the interface.
        let (head, interface) = e.operands.split_at(3.min(e.operands.len()));
        let kept: Vec<Operand> = interface
            .iter()
            .filter(|o| !matches!(o, Operand::IdRef(id) if unbound.contains(id)))
            .cloned()
            .collect();
        e.operands = head.iter().cloned().chain(kept).collect();
    }
}
