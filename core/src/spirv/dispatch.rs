//! One call made through a switch: the block that holds it is cut after the call, the call
//! becomes an `OpSwitch` on a value whose each case calls its own function, and the rest of
//! the block follows as the switch's merge block (with an `OpPhi` of the cases' results where
//! the call returns one). The descriptor array split uses it for a call that hands an array
//! index known only at run time to a function: each case calls the function's clone for that
//! index.

use rspirv::dr::{Block, Function, Instruction, Operand};
use rspirv::spirv::{Op, SelectionControl, Word};

use super::SpirvError;
use super::ops::{Ids, inst};

/// Replaces the call at `(block, instruction)` of `f` by a switch on `selector` whose case
/// `values[k]` calls `targets[k]` with the call's arguments; any other value takes the first
/// case. `returns_value`: whether the call's result is used as a value (not void).
pub(super) fn switch_call(
    f: &mut Function,
    (bi, ii): (usize, usize),
    selector: Word,
    (values, targets): (&[u32], &[Word]),
    returns_value: bool,
    ids: &mut Ids,
) -> Result<(), SpirvError> {
    let refused = |detail: &str| SpirvError::Unsupported {
        feature: "descriptor array",
        detail: detail.to_owned(),
    };
    let block = &mut f.blocks[bi];
    if block
        .instructions
        .iter()
        .any(|i| i.class.opcode == Op::LoopMerge)
    {
        return Err(refused(
            "a call that hands an index known only at run time sits in a loop's header block",
        ));
    }
    let Some(original) = block.label.as_ref().and_then(|l| l.result_id) else {
        return Err(refused("a block without a label"));
    };
    if targets.is_empty() || values.len() != targets.len() {
        return Err(refused("a switch without cases"));
    }
    let rest = block.instructions.split_off(ii + 1);
    let Some(call) = block.instructions.pop() else {
        return Err(refused("no call where the dispatch was planned"));
    };
    let merge = ids.fresh()?;
    let labels: Vec<Word> = targets
        .iter()
        .map(|_| ids.fresh())
        .collect::<Result<_, _>>()?;
    block.instructions.push(inst(
        Op::SelectionMerge,
        None,
        None,
        vec![
            Operand::IdRef(merge),
            Operand::SelectionControl(SelectionControl::NONE),
        ],
    ));
    let mut switch = vec![Operand::IdRef(selector), Operand::IdRef(labels[0])];
    for (&v, &l) in values.iter().zip(&labels) {
        switch.extend([Operand::LiteralBit32(v), Operand::IdRef(l)]);
    }
    block
        .instructions
        .push(inst(Op::Switch, None, None, switch));
    let mut added: Vec<Block> = Vec::with_capacity(targets.len() + 1);
    let mut phi = Vec::new();
    for (&target, &label) in targets.iter().zip(&labels) {
        let result = ids.fresh()?;
        let mut operands = call.operands.clone();
        operands[0] = Operand::IdRef(target);
        added.push(Block {
            label: Some(inst(Op::Label, None, Some(label), vec![])),
            instructions: vec![
                inst(Op::FunctionCall, call.result_type, Some(result), operands),
                inst(Op::Branch, None, None, vec![Operand::IdRef(merge)]),
            ],
        });
        phi.extend([Operand::IdRef(result), Operand::IdRef(label)]);
    }
    let mut instructions: Vec<Instruction> = Vec::with_capacity(rest.len() + 1);
    if returns_value {
        instructions.push(inst(Op::Phi, call.result_type, call.result_id, phi));
    }
    instructions.extend(rest);
    added.push(Block {
        label: Some(inst(Op::Label, None, Some(merge), vec![])),
        instructions,
    });
    // What followed the block now follows the merge block.
    for b in &mut f.blocks {
        for i in b
            .instructions
            .iter_mut()
            .filter(|i| i.class.opcode == Op::Phi)
        {
            for parent in i.operands.iter_mut().skip(1).step_by(2) {
                if *parent == Operand::IdRef(original) {
                    *parent = Operand::IdRef(merge);
                }
            }
        }
    }
    f.blocks.splice(bi + 1..bi + 1, added);
    Ok(())
}
