//! Demote to helper invocation taken as OpKill, on a built module: what `discard` in an `if`
//! becomes in ANGLE's shaders.

use rspirv::dr::{InsertPoint, Instruction};
use rspirv::spirv::SelectionControl;

use super::*;

/// A fragment shader that demotes in one branch of a selection and writes a colour after it.
pub(super) fn demote_module() -> Vec<u32> {
    let mut b = Builder::new();
    b.set_version(1, 0);
    b.capability(Capability::Shader);
    b.capability(Capability::DemoteToHelperInvocation);
    b.extension("SPV_EXT_demote_to_helper_invocation");
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let boolean = b.type_bool();
    let yes = b.constant_true(boolean);
    let float = b.type_float(32, None);
    let vec4 = b.type_vector(float, 4);
    let out_ptr = b.type_pointer(None, StorageClass::Output, vec4);
    let color = b.variable(out_ptr, None, StorageClass::Output, None);
    b.decorate(color, Decoration::Location, [Operand::LiteralBit32(0)]);
    let one = b.constant_bit32(float, 1.0f32.to_bits());
    let white = b.constant_composite(vec4, [one, one, one, one]);
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    let (demote, merge) = (b.id(), b.id());
    b.selection_merge(merge, SelectionControl::NONE).unwrap();
    b.branch_conditional(yes, demote, merge, []).unwrap();
    b.begin_block(Some(demote)).unwrap();
    b.insert_into_block(
        InsertPoint::End,
        Instruction::new(Op::DemoteToHelperInvocation, None, None, vec![]),
    )
    .unwrap();
    b.branch(merge).unwrap();
    b.begin_block(Some(merge)).unwrap();
    b.store(color, white, None, []).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::Fragment, f, "main", [color]);
    b.execution_mode(f, ExecutionMode::OriginUpperLeft, []);
    b.module().assemble()
}

#[test]
fn a_demote_that_ends_its_block_becomes_a_kill() {
    let out = rewrite(
        &demote_module(),
        ExecutionModel::Fragment,
        "main",
        &opts(false),
    )
    .unwrap();
    let m = load(&out);
    let ops: Vec<Op> = m
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .map(|i| i.class.opcode)
        .collect();
    assert!(!ops.contains(&Op::DemoteToHelperInvocation));
    assert!(ops.contains(&Op::Kill));
    // The colour is still written where nothing is discarded.
    assert!(ops.contains(&Op::Store));
    assert!(
        !reflect(&out)
            .unwrap()
            .capabilities
            .contains(&Capability::DemoteToHelperInvocation),
        "the capability goes with the instruction"
    );
}
