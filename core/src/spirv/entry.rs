//! A module cut down to the one entry point a pipeline stage runs: the other entry points,
//! their execution modes, and the functions only they reach are removed, with every name and
//! decoration of what those functions defined. What is left is what the stage statically
//! uses, so that a descriptor only another entry point names is no longer in the module (one
//! module holding every pass of an effect, as vkBasalt's ReShade effects do, binds
//! everything to every pass).

use std::collections::HashSet;

use rspirv::dr::{Module, Operand};
use rspirv::spirv::{ExecutionModel, Op, Word};

use super::reflect::entry_point_parts;

/// Keeps the entry point `entry` of `model` and what it reaches; a module without it is left
/// as it is (the rewrite says the entry point is missing).
pub(super) fn keep_entry(module: &mut Module, model: ExecutionModel, entry: &str) {
    let Some(kept) = module
        .entry_points
        .iter()
        .filter_map(entry_point_parts)
        .find(|(m, _, n)| *m == model && *n == entry)
        .map(|(_, f, _)| f)
    else {
        return;
    };
    let reached = reached(module, HashSet::from([kept]));
    let removed: HashSet<Word> = module
        .functions
        .iter()
        .filter(|f| {
            f.def
                .as_ref()
                .and_then(|d| d.result_id)
                .is_some_and(|id| !reached.contains(&id))
        })
        .flat_map(|f| f.all_inst_iter())
        .filter_map(|i| i.result_id)
        .collect();
    if removed.is_empty() && module.entry_points.len() == 1 {
        return;
    }
    module.functions.retain(|f| {
        f.def
            .as_ref()
            .and_then(|d| d.result_id)
            .is_none_or(|id| reached.contains(&id))
    });
    module.entry_points.retain(|e| {
        entry_point_parts(e).is_some_and(|(m, f, n)| m == model && n == entry && f == kept)
    });
    let targets_removed = |i: &rspirv::dr::Instruction| matches!(i.operands.first(), Some(Operand::IdRef(t)) if removed.contains(t));
    module
        .execution_modes
        .retain(|i| matches!(i.operands.first(), Some(Operand::IdRef(f)) if *f == kept));
    module.annotations.retain(|i| !targets_removed(i));
    module.debug_names.retain(|i| !targets_removed(i));
}

/// The functions `roots` reach through calls, themselves included.
pub(super) fn reached(module: &Module, roots: HashSet<Word>) -> HashSet<Word> {
    let mut out = roots;
    let mut todo: Vec<Word> = out.iter().copied().collect();
    while let Some(f) = todo.pop() {
        let Some(function) = module
            .functions
            .iter()
            .find(|x| x.def.as_ref().and_then(|d| d.result_id) == Some(f))
        else {
            continue;
        };
        for i in function.all_inst_iter() {
            if i.class.opcode == Op::FunctionCall
                && let Some(Operand::IdRef(callee)) = i.operands.first()
                && out.insert(*callee)
            {
                todo.push(*callee);
            }
        }
    }
    out
}
