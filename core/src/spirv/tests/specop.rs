//! Spec-constant operations with repeated operands (a shuffle of two components, an extract
//! through two indexes), which the SPIR-V reader cannot decode as written: the module still
//! loads, reflects and rewrites, into instructions of the same value (`validators` runs
//! `spirv-val` on the result).

use rspirv::dr::Instruction;

use super::*;

/// What `spec_module` made: the module and the ids whose definitions the test follows.
pub(super) struct Made {
    pub words: Vec<u32>,
    vector: Word,
    shuffle: Word,
    array: Word,
    nested: Word,
}

/// A fragment shader writing a colour made of spec-constant operations: `shuffle` is
/// `VectorShuffle vector vector 1 6` (vector.y, vector.z), `nested` is `CompositeExtract array
/// 1 0` (array[1].x); with `insert`, a `CompositeInsert` through two indexes as well.
pub(super) fn spec_module(insert: bool) -> Made {
    let mut b = Builder::new();
    b.set_version(1, 0);
    b.capability(Capability::Shader);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let float = b.type_float(32, None);
    let uint = b.type_int(32, 0);
    let vec2 = b.type_vector(float, 2);
    let vec4 = b.type_vector(float, 4);
    let two = b.constant_bit32(uint, 2);
    let pair = b.type_array(vec2, two);
    let scalars: Vec<Word> = (0..4)
        .map(|n| b.spec_constant_bit32(float, (n as f32 / 4.0).to_bits()))
        .collect();
    let vector = b.spec_constant_composite(vec4, scalars.clone());
    let early = b.spec_constant_composite(vec2, [scalars[0], scalars[1]]);
    let late = b.spec_constant_composite(vec2, [scalars[2], scalars[3]]);
    let array = b.spec_constant_composite(pair, [early, late]);
    let spec_op = |b: &mut Builder, ty: Word, operands: Vec<Operand>| {
        let id = b.id();
        b.module_mut().types_global_values.push(Instruction::new(
            Op::SpecConstantOp,
            Some(ty),
            Some(id),
            operands,
        ));
        id
    };
    use Operand::{IdRef, LiteralBit32, LiteralSpecConstantOpInteger as Computes};
    let shuffle = spec_op(
        &mut b,
        vec2,
        vec![
            Computes(Op::VectorShuffle),
            IdRef(vector),
            IdRef(vector),
            LiteralBit32(1),
            LiteralBit32(6),
        ],
    );
    let nested = spec_op(
        &mut b,
        float,
        vec![
            Computes(Op::CompositeExtract),
            IdRef(array),
            LiteralBit32(1),
            LiteralBit32(0),
        ],
    );
    if insert {
        spec_op(
            &mut b,
            pair,
            vec![
                Computes(Op::CompositeInsert),
                IdRef(scalars[0]),
                IdRef(array),
                LiteralBit32(0),
                LiteralBit32(1),
            ],
        );
    }
    let x = spec_op(
        &mut b,
        float,
        vec![
            Computes(Op::CompositeExtract),
            IdRef(shuffle),
            LiteralBit32(0),
        ],
    );
    let y = spec_op(
        &mut b,
        float,
        vec![
            Computes(Op::CompositeExtract),
            IdRef(shuffle),
            LiteralBit32(1),
        ],
    );
    let one = b.constant_bit32(float, 1f32.to_bits());
    let colour = b.spec_constant_composite(vec4, [x, y, nested, one]);
    let out_ptr = b.type_pointer(None, StorageClass::Output, vec4);
    let out = b.variable(out_ptr, None, StorageClass::Output, None);
    b.decorate(out, Decoration::Location, [Operand::LiteralBit32(0)]);
    let main = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    b.store(out, colour, None, []).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::Fragment, main, "main", [out]);
    b.execution_mode(main, ExecutionMode::OriginUpperLeft, []);
    Made {
        words: b.module().assemble(),
        vector,
        shuffle,
        array,
        nested,
    }
}

/// The definition of `id` in `module`'s globals.
fn def(module: &Module, id: Word) -> &Instruction {
    module
        .types_global_values
        .iter()
        .find(|i| i.result_id == Some(id))
        .unwrap_or_else(|| panic!("%{id} is not defined"))
}

/// `(composite, index)` when `inst` is a single-index spec-constant CompositeExtract.
fn single_extract(inst: &Instruction) -> Option<(Word, u32)> {
    match (inst.class.opcode, inst.operands.as_slice()) {
        (
            Op::SpecConstantOp,
            [
                Operand::LiteralSpecConstantOpInteger(Op::CompositeExtract),
                Operand::IdRef(c),
                Operand::LiteralBit32(i),
            ],
        ) => Some((*c, *i)),
        _ => None,
    }
}

#[test]
fn repeated_spec_constant_operands_load_as_the_same_values() {
    let made = spec_module(false);
    // The reader cannot take the module as written.
    assert!(rspirv::dr::load_words(&made.words).is_err());
    let r = reflect(&made.words).expect("reflects");
    assert_eq!(r.entry_points.len(), 1);
    let out = rewrite(&made.words, ExecutionModel::Fragment, "main", &opts(true)).unwrap();
    let module = load(&out);
    // The shuffle keeps its id as a composite of (vector.y, vector.z).
    let shuffle = def(&module, made.shuffle);
    assert_eq!(shuffle.class.opcode, Op::SpecConstantComposite);
    let parts: Vec<(Word, u32)> = shuffle
        .operands
        .iter()
        .map(|o| match o {
            Operand::IdRef(id) => single_extract(def(&module, *id)).expect("an extract"),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(parts, [(made.vector, 1), (made.vector, 2)]);
    // array[1].x: x of a new extract of array[1].
    let (inner, last) = single_extract(def(&module, made.nested)).expect("an extract");
    assert_eq!(last, 0);
    assert_eq!(single_extract(def(&module, inner)), Some((made.array, 1)));
    let bound = module.header.as_ref().unwrap().bound;
    assert!(
        module
            .all_inst_iter()
            .all(|i| i.result_id.is_none_or(|id| id < bound))
    );
}

#[test]
fn a_nested_spec_constant_insert_is_refused_by_name() {
    let made = spec_module(true);
    match reflect(&made.words) {
        Err(SpirvError::Unsupported { feature, detail }) => {
            assert_eq!(feature, "OpSpecConstantOp");
            assert!(detail.contains("OpCompositeInsert"), "{detail}");
        }
        other => panic!("{other:?}"),
    }
}
