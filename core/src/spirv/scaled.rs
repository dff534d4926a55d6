//! Vertex attributes in scaled formats (`USCALED`, `SSCALED`: integers read as floats, 3 as
//! 3.0), in the shader: wgpu has no such vertex format, so the replay fetches the attribute
//! in the integer format of the same width (`Uint16x2` for `R16G16_USCALED`) and this rewrite
//! gives the input at that location the integer type of the same shape, converting each value
//! loaded from it (`OpConvertUToF`, `OpConvertSToF`) to the float the shader declared. Values
//! the attribute lacks are filled as Vulkan fills them (0, 0, 1), the same numbers either way.
//! Loads through an access chain into the input (one component) are converted the same way;
//! any other use of the input is refused by name.
//!
//! Packed 2-10-10-10 formats (`A2B10G10R10_SNORM_PACK32`: OpenGL's packed normals, which zink
//! passes on) are fetched as their 32-bit word (`Uint32`); each whole load of the input takes
//! its channels apart (`OpBitFieldSExtract`, `OpBitFieldUExtract`) and converts each as Vulkan
//! does: normalized signed values divided by 511 (or 1 for the 2-bit alpha) and clamped at -1,
//! unsigned by 1023 (or 3), scaled ones as they are.

use std::collections::HashMap;

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Decoration, Op, StorageClass, Word};

use super::index::{first_free_id, id_ref, literal};
use super::ops::{Ids, inst, int32, type_id, vector};
use super::{IntegerFetch, SpirvError};

fn unsupported(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "a vertex input in a scaled format",
        detail,
    }
}

/// A float type's shape: its component count (1 for a scalar), and whether it is one.
fn float_shape(module: &Module, ty: Word) -> Option<u32> {
    let def = |id: Word| {
        module
            .types_global_values
            .iter()
            .find(|i| i.result_id == Some(id))
    };
    let t = def(ty)?;
    match t.class.opcode {
        Op::TypeFloat if literal(t.operands.first()) == Some(32) => Some(1),
        Op::TypeVector => {
            let c = def(id_ref(t.operands.first())?)?;
            (c.class.opcode == Op::TypeFloat && literal(c.operands.first()) == Some(32))
                .then(|| literal(t.operands.get(1)))
                .flatten()
        }
        _ => None,
    }
}

/// Gives each `Input` variable at a location of `scaled` the integer type it is fetched as (of
/// its float type's shape; one word for a packed format), and converts every value loaded
/// from it back to that float type.
pub fn scaled_inputs(
    module: &mut Module,
    scaled: &[(u32, IntegerFetch)],
) -> Result<(), SpirvError> {
    if scaled.is_empty() {
        return Ok(());
    }
    let mut ids = Ids {
        next: first_free_id(module).ok_or(SpirvError::IdsExhausted { bound: u32::MAX })?,
    };
    let mut added: Vec<Instruction> = Vec::new();
    let (vars, packed) = retype_inputs(module, scaled, &mut added, &mut ids)?;
    if vars.is_empty() && packed.is_empty() {
        return Ok(());
    }
    let mut unpack = if packed.is_empty() {
        None
    } else {
        Some(Unpack::new(module, &mut added, &mut ids)?)
    };
    // Pointers into a rewritten input: the variable itself (whole) and chains into it (one
    // component), with the float and int types a load through each gives.
    let mut pointers: HashMap<Word, (Word, Word, bool)> = vars
        .iter()
        .map(|(&v, x)| (v, (x.whole.0, x.whole.1, x.signed)))
        .collect();
    for f in &mut module.functions {
        for b in &mut f.blocks {
            let mut out = Vec::with_capacity(b.instructions.len());
            for mut i in std::mem::take(&mut b.instructions) {
                let first = id_ref(i.operands.first());
                match i.class.opcode {
                    Op::AccessChain | Op::InBoundsAccessChain
                        if first.is_some_and(|p| vars.contains_key(&p)) =>
                    {
                        let x = &vars[&first.unwrap_or_default()];
                        if i.operands.len() != 2 {
                            return Err(unsupported(format!(
                                "%{} chains more than one index into the input",
                                i.result_id.unwrap_or(0)
                            )));
                        }
                        i.result_type = Some(x.component.2);
                        if let Some(id) = i.result_id {
                            pointers.insert(id, (x.component.0, x.component.1, x.signed));
                        }
                        out.push(i);
                    }
                    Op::Load if first.is_some_and(|p| packed.contains_key(&p)) => {
                        let (float, n, fetch) = packed[&first.unwrap_or_default()];
                        let (Some(result), Some(unpack)) = (i.result_id, unpack.as_mut()) else {
                            out.push(i);
                            continue;
                        };
                        let word = ids.fresh()?;
                        i.result_id = Some(word);
                        i.result_type = Some(unpack.uint);
                        out.push(i);
                        let fetched = (word, float, n, fetch);
                        unpack.emit(fetched, result, &mut out, &mut added, &mut ids)?;
                    }
                    Op::Load if first.is_some_and(|p| pointers.contains_key(&p)) => {
                        let (float, int, signed) = pointers[&first.unwrap_or_default()];
                        let (Some(result), Some(_)) = (i.result_id, i.result_type) else {
                            out.push(i);
                            continue;
                        };
                        let loaded = ids.fresh()?;
                        i.result_id = Some(loaded);
                        i.result_type = Some(int);
                        out.push(i);
                        let convert = if signed {
                            Op::ConvertSToF
                        } else {
                            Op::ConvertUToF
                        };
                        out.push(inst(
                            convert,
                            Some(float),
                            Some(result),
                            vec![Operand::IdRef(loaded)],
                        ));
                    }
                    _ => {
                        if let Some(p) = i.operands.iter().find_map(|o| match o {
                            Operand::IdRef(x)
                                if pointers.contains_key(x) || packed.contains_key(x) =>
                            {
                                Some(*x)
                            }
                            _ => None,
                        }) {
                            return Err(unsupported(format!(
                                "Op{:?} uses the input %{p} other than by loading it",
                                i.class.opcode
                            )));
                        }
                        out.push(i);
                    }
                }
            }
            b.instructions = out;
        }
    }
    // A type goes after what it names and before what names it: the new types go last (an
    // existing vector they name may come late, as zink interleaves types and variables), and
    // the inputs that now point to them move after them.
    let (moved, kept): (Vec<Instruction>, Vec<Instruction>) =
        std::mem::take(&mut module.types_global_values)
            .into_iter()
            .partition(|i| {
                i.result_id
                    .is_some_and(|id| vars.contains_key(&id) || packed.contains_key(&id))
            });
    module.types_global_values = kept;
    module.types_global_values.extend(added);
    module.types_global_values.extend(moved);
    if let Some(h) = module.header.as_mut() {
        h.bound = h.bound.max(ids.next);
    }
    Ok(())
}

/// A rewritten input: the (float, int) types of a value loaded whole, and the (float, int,
/// pointer) types of one component.
struct Var {
    whole: (Word, Word),
    component: (Word, Word, Word),
    signed: bool,
}

/// Packed inputs: their float type, its component count, and the packing.
type Packed = HashMap<Word, (Word, u32, IntegerFetch)>;

/// Each input at a location of `scaled` given the integer type it is fetched as: the scaled
/// ones by variable, and the packed ones (one word each).
fn retype_inputs(
    module: &mut Module,
    scaled: &[(u32, IntegerFetch)],
    added: &mut Vec<Instruction>,
    ids: &mut Ids,
) -> Result<(HashMap<Word, Var>, Packed), SpirvError> {
    let locations: HashMap<Word, u32> = module
        .annotations
        .iter()
        .filter(|a| {
            a.class.opcode == Op::Decorate
                && a.operands.get(1) == Some(&Operand::Decoration(Decoration::Location))
        })
        .filter_map(|a| Some((id_ref(a.operands.first())?, literal(a.operands.get(2))?)))
        .collect();
    let pointee = |module: &Module, ptr: Word| -> Option<Word> {
        module
            .types_global_values
            .iter()
            .find(|i| i.result_id == Some(ptr) && i.class.opcode == Op::TypePointer)
            .and_then(|p| id_ref(p.operands.get(1)))
    };
    // Packed inputs: their float type, its component count, and the packing.
    let mut packed: Packed = HashMap::new();
    let mut vars: HashMap<Word, Var> = HashMap::new();
    let globals: Vec<(usize, Word, Word)> = module
        .types_global_values
        .iter()
        .enumerate()
        .filter(|(_, i)| {
            i.class.opcode == Op::Variable
                && i.operands.first() == Some(&Operand::StorageClass(StorageClass::Input))
        })
        .filter_map(|(n, i)| Some((n, i.result_id?, i.result_type?)))
        .collect();
    for (n, var, ptr) in globals {
        let Some(location) = locations.get(&var) else {
            continue;
        };
        let Some(&(_, fetch)) = scaled.iter().find(|(l, _)| l == location) else {
            continue;
        };
        let float = pointee(module, ptr)
            .ok_or_else(|| unsupported(format!("input %{var} has no pointer type")))?;
        let shape = float_shape(module, float).ok_or_else(|| {
            unsupported(format!(
                "the input at location {location} (%{var}) is not a 32-bit float or float vector"
            ))
        })?;
        let signed = match fetch {
            IntegerFetch::Scaled { signed } => signed,
            IntegerFetch::Packed { .. } => {
                let word = int32(module, added, ids, false)?;
                let operands = vec![
                    Operand::StorageClass(StorageClass::Input),
                    Operand::IdRef(word),
                ];
                let ptr = type_id(module, added, ids, Op::TypePointer, operands)?;
                module.types_global_values[n].result_type = Some(ptr);
                packed.insert(var, (float, shape, fetch));
                continue;
            }
        };
        let int = int32(module, added, ids, signed)?;
        let float_scalar = if shape == 1 {
            float
        } else {
            module
                .types_global_values
                .iter()
                .find(|i| i.result_id == Some(float))
                .and_then(|t| id_ref(t.operands.first()))
                .unwrap_or(float)
        };
        let int_whole = if shape == 1 {
            int
        } else {
            vector(module, added, ids, int, shape)?
        };
        let input_ptr = |module: &Module, added: &mut Vec<Instruction>, ids: &mut Ids, t| {
            let operands = vec![
                Operand::StorageClass(StorageClass::Input),
                Operand::IdRef(t),
            ];
            type_id(module, added, ids, Op::TypePointer, operands)
        };
        let whole_ptr = input_ptr(module, added, ids, int_whole)?;
        let component_ptr = input_ptr(module, added, ids, int)?;
        module.types_global_values[n].result_type = Some(whole_ptr);
        vars.insert(
            var,
            Var {
                whole: (float, int_whole),
                component: (float_scalar, int, component_ptr),
                signed,
            },
        );
    }
    Ok((vars, packed))
}

/// The types and constants a packed input's loads are taken apart with, added once.
struct Unpack {
    uint: Word,
    int: Word,
    float: Word,
    boolean: Word,
    constants: HashMap<(Word, u32), Word>,
}

impl Unpack {
    fn new(
        module: &Module,
        added: &mut Vec<Instruction>,
        ids: &mut Ids,
    ) -> Result<Self, SpirvError> {
        Ok(Unpack {
            uint: int32(module, added, ids, false)?,
            int: int32(module, added, ids, true)?,
            float: super::ops::float32(module, added, ids)?,
            boolean: type_id(module, added, ids, Op::TypeBool, Vec::new())?,
            constants: HashMap::new(),
        })
    }

    fn constant(
        &mut self,
        added: &mut Vec<Instruction>,
        ids: &mut Ids,
        ty: Word,
        bits: u32,
    ) -> Result<Word, SpirvError> {
        super::ops::constant(added, ids, &mut self.constants, ty, bits)
    }

    /// The float value (`float`, `n` components) of packed word `word`, as `result`.
    fn emit(
        &mut self,
        (word, float, n, fetch): (Word, Word, u32, IntegerFetch),
        result: Word,
        out: &mut Vec<Instruction>,
        added: &mut Vec<Instruction>,
        ids: &mut Ids,
    ) -> Result<(), SpirvError> {
        let IntegerFetch::Packed {
            red_low,
            signed,
            normalized,
        } = fetch
        else {
            return Ok(());
        };
        // (bit offset, bits) of R, G, B and A in the word.
        let red = if red_low { 0 } else { 20 };
        let blue = if red_low { 20 } else { 0 };
        let channels = [(red, 10u32), (10, 10), (blue, 10), (30, 2)];
        let base = if signed {
            let b = ids.fresh()?;
            out.push(inst(
                Op::Bitcast,
                Some(self.int),
                Some(b),
                vec![Operand::IdRef(word)],
            ));
            b
        } else {
            word
        };
        let (ty, extract, convert) = if signed {
            (self.int, Op::BitFieldSExtract, Op::ConvertSToF)
        } else {
            (self.uint, Op::BitFieldUExtract, Op::ConvertUToF)
        };
        let mut parts = Vec::new();
        for &(offset, bits) in channels.iter().take(n as usize) {
            let (o, c) = (
                self.constant(added, ids, ty, offset)?,
                self.constant(added, ids, ty, bits)?,
            );
            let field = ids.fresh()?;
            out.push(inst(
                extract,
                Some(ty),
                Some(field),
                vec![Operand::IdRef(base), Operand::IdRef(o), Operand::IdRef(c)],
            ));
            let mut value = ids.fresh()?;
            out.push(inst(
                convert,
                Some(self.float),
                Some(value),
                vec![Operand::IdRef(field)],
            ));
            if normalized {
                let max = if signed {
                    (1u32 << (bits - 1)) - 1
                } else {
                    (1u32 << bits) - 1
                };
                let divisor = self.constant(added, ids, self.float, (max as f32).to_bits())?;
                let scaled = ids.fresh()?;
                out.push(inst(
                    Op::FDiv,
                    Some(self.float),
                    Some(scaled),
                    vec![Operand::IdRef(value), Operand::IdRef(divisor)],
                ));
                value = scaled;
                if signed {
                    // The most negative value reads as -1, as the one above it does.
                    let minus_one = self.constant(added, ids, self.float, (-1.0f32).to_bits())?;
                    let below = ids.fresh()?;
                    out.push(inst(
                        Op::FOrdLessThan,
                        Some(self.boolean),
                        Some(below),
                        vec![Operand::IdRef(value), Operand::IdRef(minus_one)],
                    ));
                    let clamped = ids.fresh()?;
                    out.push(inst(
                        Op::Select,
                        Some(self.float),
                        Some(clamped),
                        vec![
                            Operand::IdRef(below),
                            Operand::IdRef(minus_one),
                            Operand::IdRef(value),
                        ],
                    ));
                    value = clamped;
                }
            }
            parts.push(value);
        }
        if n == 1 {
            // A scalar input: the last instruction's result becomes the load's.
            if let Some(last) = out.last_mut() {
                last.result_id = Some(result);
            }
        } else {
            out.push(inst(
                Op::CompositeConstruct,
                Some(float),
                Some(result),
                parts.into_iter().map(Operand::IdRef).collect(),
            ));
        }
        Ok(())
    }
}
