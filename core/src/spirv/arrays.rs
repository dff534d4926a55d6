//! Descriptor arrays indexed by constants (and arrays of one, however indexed), split into one
//! variable per element. wgpu binds an
//! array of descriptors only as a binding array, whose dynamic indexing its Vulkan backend
//! turns on for some descriptor types and never for storage images, and programs mostly index
//! such arrays with constants: FFmpeg's filters keep one image per plane and hand the plane to
//! a function as a constant argument. So each function that takes an array index as a
//! parameter is cloned for each constant its calls give (and the functions it hands the index
//! on to, in turn); then every element the code names becomes a variable of its own. Element 0
//! keeps the array's binding and element `k` takes [`element_binding`]`(binding, k)`, which the
//! lowering decodes with [`binding_element`]. An index known only at run time, or an array
//! used other than through access chains, is refused by name.

use std::collections::{BTreeMap, HashMap};

use rspirv::binary::Assemble;
use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Decoration, Op, StorageClass, Word};

use super::SpirvError;
use super::array_decl::{Array, refused};
use super::index::{self, first_free_id, id_ref, literal};
use super::index_params::{Facts, VALUE_DEPTH, Value};
use super::ops::{Ids, inst, int_constants, is_chain, type_id};

/// Bits of a split binding that hold the array's own binding; the element is above them.
const ELEMENT_SHIFT: u32 = 20;

/// The binding the split gives element `element` of the array at `binding`.
pub fn element_binding(binding: u32, element: u32) -> u32 {
    binding | (element << ELEMENT_SHIFT)
}

/// The array binding and the element of a binding [`element_binding`] made (element 0 for any
/// other binding).
pub fn binding_element(binding: u32) -> (u32, u32) {
    (
        binding & ((1 << ELEMENT_SHIFT) - 1),
        binding >> ELEMENT_SHIFT,
    )
}

/// The module with its descriptor arrays split, or None where it has none (the words are
/// then used as they are).
pub fn split_descriptor_arrays(words: &[u32]) -> Result<Option<Vec<u32>>, SpirvError> {
    let mut loaded = index::load(words)?;
    let module = &mut loaded.module;
    let arrays = descriptor_arrays(module)?;
    if arrays.is_empty() {
        return Ok(None);
    }
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    super::index_params::specialize_index_params(module, &arrays, &mut ids)?;
    split(module, &arrays, &mut ids)?;
    if let Some(h) = module.header.as_mut() {
        h.bound = h.bound.max(ids.next);
    }
    Ok(Some(module.assemble()))
}

/// The descriptor variables that are arrays of a constant length.
fn descriptor_arrays(module: &Module) -> Result<BTreeMap<Word, Array>, SpirvError> {
    let globals: HashMap<Word, &Instruction> = module
        .types_global_values
        .iter()
        .filter_map(|i| Some((i.result_id?, i)))
        .collect();
    let decoration = |id: Word, d: Decoration| {
        module.annotations.iter().find_map(|a| {
            (a.class.opcode == Op::Decorate
                && id_ref(a.operands.first()) == Some(id)
                && a.operands.get(1) == Some(&Operand::Decoration(d)))
            .then(|| literal(a.operands.get(2)))
            .flatten()
        })
    };
    let mut out = BTreeMap::new();
    for v in &module.types_global_values {
        let (Op::Variable, Some(id), Some(ptr)) = (v.class.opcode, v.result_id, v.result_type)
        else {
            continue;
        };
        let class = match v.operands.first() {
            Some(&Operand::StorageClass(
                c @ (StorageClass::Uniform
                | StorageClass::UniformConstant
                | StorageClass::StorageBuffer),
            )) => c,
            _ => continue,
        };
        let Some(array) = globals
            .get(&ptr)
            .filter(|p| p.class.opcode == Op::TypePointer)
            .and_then(|p| globals.get(&id_ref(p.operands.get(1))?))
            .filter(|t| t.class.opcode == Op::TypeArray)
        else {
            continue;
        };
        let (Some(element_ty), Some(len)) = (
            id_ref(array.operands.first()),
            id_ref(array.operands.get(1))
                .and_then(|l| globals.get(&l))
                .filter(|l| l.class.opcode == Op::Constant)
                .and_then(|l| literal(l.operands.first())),
        ) else {
            continue;
        };
        let (Some(set), Some(binding)) = (
            decoration(id, Decoration::DescriptorSet),
            decoration(id, Decoration::Binding),
        ) else {
            continue;
        };
        // An array of one is split too: it is one descriptor, and the rest of the rewrite
        // (a combined image sampler's split into an image and a sampler) takes single
        // variables only.
        if len == 0 {
            continue;
        }
        let name = module
            .debug_names
            .iter()
            .find(|n| n.class.opcode == Op::Name && id_ref(n.operands.first()) == Some(id))
            .and_then(|n| match n.operands.get(1) {
                Some(Operand::LiteralString(s)) => Some(s.clone()),
                _ => None,
            })
            .unwrap_or_else(|| format!("%{id}"));
        if binding >> ELEMENT_SHIFT != 0 || len > 1 << (32 - ELEMENT_SHIFT) {
            return Err(refused(format!(
                "set {set} binding {binding} ({name}, {len} elements): the split numbers bindings below {} with at most {} elements",
                1u32 << ELEMENT_SHIFT,
                1u32 << (32 - ELEMENT_SHIFT)
            )));
        }
        out.insert(
            id,
            Array {
                set,
                binding,
                len,
                class,
                element_ty,
                name,
            },
        );
    }
    Ok(out)
}

/// Every access chain into an array becomes one into (or is replaced by) the variable of the
/// element its constant first index names; the arrays leave the module.
fn split(
    module: &mut Module,
    arrays: &BTreeMap<Word, Array>,
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    let constants = int_constants(module);
    let mut elements: BTreeMap<(Word, u32), Word> = BTreeMap::new();
    // The element each chain into an array names, by the chain's id.
    let mut chains: HashMap<Word, (Word, u32)> = HashMap::new();
    for f in &module.functions {
        let facts = Facts::new(module, f, &constants);
        for i in f.all_inst_iter() {
            let chain_base = if is_chain(i) {
                id_ref(i.operands.first())
            } else {
                None
            };
            for (n, o) in i.operands.iter().enumerate() {
                let Operand::IdRef(x) = o else { continue };
                let Some(a) = arrays.get(x) else { continue };
                if n != 0 || chain_base != Some(*x) || i.result_id.is_none() {
                    return Err(refused(format!(
                        "set {} binding {} ({}) is used whole by Op{:?}, not element by element",
                        a.set, a.binding, a.name, i.class.opcode
                    )));
                }
                let index = id_ref(i.operands.get(1)).unwrap_or(0);
                let k = match facts.value(index, VALUE_DEPTH) {
                    Value::Constant(c) => constants[&c],
                    // An array of one has one element to name: any other index is out of
                    // bounds, which Vulkan leaves undefined.
                    _ if a.len == 1 => 0,
                    _ => {
                        return Err(refused(format!(
                            "set {} binding {} ({}) is indexed by a value known only at run time (%{index}); wgpu's binding arrays are not used",
                            a.set, a.binding, a.name
                        )));
                    }
                };
                if k >= a.len {
                    return Err(refused(format!(
                        "set {} binding {} ({}) has {} elements and the code names element {k}",
                        a.set, a.binding, a.name, a.len
                    )));
                }
                if let std::collections::btree_map::Entry::Vacant(e) = elements.entry((*x, k)) {
                    e.insert(ids.fresh()?);
                }
                chains.insert(i.result_id.unwrap_or(0), (*x, k));
            }
        }
    }
    declare_elements(module, arrays, &elements, ids)?;
    // Chains of one index are the element's variable; longer ones continue from it.
    let mut replaced: HashMap<Word, Word> = HashMap::new();
    for f in &mut module.functions {
        for b in &mut f.blocks {
            b.instructions.retain_mut(|i| {
                let Some(&(array, k)) = i.result_id.and_then(|id| chains.get(&id)) else {
                    return true;
                };
                let var = elements[&(array, k)];
                if i.operands.len() == 2 {
                    if let Some(id) = i.result_id {
                        replaced.insert(id, var);
                    }
                    return false;
                }
                i.operands.remove(1);
                i.operands[0] = Operand::IdRef(var);
                true
            });
        }
    }
    for i in module.all_inst_iter_mut() {
        for o in &mut i.operands {
            if let Operand::IdRef(x) = o
                && let Some(&v) = replaced.get(x)
            {
                *x = v;
            }
        }
    }
    Ok(())
}

/// The element variables, after the pointer types they need, with the array's decorations
/// (the binding made the element's) and names; the arrays, their decorations and names go, and
/// each entry point's interface lists the elements where it listed the array.
fn declare_elements(
    module: &mut Module,
    arrays: &BTreeMap<Word, Array>,
    elements: &BTreeMap<(Word, u32), Word>,
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    let mut added: Vec<Instruction> = Vec::new();
    let mut vars: Vec<Instruction> = Vec::new();
    let mut annotations: Vec<Instruction> = Vec::new();
    let mut names: Vec<Instruction> = Vec::new();
    for (&(array, k), &var) in elements {
        let a = &arrays[&array];
        let ptr = type_id(
            module,
            &mut added,
            ids,
            Op::TypePointer,
            vec![Operand::StorageClass(a.class), Operand::IdRef(a.element_ty)],
        )?;
        vars.push(inst(
            Op::Variable,
            Some(ptr),
            Some(var),
            vec![Operand::StorageClass(a.class)],
        ));
        for d in module
            .annotations
            .iter()
            .filter(|d| d.class.opcode == Op::Decorate && id_ref(d.operands.first()) == Some(array))
        {
            let mut d = d.clone();
            d.operands[0] = Operand::IdRef(var);
            if d.operands.get(1) == Some(&Operand::Decoration(Decoration::Binding))
                && let Some(b) = d.operands.get_mut(2)
            {
                *b = Operand::LiteralBit32(element_binding(a.binding, k));
            }
            annotations.push(d);
        }
        names.push(super::ops::name(var, format!("{}_{k}", a.name)));
    }
    let gone =
        |i: &Instruction| id_ref(i.operands.first()).is_some_and(|t| arrays.contains_key(&t));
    module.annotations.retain(|i| !gone(i));
    module.annotations.extend(annotations);
    module.debug_names.retain(|i| !gone(i));
    module.debug_names.extend(names);
    module
        .types_global_values
        .retain(|i| i.result_id.is_none_or(|id| !arrays.contains_key(&id)));
    module.types_global_values.extend(added);
    module.types_global_values.extend(vars);
    for e in &mut module.entry_points {
        let mut operands = Vec::with_capacity(e.operands.len());
        for o in e.operands.drain(..) {
            match o {
                Operand::IdRef(x) if arrays.contains_key(&x) => operands.extend(
                    elements
                        .range((x, 0)..=(x, u32::MAX))
                        .map(|(_, &v)| Operand::IdRef(v)),
                ),
                o => operands.push(o),
            }
        }
        e.operands = operands;
    }
    Ok(())
}
