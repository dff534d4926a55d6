//! Array indices handed to functions, made constants for the descriptor array split
//! (`arrays`): each function that takes an index as a parameter is cloned for each constant
//! its calls give it, and a call that gives one known only at run time becomes a switch over
//! those clones (`dispatch`). Values are followed as glslang hands them: by value, or, in
//! older output, through a pointer to a variable of the caller's that it stored once.

use std::collections::{BTreeMap, HashMap, HashSet};

use rspirv::dr::{Function, Instruction, Module, Operand};
use rspirv::spirv::{Op, StorageClass, Word};

use super::SpirvError;
use super::array_decl::{Array, arrays_named, refused};
use super::entry::reached;
use super::index::{id_ref, literal};
use super::ops::{Ids, inst, int_constants, is_chain};

/// Calls through which an index may be handed on before the split gives up.
const MAX_CALL_DEPTH: usize = 64;

pub(super) fn function_id(f: &Function) -> Option<Word> {
    f.def.as_ref().and_then(|d| d.result_id)
}

/// What a value of a function is, as far as an index needs: a constant, whatever the caller
/// gives one of its parameters, or neither.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Value {
    Constant(Word),
    Param(usize),
    Unknown,
}

/// How the values of one function come about: glslang hands an `int` to a function by value
/// or, in older output, as a pointer to a variable of the caller's that it stored once.
pub(super) struct Facts<'m> {
    /// Parameters by id: position, and whether a pointer.
    params: HashMap<Word, (usize, bool)>,
    pub(super) defs: HashMap<Word, &'m Instruction>,
    /// The values stored through each pointer.
    stores: HashMap<Word, Vec<Word>>,
    constants: &'m HashMap<Word, u32>,
}

impl<'m> Facts<'m> {
    pub(super) fn new(
        module: &'m Module,
        f: &'m Function,
        constants: &'m HashMap<Word, u32>,
    ) -> Self {
        let pointers = global_ids(module, Op::TypePointer);
        let params = f
            .parameters
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                Some((
                    p.result_id?,
                    (i, p.result_type.is_some_and(|t| pointers.contains(&t))),
                ))
            })
            .collect();
        let mut defs = HashMap::new();
        let mut stores: HashMap<Word, Vec<Word>> = HashMap::new();
        for i in f.all_inst_iter() {
            if let Some(id) = i.result_id {
                defs.insert(id, i);
            }
            if i.class.opcode == Op::Store
                && let (Some(ptr), Some(v)) =
                    (id_ref(i.operands.first()), id_ref(i.operands.get(1)))
            {
                stores.entry(ptr).or_default().push(v);
            }
        }
        Facts {
            params,
            defs,
            stores,
            constants,
        }
    }

    pub(super) fn value(&self, id: Word, depth: usize) -> Value {
        if self.constants.contains_key(&id) {
            return Value::Constant(id);
        }
        if let Some(&(pos, false)) = self.params.get(&id) {
            return Value::Param(pos);
        }
        match self.defs.get(&id) {
            Some(i) if i.class.opcode == Op::Load && depth > 0 => {
                id_ref(i.operands.first()).map_or(Value::Unknown, |p| self.pointee(p, depth - 1))
            }
            _ => Value::Unknown,
        }
    }

    /// The value behind a pointer the function only reads: a parameter's, or a local
    /// variable's stored once (or initialized and never stored).
    fn pointee(&self, ptr: Word, depth: usize) -> Value {
        let stored = self.stores.get(&ptr).map_or(&[][..], |s| &s[..]);
        if let Some(&(pos, true)) = self.params.get(&ptr) {
            return if stored.is_empty() {
                Value::Param(pos)
            } else {
                Value::Unknown
            };
        }
        let Some(var) = self
            .defs
            .get(&ptr)
            .filter(|v| v.class.opcode == Op::Variable)
        else {
            return Value::Unknown;
        };
        match (id_ref(var.operands.get(1)), stored) {
            (Some(init), []) => self.value(init, depth),
            (None, [v]) => self.value(*v, depth),
            _ => Value::Unknown,
        }
    }

    /// The value a call gives its argument `arg`: the pointee where the argument is a
    /// pointer.
    fn argument(&self, arg: Word, depth: usize) -> Value {
        match self.value(arg, depth) {
            Value::Unknown => self.pointee(arg, depth),
            v => v,
        }
    }
}

/// The ids of the module's global instructions of opcode `op` (its pointer types, say).
fn global_ids(module: &Module, op: Op) -> HashSet<Word> {
    module
        .types_global_values
        .iter()
        .filter(|t| t.class.opcode == op)
        .filter_map(|t| t.result_id)
        .collect()
}

/// How deep a value is followed through loads and stores.
pub(super) const VALUE_DEPTH: usize = 16;

/// The parameters, by function and position, that reach an array's index: the value of the
/// first index of an access chain into one, or handed on to such a parameter of another
/// function; each with the fewest elements of the arrays it indexes.
fn index_params(
    module: &Module,
    arrays: &BTreeMap<Word, Array>,
    constants: &HashMap<Word, u32>,
) -> HashMap<Word, HashMap<usize, u32>> {
    let facts: Vec<(Word, &Function, Facts)> = module
        .functions
        .iter()
        .filter_map(|f| Some((function_id(f)?, f, Facts::new(module, f, constants))))
        .collect();
    let mut marked: HashMap<Word, HashMap<usize, u32>> = HashMap::new();
    let mark = |marked: &mut HashMap<Word, HashMap<usize, u32>>, f: Word, pos: usize, len: u32| {
        let at = marked.entry(f).or_default().entry(pos).or_insert(u32::MAX);
        let grew = len < *at;
        *at = (*at).min(len);
        grew
    };
    for (fid, f, facts) in &facts {
        for i in f.all_inst_iter().filter(|i| is_chain(i)) {
            if let Some(a) = id_ref(i.operands.first()).and_then(|b| arrays.get(&b))
                && let Some(index) = id_ref(i.operands.get(1))
                && let Value::Param(pos) = facts.value(index, VALUE_DEPTH)
            {
                mark(&mut marked, *fid, pos, a.len);
            }
        }
    }
    loop {
        let mut grew = false;
        for (fid, f, facts) in &facts {
            for i in f
                .all_inst_iter()
                .filter(|i| i.class.opcode == Op::FunctionCall)
            {
                let Some(callee) = id_ref(i.operands.first()) else {
                    continue;
                };
                let Some(positions) = marked.get(&callee).cloned() else {
                    continue;
                };
                for (pos, len) in positions {
                    if let Some(arg) = id_ref(i.operands.get(pos + 1))
                        && let Value::Param(p) = facts.argument(arg, VALUE_DEPTH)
                    {
                        grew |= mark(&mut marked, *fid, p, len);
                    }
                }
            }
        }
        if !grew {
            return marked;
        }
    }
}

/// A function to clone: the callee, and the constant each index parameter takes.
type CloneKey = (Word, Vec<(usize, Word)>);

/// What becomes of one call that hands an index to a function.
enum Action {
    /// Every index it gives is a constant: it calls the clone for them.
    Redirect(CloneKey),
    /// One index is known only at run time: the call becomes a switch on it whose case `k`
    /// calls the clone for `k` (an index past the array is undefined behaviour; it takes
    /// case 0).
    Dispatch {
        selector: Selector,
        cases: Vec<CloneKey>,
    },
}

/// The value a dispatch switches on: the argument itself, or what its pointer holds.
enum Selector {
    Value(Word),
    Load { pointer: Word, ty: Word },
}

/// An instruction's place: function, block, instruction.
type Place = (usize, usize, usize);

/// Clones each function that takes an array index for every set of constants its calls give
/// it, and turns a call that gives an index known only at run time (a loop over the planes)
/// into a switch over the clones, until no call hands an index to a function; the
/// originals no entry point reaches any more are removed.
pub(super) fn specialize_index_params(
    module: &mut Module,
    arrays: &BTreeMap<Word, Array>,
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    let mut constants = int_constants(module);
    for _ in 0..MAX_CALL_DEPTH {
        let marked = index_params(module, arrays, &constants);
        if marked.is_empty() {
            return Ok(());
        }
        let (actions, needed) = plan_round(module, arrays, &marked, &mut constants, ids)?;
        if actions.is_empty() {
            return Err(refused(format!(
                "an index of {} is handed between functions in a cycle",
                arrays_named(arrays)
            )));
        }
        module.types_global_values.extend(needed);
        let (clones, added) = make_clones(module, &actions, ids)?;
        apply(module, actions, &clones, ids)?;
        for (clone, annotations) in added {
            module.functions.push(clone);
            module.annotations.extend(annotations);
        }
        remove_unreached(module);
    }
    Err(refused(format!(
        "an index of {} is handed through more than {MAX_CALL_DEPTH} calls",
        arrays_named(arrays)
    )))
}

/// The actions of a round, and the constants their switches need.
type Round = (Vec<(Place, Action)>, Vec<Instruction>);

/// What becomes of each call that hands an index to a function this round (a call whose
/// caller takes the index itself waits for the caller's clones), and the constants the
/// switches need.
fn plan_round(
    module: &Module,
    arrays: &BTreeMap<Word, Array>,
    marked: &HashMap<Word, HashMap<usize, u32>>,
    constants: &mut HashMap<Word, u32>,
    ids: &mut Ids,
) -> Result<Round, SpirvError> {
    let mut actions = Vec::new();
    let mut needed: Vec<Instruction> = Vec::new();
    let known = constants.clone();
    for (fi, f) in module.functions.iter().enumerate() {
        let facts = Facts::new(module, f, &known);
        for (bi, b) in f.blocks.iter().enumerate() {
            for (ii, i) in b.instructions.iter().enumerate() {
                if i.class.opcode != Op::FunctionCall {
                    continue;
                }
                let Some(callee) = id_ref(i.operands.first()) else {
                    continue;
                };
                let Some(positions) = marked.get(&callee) else {
                    continue;
                };
                let call = Call {
                    module,
                    facts: &facts,
                    callee,
                    operands: &i.operands,
                };
                if let Some(action) = call.plan(positions, arrays, constants, ids, &mut needed)? {
                    actions.push(((fi, bi, ii), action));
                }
            }
        }
    }
    Ok((actions, needed))
}

/// One call to a function that takes an index.
struct Call<'a> {
    module: &'a Module,
    facts: &'a Facts<'a>,
    callee: Word,
    operands: &'a [Operand],
}

impl Call<'_> {
    /// What becomes of the call; None while an index it gives is its caller's parameter.
    fn plan(
        &self,
        positions: &HashMap<usize, u32>,
        arrays: &BTreeMap<Word, Array>,
        constants: &mut HashMap<Word, u32>,
        ids: &mut Ids,
        needed: &mut Vec<Instruction>,
    ) -> Result<Option<Action>, SpirvError> {
        let callee = self.callee;
        let mut key: Vec<(usize, Word)> = Vec::new();
        let mut run_time: Vec<(usize, u32, Word)> = Vec::new();
        let mut positions: Vec<(usize, u32)> = positions.iter().map(|(&p, &l)| (p, l)).collect();
        positions.sort_unstable();
        for (pos, len) in positions {
            let arg = id_ref(self.operands.get(pos + 1)).unwrap_or(0);
            match self.facts.argument(arg, VALUE_DEPTH) {
                Value::Constant(c) => key.push((pos, c)),
                // The caller is cloned first; its clones give a constant here.
                Value::Param(_) => return Ok(None),
                Value::Unknown => run_time.push((pos, len, arg)),
            }
        }
        let [(pos, len, arg)] = run_time[..] else {
            if run_time.is_empty() {
                return Ok(Some(Action::Redirect((callee, key))));
            }
            return Err(refused(format!(
                "a call to function %{callee} gives more than one index of {} known only at run time",
                arrays_named(arrays)
            )));
        };
        let selector = selector(self.module, pos, arg, callee);
        let ty = match selector {
            Selector::Value(v) => self.facts.defs.get(&v).and_then(|d| d.result_type),
            Selector::Load { ty, .. } => Some(ty),
        }
        .ok_or_else(|| {
            refused(format!(
                "the index %{arg} handed to function %{callee} has no type"
            ))
        })?;
        let mut cases = Vec::new();
        for k in 0..len.min(MAX_CASES) {
            let c = constant(self.module, constants, ids, ty, k, needed)?;
            let mut key = key.clone();
            key.push((pos, c));
            key.sort_unstable();
            cases.push((callee, key));
        }
        Ok(Some(Action::Dispatch { selector, cases }))
    }
}

/// The clone made for each key, and the clones with the decorations of their ids.
type Clones = (BTreeMap<CloneKey, Word>, Vec<(Function, Vec<Instruction>)>);

/// A clone of each function the actions call.
fn make_clones(
    module: &Module,
    actions: &[(Place, Action)],
    ids: &mut Ids,
) -> Result<Clones, SpirvError> {
    let mut clones: BTreeMap<CloneKey, Word> = BTreeMap::new();
    let mut added = Vec::new();
    let keys = actions.iter().flat_map(|(_, a)| match a {
        Action::Redirect(key) => std::slice::from_ref(key),
        Action::Dispatch { cases, .. } => &cases[..],
    });
    for key in keys {
        if clones.contains_key(key) {
            continue;
        }
        let original = module
            .functions
            .iter()
            .find(|f| function_id(f) == Some(key.0))
            .ok_or_else(|| refused(format!("a call to %{}, which the module lacks", key.0)))?;
        let (clone, annotations) = clone_function(module, original, &key.1, ids)?;
        clones.insert(key.clone(), function_id(&clone).unwrap_or(0));
        added.push((clone, annotations));
    }
    Ok((clones, added))
}

/// Redirects each call to its clone or makes it a switch over them.
fn apply(
    module: &mut Module,
    mut actions: Vec<(Place, Action)>,
    clones: &BTreeMap<CloneKey, Word>,
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    let voids = global_ids(module, Op::TypeVoid);
    // Last first, so that splitting a block leaves the places of the others.
    actions.sort_by_key(|a| std::cmp::Reverse(a.0));
    for ((fi, bi, ii), action) in actions {
        match action {
            Action::Redirect(key) => {
                module.functions[fi].blocks[bi].instructions[ii].operands[0] =
                    Operand::IdRef(clones[&key]);
            }
            Action::Dispatch { selector, cases } => {
                let targets: Vec<Word> = cases.iter().map(|k| clones[k]).collect();
                let values: Vec<u32> = (0..targets.len() as u32).collect();
                let f = &mut module.functions[fi];
                let (selector, ii) = selector_id(f, bi, ii, selector, ids)?;
                let returns = f.blocks[bi].instructions[ii]
                    .result_type
                    .is_some_and(|t| !voids.contains(&t));
                super::dispatch::switch_call(
                    f,
                    (bi, ii),
                    selector,
                    (&values, &targets),
                    returns,
                    ids,
                )?;
            }
        }
    }
    Ok(())
}

/// The most cases a dispatch switches over (the fewest elements of the arrays indexed).
const MAX_CASES: u32 = 64;

/// What a dispatch on the argument `arg` of a call to `callee` switches on.
fn selector(module: &Module, pos: usize, arg: Word, callee: Word) -> Selector {
    let param_ty = module
        .functions
        .iter()
        .find(|g| function_id(g) == Some(callee))
        .and_then(|g| g.parameters.get(pos)?.result_type);
    let pointee = param_ty.and_then(|t| {
        module
            .types_global_values
            .iter()
            .find(|p| p.result_id == Some(t) && p.class.opcode == Op::TypePointer)
            .and_then(|p| id_ref(p.operands.get(1)))
    });
    match pointee {
        Some(ty) => Selector::Load { pointer: arg, ty },
        None => Selector::Value(arg),
    }
}

/// The selector's id, loaded just before the call where it is behind a pointer, and the
/// call's place after that.
fn selector_id(
    f: &mut Function,
    bi: usize,
    ii: usize,
    selector: Selector,
    ids: &mut Ids,
) -> Result<(Word, usize), SpirvError> {
    Ok(match selector {
        Selector::Value(v) => (v, ii),
        Selector::Load { pointer, ty } => {
            let id = ids.fresh()?;
            f.blocks[bi].instructions.insert(
                ii,
                inst(Op::Load, Some(ty), Some(id), vec![Operand::IdRef(pointer)]),
            );
            (id, ii + 1)
        }
    })
}

/// The id of the constant `value` of integer type `ty`, found or made (queued in `needed`).
fn constant(
    module: &Module,
    constants: &mut HashMap<Word, u32>,
    ids: &mut Ids,
    ty: Word,
    value: u32,
    needed: &mut Vec<Instruction>,
) -> Result<Word, SpirvError> {
    let found = module
        .types_global_values
        .iter()
        .chain(needed.iter())
        .find(|c| {
            c.class.opcode == Op::Constant
                && c.result_type == Some(ty)
                && literal(c.operands.first()) == Some(value)
        })
        .and_then(|c| c.result_id);
    if let Some(id) = found {
        return Ok(id);
    }
    let id = ids.fresh()?;
    constants.insert(id, value);
    needed.push(inst(
        Op::Constant,
        Some(ty),
        Some(id),
        vec![Operand::LiteralBit32(value)],
    ));
    Ok(id)
}

/// A copy of `f` under fresh ids in which each parameter of `given` (position, constant)
/// takes its constant: a value parameter is replaced by it, a pointer parameter by a local
/// variable initialized with it. The decorations of `f`'s ids are copied to the copy's.
fn clone_function(
    module: &Module,
    f: &Function,
    given: &[(usize, Word)],
    ids: &mut Ids,
) -> Result<(Function, Vec<Instruction>), SpirvError> {
    let pointers = global_ids(module, Op::TypePointer);
    let mut subst: HashMap<Word, Word> = HashMap::new();
    let mut locals: Vec<Instruction> = Vec::new();
    for &(pos, constant) in given {
        let Some(param) = f.parameters.get(pos) else {
            continue;
        };
        let (Some(id), Some(ty)) = (param.result_id, param.result_type) else {
            continue;
        };
        if pointers.contains(&ty) {
            let var = ids.fresh()?;
            locals.push(inst(
                Op::Variable,
                Some(ty),
                Some(var),
                vec![
                    Operand::StorageClass(StorageClass::Function),
                    Operand::IdRef(constant),
                ],
            ));
            subst.insert(id, var);
        } else {
            subst.insert(id, constant);
        }
    }
    let mut map: HashMap<Word, Word> = HashMap::new();
    for i in f.all_inst_iter() {
        if let Some(id) = i.result_id {
            map.insert(id, ids.fresh()?);
        }
    }
    let remap = |i: &Instruction| {
        let mut i = i.clone();
        i.result_id = i.result_id.map(|id| map[&id]);
        for o in &mut i.operands {
            if let Operand::IdRef(x) = o {
                *x = subst.get(x).or_else(|| map.get(x)).copied().unwrap_or(*x);
            }
        }
        i
    };
    let mut clone = f.clone();
    clone.def = f.def.as_ref().map(remap);
    clone.end = f.end.as_ref().map(remap);
    clone.parameters = f.parameters.iter().map(remap).collect();
    for (b, old) in clone.blocks.iter_mut().zip(&f.blocks) {
        b.label = old.label.as_ref().map(remap);
        b.instructions = old.instructions.iter().map(remap).collect();
    }
    // Function variables open the first block.
    if let Some(first) = clone.blocks.first_mut() {
        first.instructions.splice(0..0, locals);
    }
    let annotations = module
        .annotations
        .iter()
        .filter(|a| {
            a.class.opcode == Op::Decorate
                && id_ref(a.operands.first()).is_some_and(|t| map.contains_key(&t))
        })
        .map(remap)
        .collect();
    Ok((clone, annotations))
}

/// Removes the functions no entry point reaches, with their ids' names and decorations.
fn remove_unreached(module: &mut Module) {
    let roots: HashSet<Word> = module
        .entry_points
        .iter()
        .filter_map(|e| id_ref(e.operands.get(1)))
        .collect();
    let kept = reached(module, roots);
    let removed: HashSet<Word> = module
        .functions
        .iter()
        .filter(|f| function_id(f).is_some_and(|id| !kept.contains(&id)))
        .flat_map(|f| f.all_inst_iter())
        .filter_map(|i| i.result_id)
        .collect();
    if removed.is_empty() {
        return;
    }
    module
        .functions
        .retain(|f| function_id(f).is_none_or(|id| kept.contains(&id)));
    let targets_removed =
        |i: &Instruction| id_ref(i.operands.first()).is_some_and(|t| removed.contains(&t));
    module.annotations.retain(|i| !targets_removed(i));
    module.debug_names.retain(|i| !targets_removed(i));
}
