//! Combined image samplers handed to functions. glslang passes a `sampler2D` argument as a
//! pointer parameter (`OpFunctionParameter` of the variable's pointer type), and the split
//! (`rewrite`) follows only loads of the variable itself. So each such parameter is resolved
//! first to the one variable every call passes (through other such parameters too), and
//! removed: loads of the parameter become loads of the variable, the argument leaves every
//! call, and the function takes a type without it. Then the variable is only ever loaded,
//! which the split rewrites. A function whose calls fill a parameter with different variables
//! is first copied per list of variables (`param_copies`); a parameter used other than by
//! loading it or passing it on is refused by name.

use std::collections::{HashMap, HashSet};

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Op, Word};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::{Ids, type_id};

fn unsupported(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "combined image sampler passed to a function",
        detail,
    }
}

/// The module's combined image sampler variables (one each, not arrays): what the split
/// rewrites.
pub(super) fn combined_vars(module: &Module) -> HashSet<Word> {
    let defs: HashMap<Word, &Instruction> = module
        .types_global_values
        .iter()
        .filter_map(|i| Some((i.result_id?, i)))
        .collect();
    let sampled_pointer = |ty: Word| {
        defs.get(&ty)
            .filter(|p| p.class.opcode == Op::TypePointer)
            .and_then(|p| id_ref(p.operands.get(1)))
            .and_then(|pointee| defs.get(&pointee))
            .is_some_and(|t| t.class.opcode == Op::TypeSampledImage)
    };
    module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::Variable)
        .filter(|i| i.result_type.is_some_and(sampled_pointer))
        .filter_map(|i| i.result_id)
        .collect()
}

/// Removes every function parameter through which one of `vars` (combined image sampler
/// variables) is passed, as above. Returns whether anything changed.
pub(super) fn inline_sampler_params(
    module: &mut Module,
    vars: &HashSet<Word>,
) -> Result<bool, SpirvError> {
    let var_types: HashSet<Word> = module
        .types_global_values
        .iter()
        .filter(|i| i.result_id.is_some_and(|id| vars.contains(&id)))
        .filter_map(|i| i.result_type)
        .collect();
    // A parameter different calls fill with different variables gets a function per list.
    super::param_copies::copy_per_sampler(module, vars, &var_types)?;
    // Function id -> its parameters (id, type), in order.
    let params: HashMap<Word, Vec<(Word, Word)>> = module
        .functions
        .iter()
        .filter_map(|f| {
            let id = f.def.as_ref()?.result_id?;
            let ps = f
                .parameters
                .iter()
                .filter_map(|p| Some((p.result_id?, p.result_type?)))
                .collect();
            Some((id, ps))
        })
        .collect();
    let candidates: Vec<(Word, usize, Word)> = params
        .iter()
        .flat_map(|(&f, ps)| {
            ps.iter()
                .enumerate()
                .filter(|(_, (_, ty))| var_types.contains(ty))
                .map(move |(k, (p, _))| (f, k, *p))
        })
        .collect();
    if candidates.is_empty() {
        return Ok(false);
    }
    // Every call: (callee, arguments).
    let calls = super::param_copies::calls(module);
    let source = resolve(module, &candidates, &calls, vars)?;
    if source.is_empty() {
        return Ok(false);
    }
    check_param_uses(module, &source)?;
    // Loads of a parameter load the variable.
    for inst in module
        .functions
        .iter_mut()
        .flat_map(|f| f.blocks.iter_mut())
        .flat_map(|b| b.instructions.iter_mut())
    {
        if inst.class.opcode == Op::Load
            && let Some(Operand::IdRef(p)) = inst.operands.first_mut()
            && let Some(&v) = source.get(p)
        {
            *p = v;
        }
    }
    // Positions removed per function.
    let mut removed: HashMap<Word, Vec<usize>> = HashMap::new();
    for &(f, k, p) in &candidates {
        if source.contains_key(&p) {
            removed.entry(f).or_default().push(k);
        }
    }
    for inst in module
        .functions
        .iter_mut()
        .flat_map(|f| f.blocks.iter_mut())
        .flat_map(|b| b.instructions.iter_mut())
        .filter(|i| i.class.opcode == Op::FunctionCall)
    {
        if let Some(ks) = id_ref(inst.operands.first()).and_then(|f| removed.get(&f)) {
            let mut k = 0;
            inst.operands.retain(|_| {
                k += 1;
                // Operand 0 is the callee; argument n is operand n + 1.
                k == 1 || !ks.contains(&(k - 2))
            });
        }
    }
    let retyped = retype(module, &removed)?;
    forget(module, &source.keys().copied().collect());
    Ok(retyped)
}

/// Drops the names and decorations of removed parameters: a debug name or a decoration
/// (compilers mark parameters `RelaxedPrecision`) naming an id nothing defines any more makes
/// the module invalid.
fn forget(module: &mut Module, gone: &HashSet<Word>) {
    let names = |i: &Instruction| !matches!(i.operands.first(), Some(Operand::IdRef(t)) if gone.contains(t));
    module.debug_names.retain(names);
    module
        .annotations
        .retain(|i| i.class.opcode == Op::GroupDecorate || names(i));
    for inst in module
        .annotations
        .iter_mut()
        .filter(|i| i.class.opcode == Op::GroupDecorate)
    {
        // Operand 0 is the group; the rest are targets.
        let mut first = true;
        inst.operands.retain(|o| {
            std::mem::take(&mut first) || !matches!(o, Operand::IdRef(t) if gone.contains(t))
        });
    }
}

/// The variable each candidate parameter carries, found to a fixed point over the calls
/// (`param_copies::settled`; a function whose calls differ was copied per list before). A
/// parameter some call fills with what no variable resolves to is refused by name.
fn resolve(
    module: &Module,
    candidates: &[(Word, usize, Word)],
    calls: &[(Word, Vec<Option<Word>>)],
    vars: &HashSet<Word>,
) -> Result<HashMap<Word, Word>, SpirvError> {
    let source = super::param_copies::settled(module, candidates, vars);
    for &(f, _, p) in candidates {
        let called = calls.iter().any(|(callee, _)| *callee == f);
        if called && !source.contains_key(&p) {
            return Err(unsupported(format!(
                "parameter %{p} of function %{f} is given a combined image sampler the rewrite cannot trace to its variable"
            )));
        }
    }
    Ok(source)
}

/// A resolved parameter may only be loaded or passed on to another call.
fn check_param_uses(module: &Module, source: &HashMap<Word, Word>) -> Result<(), SpirvError> {
    for inst in module.functions.iter().flat_map(|f| f.all_inst_iter()) {
        for (n, op) in inst.operands.iter().enumerate() {
            let Some(p) = id_ref(Some(op)).filter(|x| source.contains_key(x)) else {
                continue;
            };
            let ok = match inst.class.opcode {
                Op::Load => n == 0,
                Op::FunctionCall => n > 0,
                _ => false,
            };
            if !ok {
                return Err(unsupported(format!(
                    "parameter %{p} is used by Op{:?}",
                    inst.class.opcode
                )));
            }
        }
    }
    Ok(())
}

/// Drops the removed parameters from their functions and gives each function the type of
/// what is left.
fn retype(module: &mut Module, removed: &HashMap<Word, Vec<usize>>) -> Result<bool, SpirvError> {
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut added: Vec<Instruction> = Vec::new();
    let fn_types: HashMap<Word, Vec<Operand>> = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::TypeFunction)
        .filter_map(|i| Some((i.result_id?, i.operands.clone())))
        .collect();
    let mut new_types = Vec::new();
    for (fi, f) in module.functions.iter().enumerate() {
        let Some(def) = &f.def else { continue };
        let Some(ks) = def.result_id.and_then(|id| removed.get(&id)) else {
            continue;
        };
        let Some(old) = id_ref(def.operands.get(1)) else {
            continue;
        };
        let Some(ops) = fn_types.get(&old) else {
            return Err(SpirvError::Malformed {
                at_word: 0,
                detail: format!("function type %{old} is not an OpTypeFunction"),
            });
        };
        // Operand 0 is the return type; parameter n is operand n + 1.
        let kept: Vec<Operand> = ops
            .iter()
            .enumerate()
            .filter(|(n, _)| *n == 0 || !ks.contains(&(n - 1)))
            .map(|(_, o)| o.clone())
            .collect();
        let ty = type_id(module, &mut added, &mut ids, Op::TypeFunction, kept)?;
        new_types.push((fi, ty, ks.clone()));
    }
    module.types_global_values.extend(added);
    for (fi, ty, ks) in new_types {
        let f = &mut module.functions[fi];
        if let Some(def) = f.def.as_mut()
            && let Some(op) = def.operands.get_mut(1)
        {
            *op = Operand::IdRef(ty);
        }
        let mut k = 0;
        f.parameters.retain(|_| {
            k += 1;
            !ks.contains(&(k - 1))
        });
    }
    if let Some(h) = module.header.as_mut() {
        h.bound = h.bound.max(ids.next);
    }
    Ok(true)
}
