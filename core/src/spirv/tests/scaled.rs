//! Vertex inputs in scaled formats, on 0 A.D.'s menu vertex shader as zink wrote it (its
//! position, `a_vertex` at location 0, comes in `R16G16_SSCALED`): the input becomes an
//! integer vector converted where loaded, the module stays valid for both shader paths, and a
//! use other than a load is refused by name.

use rspirv::dr::Instruction;

use super::validators::{naga_accepts, spirv_val};
use super::*;

const VERTEX: &str = "zeroad_zink_menu_f60/sh171";
const SIGNED: IntegerFetch = IntegerFetch::Scaled { signed: true };
const UNSIGNED: IntegerFetch = IntegerFetch::Scaled { signed: false };

fn rewritten(scaled: &[(u32, IntegerFetch)]) -> Result<Vec<u32>, SpirvError> {
    // zink's uniform block of words is widened to std140 as the lowering does, so that
    // spirv-val takes the module under Vulkan's uniform layout rules.
    let opts = RewriteOptions {
        scaled_inputs: scaled,
        std140_blocks: &[(0, 0)],
        ..opts(false)
    };
    rewrite(&fixture(VERTEX), ExecutionModel::Vertex, "main", &opts)
}

/// The type an input variable at `location` points to, as (opcode, component type's
/// opcode and signedness).
fn input_type(module: &Module, location: u32) -> (Op, Option<(Op, Option<u32>)>) {
    let var = module
        .annotations
        .iter()
        .find(|a| {
            a.operands.get(1) == Some(&Operand::Decoration(Decoration::Location))
                && a.operands.get(2) == Some(&Operand::LiteralBit32(location))
                && module.types_global_values.iter().any(|v| {
                    v.class.opcode == Op::Variable
                        && v.result_id == index::id_ref(a.operands.first())
                        && v.operands.first() == Some(&Operand::StorageClass(StorageClass::Input))
                })
        })
        .and_then(|a| index::id_ref(a.operands.first()))
        .expect("an input at the location");
    let def = |id: u32| {
        module
            .types_global_values
            .iter()
            .find(|i| i.result_id == Some(id))
            .expect("defined")
    };
    let v = def(var);
    let pointee = def(index::id_ref(def(v.result_type.unwrap()).operands.get(1)).unwrap());
    let component = index::id_ref(pointee.operands.first()).map(|c| {
        let c = def(c);
        (c.class.opcode, index::literal(c.operands.get(1)))
    });
    (pointee.class.opcode, component)
}

#[test]
fn a_scaled_input_is_fetched_as_integers_and_converted_where_loaded() {
    let before = load(&fixture(VERTEX));
    assert_eq!(
        input_type(&before, 0),
        (Op::TypeVector, Some((Op::TypeFloat, None)))
    );
    let words = rewritten(&[(0, SIGNED)]).unwrap();
    let module = load(&words);
    // A signed 32-bit vector, converted by OpConvertSToF at each load; location 1 untouched.
    assert_eq!(
        input_type(&module, 0),
        (Op::TypeVector, Some((Op::TypeInt, Some(1))))
    );
    assert_eq!(
        input_type(&module, 1),
        (Op::TypeVector, Some((Op::TypeFloat, None)))
    );
    assert!(count_op(&module, Op::ConvertSToF) >= 1);
    assert_eq!(count_op(&module, Op::ConvertUToF), 0);
    spirv_val(&words, "scaled-signed").unwrap();
    naga_accepts(&words).unwrap();
    // Unsigned, both inputs.
    let words = rewritten(&[(0, UNSIGNED), (1, UNSIGNED)]).unwrap();
    let module = load(&words);
    assert_eq!(
        input_type(&module, 1),
        (Op::TypeVector, Some((Op::TypeInt, Some(0))))
    );
    assert!(count_op(&module, Op::ConvertUToF) >= 2);
    spirv_val(&words, "scaled-unsigned").unwrap();
    naga_accepts(&words).unwrap();
    // No scaled input: the module is what it was.
    assert_eq!(rewritten(&[]).unwrap(), rewritten(&[(7, SIGNED)]).unwrap());
}

/// A packed 2-10-10-10 input (OpenGL's packed normals, `A2B10G10R10_SNORM_PACK32` through
/// zink): fetched as one unsigned word, each load taking its channels apart with sign
/// extension, dividing by 511 and clamping at -1; unsigned and scaled packings likewise. The
/// module stays valid for both shader paths.
#[test]
fn a_packed_input_is_fetched_as_its_word_and_taken_apart_where_loaded() {
    for (signed, normalized) in [(true, true), (false, true), (true, false), (false, false)] {
        let fetch = IntegerFetch::Packed {
            red_low: signed,
            signed,
            normalized,
        };
        let words = rewritten(&[(0, fetch)]).unwrap();
        let module = load(&words);
        assert_eq!(input_type(&module, 0), (Op::TypeInt, None));
        let (extract, other) = if signed {
            (Op::BitFieldSExtract, Op::BitFieldUExtract)
        } else {
            (Op::BitFieldUExtract, Op::BitFieldSExtract)
        };
        // 0 A.D.'s position is a vec2: two channels a load.
        assert!(count_op(&module, extract) >= 2, "{fetch:?}");
        assert_eq!(count_op(&module, other), 0);
        assert_eq!(count_op(&module, Op::FDiv) >= 2, normalized, "{fetch:?}");
        assert_eq!(count_op(&module, Op::Select) >= 2, signed && normalized);
        spirv_val(&words, "packed").unwrap();
        naga_accepts(&words).unwrap();
    }
}

#[test]
fn an_input_used_other_than_by_a_load_is_refused_by_name() {
    let mut module = load(&fixture(VERTEX));
    // The input handed whole to OpCopyObject.
    let var = module
        .types_global_values
        .iter()
        .find(|v| {
            v.class.opcode == Op::Variable
                && v.operands.first() == Some(&Operand::StorageClass(StorageClass::Input))
        })
        .and_then(|v| Some((v.result_id?, v.result_type?)))
        .unwrap();
    let f = module.functions.first_mut().unwrap();
    f.blocks[0].instructions.insert(
        0,
        Instruction::new(
            Op::CopyObject,
            Some(var.1),
            Some(9999),
            vec![Operand::IdRef(var.0)],
        ),
    );
    if let Some(h) = module.header.as_mut() {
        h.bound = h.bound.max(10_000);
    }
    let words = module.assemble();
    let opts = RewriteOptions {
        scaled_inputs: &[(0, SIGNED), (1, SIGNED)],
        std140_blocks: &[(0, 0)],
        ..opts(false)
    };
    let err = rewrite(&words, ExecutionModel::Vertex, "main", &opts).unwrap_err();
    assert!(
        err.to_string().contains("scaled format") && err.to_string().contains("OpCopyObject"),
        "{err}"
    );
}
