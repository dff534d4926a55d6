//! `OpDemoteToHelperInvocation` (GLSL's `demote`, ANGLE's translation of `discard`) needs a
//! device feature wgpu never turns on. Where the demote ends a block that only branches on,
//! it is taken as `OpKill`: the invocation's outputs are discarded either way, and what
//! differs is only that a killed invocation no longer feeds its quad's derivatives, which
//! the lowering says in a note. A demote elsewhere, or a module asking whether it is a
//! helper invocation, is refused.

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Capability, Op};

use super::SpirvError;

fn refuse(detail: &str) -> SpirvError {
    SpirvError::Unsupported {
        feature: "demote to helper invocation",
        detail: detail.to_owned(),
    }
}

/// Replaces each demote of `module` with `OpKill`; whether there was any.
pub(super) fn demote_as_kill(module: &mut Module) -> Result<bool, SpirvError> {
    let demotes = |i: &Instruction| i.class.opcode == Op::DemoteToHelperInvocation;
    let any = module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .any(demotes);
    if !any {
        return Ok(false);
    }
    if module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .any(|i| i.class.opcode == Op::IsHelperInvocationEXT)
    {
        return Err(refuse(
            "the module asks whether an invocation is a helper (OpIsHelperInvocationEXT)",
        ));
    }
    for f in &mut module.functions {
        let mut killed = Vec::new();
        for b in &mut f.blocks {
            let Some(at) = b.instructions.iter().position(demotes) else {
                continue;
            };
            // Only a plain branch may follow: the block heads no construct and defines
            // nothing after the demote that another block could read.
            if b.instructions.len() != at + 2 || b.instructions[at + 1].class.opcode != Op::Branch {
                return Err(refuse(
                    "a demote not followed directly by the end of its block (OpBranch)",
                ));
            }
            let target = match b.instructions[at + 1].operands.first() {
                Some(Operand::IdRef(t)) => *t,
                _ => return Err(refuse("a branch without a target")),
            };
            let label = b.label.as_ref().and_then(|l| l.result_id);
            b.instructions.truncate(at);
            b.instructions
                .push(Instruction::new(Op::Kill, None, None, Vec::new()));
            killed.extend(label.map(|l| (target, l)));
        }
        for (target, label) in killed {
            drop_phi_parent(f, target, label)?;
        }
    }
    module.capabilities.retain(|i| {
        !matches!(
            i.operands.first(),
            Some(Operand::Capability(Capability::DemoteToHelperInvocation))
        )
    });
    module.extensions.retain(|i| {
        !matches!(i.operands.first(),
            Some(Operand::LiteralString(s)) if s == "SPV_EXT_demote_to_helper_invocation")
    });
    Ok(true)
}

/// Removes `parent` (a block that now ends in a kill) from the OpPhi instructions of block
/// `target` of `f`; a phi left without parents is refused.
fn drop_phi_parent(
    f: &mut rspirv::dr::Function,
    target: u32,
    parent: u32,
) -> Result<(), SpirvError> {
    let Some(b) = f
        .blocks
        .iter_mut()
        .find(|b| b.label.as_ref().and_then(|l| l.result_id) == Some(target))
    else {
        return Ok(());
    };
    for phi in b
        .instructions
        .iter_mut()
        .filter(|i| i.class.opcode == Op::Phi)
    {
        let pairs: Vec<Operand> = phi
            .operands
            .chunks(2)
            .filter(|pair| !matches!(pair.get(1), Some(Operand::IdRef(p)) if *p == parent))
            .flatten()
            .cloned()
            .collect();
        if pairs.is_empty() {
            return Err(refuse("a phi whose only parent demotes"));
        }
        phi.operands = pairs;
    }
    Ok(())
}
