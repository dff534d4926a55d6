//! Functions whose calls hand different combined image samplers to one parameter (Qt Quick
//! 3D's `qt_sampleOrthographic(sampler2D, ...)` called once per shadow-casting light, a
//! ReShade effect's helper called with the back buffer and with a texture): each such
//! function is copied, one copy per distinct list of samplers its calls pass, and each call
//! is sent to its copy. Then every parameter carries one variable, which `params` removes
//! and the split rewrites. A function called with one list keeps its single body; nested
//! helpers are copied as their callers' copies make their calls differ.

use std::collections::{BTreeSet, HashMap, HashSet};

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Op, Word};

use super::SpirvError;
use super::index::{first_free_id, id_ref};
use super::ops::Ids;

/// At most this many copies a module: a copy per call site of a helper nested a few levels
/// deep stays far below it; more is refused rather than grown without bound.
const MAX_COPIES: usize = 256;

/// A sampler parameter: its function, its position among the parameters, its id.
type Candidate = (Word, usize, Word);

/// Copies functions until no sampler parameter is given different variables by its calls.
/// `var_types` are the pointer types of the combined image sampler variables `vars`.
pub(super) fn copy_per_sampler(
    module: &mut Module,
    vars: &HashSet<Word>,
    var_types: &HashSet<Word>,
) -> Result<(), SpirvError> {
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut copies = 0;
    loop {
        let candidates = candidates(module, var_types);
        if candidates.is_empty() {
            break;
        }
        let source = settled(module, &candidates, vars);
        let Some((f, positions)) = first_divided(module, &candidates, vars, &source) else {
            break;
        };
        // Every call of `f`: where it is, and the samplers it passes at `positions`.
        let mut sites: Vec<((usize, usize, usize), Vec<Word>)> = Vec::new();
        for (fi, func) in module.functions.iter().enumerate() {
            for (bi, block) in func.blocks.iter().enumerate() {
                for (ii, inst) in block.instructions.iter().enumerate() {
                    if inst.class.opcode == Op::FunctionCall
                        && id_ref(inst.operands.first()) == Some(f)
                        && let Some(list) = passed(inst, &positions, vars, &source)
                    {
                        sites.push(((fi, bi, ii), list));
                    }
                }
            }
        }
        let lists: BTreeSet<Vec<Word>> = sites.iter().map(|(_, l)| l.clone()).collect();
        let Some(fi) = module
            .functions
            .iter()
            .position(|g| g.def.as_ref().and_then(|d| d.result_id) == Some(f))
        else {
            break;
        };
        // The first list keeps the function; every other gets a copy.
        let mut callee: HashMap<Vec<Word>, Word> = HashMap::new();
        for list in lists.into_iter().skip(1) {
            copies += 1;
            if copies > MAX_COPIES {
                return Err(SpirvError::Unsupported {
                    feature: "combined image sampler passed to a function",
                    detail: format!(
                        "more than {MAX_COPIES} copies of functions would be needed to give each call's combined image samplers a function of their own"
                    ),
                });
            }
            callee.insert(list, copy_function(module, fi, &mut ids)?);
        }
        for ((fi, bi, ii), list) in sites {
            if let Some(&g) = callee.get(&list) {
                module.functions[fi].blocks[bi].instructions[ii].operands[0] = Operand::IdRef(g);
            }
        }
    }
    if let Some(h) = module.header.as_mut() {
        h.bound = h.bound.max(ids.next);
    }
    Ok(())
}

/// Every parameter of a combined image sampler variable's pointer type.
fn candidates(module: &Module, var_types: &HashSet<Word>) -> Vec<Candidate> {
    module
        .functions
        .iter()
        .filter_map(|f| Some((f.def.as_ref()?.result_id?, f)))
        .flat_map(|(id, f)| {
            f.parameters.iter().enumerate().filter_map(move |(k, p)| {
                p.result_type
                    .filter(|ty| var_types.contains(ty))
                    .and_then(|_| Some((id, k, p.result_id?)))
            })
        })
        .collect()
}

/// The variable a call's argument is: a variable itself, or a parameter settled to one.
fn variable_of(a: Word, vars: &HashSet<Word>, source: &HashMap<Word, Word>) -> Option<Word> {
    if vars.contains(&a) {
        Some(a)
    } else {
        source.get(&a).copied()
    }
}

/// The samplers call `inst` passes at parameter `positions`, where each is known.
fn passed(
    inst: &Instruction,
    positions: &[usize],
    vars: &HashSet<Word>,
    source: &HashMap<Word, Word>,
) -> Option<Vec<Word>> {
    positions
        .iter()
        .map(|&k| {
            // Operand 0 is the callee; argument k is operand k + 1.
            let a = id_ref(inst.operands.get(k + 1))?;
            variable_of(a, vars, source)
        })
        .collect()
}

/// The parameters every call agrees on, to a fixed point (a parameter passed on settles
/// once its caller's does).
pub(super) fn settled(
    module: &Module,
    candidates: &[Candidate],
    vars: &HashSet<Word>,
) -> HashMap<Word, Word> {
    let calls = calls(module);
    let mut source: HashMap<Word, Word> = HashMap::new();
    for _ in 0..=candidates.len() {
        let mut changed = false;
        for &(f, k, p) in candidates {
            if source.contains_key(&p) {
                continue;
            }
            let args: Option<BTreeSet<Word>> = calls
                .iter()
                .filter(|(callee, _)| *callee == f)
                .map(|(_, args)| variable_of(args.get(k).copied().flatten()?, vars, &source))
                .collect();
            if let Some(args) = args
                && args.len() == 1
                && let Some(&v) = args.first()
            {
                source.insert(p, v);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    source
}

/// The first function (in module order) some of whose sampler parameters its calls fill
/// with different variables, every call's known: the function and its sampler parameters'
/// positions.
fn first_divided(
    module: &Module,
    candidates: &[Candidate],
    vars: &HashSet<Word>,
    source: &HashMap<Word, Word>,
) -> Option<(Word, Vec<usize>)> {
    let calls = calls(module);
    let mut functions: Vec<Word> = candidates.iter().map(|c| c.0).collect();
    functions.dedup();
    functions.into_iter().find_map(|f| {
        let positions: Vec<usize> = candidates
            .iter()
            .filter(|c| c.0 == f)
            .map(|c| c.1)
            .collect();
        let lists: Option<BTreeSet<Vec<Word>>> = calls
            .iter()
            .filter(|(callee, _)| *callee == f)
            .map(|(_, args)| {
                positions
                    .iter()
                    .map(|&k| variable_of(args.get(k).copied().flatten()?, vars, source))
                    .collect::<Option<Vec<Word>>>()
            })
            .collect();
        lists.filter(|l| l.len() > 1).map(|_| (f, positions))
    })
}

/// Every call: (callee, arguments).
pub(super) fn calls(module: &Module) -> Vec<(Word, Vec<Option<Word>>)> {
    module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .filter(|i| i.class.opcode == Op::FunctionCall)
        .filter_map(|i| {
            let callee = id_ref(i.operands.first())?;
            Some((
                callee,
                i.operands[1..].iter().map(|o| id_ref(Some(o))).collect(),
            ))
        })
        .collect()
}

/// Appends a copy of function `fi` whose every id is fresh (its decorations copied with
/// them); returns the copy's id.
fn copy_function(module: &mut Module, fi: usize, ids: &mut Ids) -> Result<Word, SpirvError> {
    let mut copy = module.functions[fi].clone();
    let mut fresh: HashMap<Word, Word> = HashMap::new();
    for inst in copy.all_inst_iter() {
        if let Some(id) = inst.result_id {
            fresh.insert(id, ids.fresh()?);
        }
    }
    for inst in copy.all_inst_iter_mut() {
        if let Some(id) = inst.result_id.as_mut() {
            *id = fresh[id];
        }
        for op in &mut inst.operands {
            if let Operand::IdRef(x) = op
                && let Some(&y) = fresh.get(x)
            {
                *x = y;
            }
        }
    }
    let decorations: Vec<Instruction> = module
        .annotations
        .iter()
        .filter(|a| matches!(a.class.opcode, Op::Decorate | Op::DecorateId))
        .filter_map(|a| {
            let target = fresh.get(&id_ref(a.operands.first())?)?;
            let mut d = a.clone();
            d.operands[0] = Operand::IdRef(*target);
            Some(d)
        })
        .collect();
    module.annotations.extend(decorations);
    let id = copy
        .def
        .as_ref()
        .and_then(|d| d.result_id)
        .ok_or_else(|| SpirvError::Malformed {
            at_word: 0,
            detail: "a function without an id".to_owned(),
        })?;
    module.functions.push(copy);
    Ok(id)
}
