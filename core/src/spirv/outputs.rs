//! Fragment outputs with no colour attachment. Vulkan discards what a fragment shader writes to
//! a location the subpass has no attachment for (the validation layer warns,
//! `UNASSIGNED-CoreValidation-Shader-OutputNotConsumed`); Mesa's zink declares all eight
//! `gl_FragData` in every OpenGL fragment shader. Each such output becomes a private variable:
//! the code that writes it stays, nothing leaves the shader, and the module declares only the
//! outputs the pipeline renders.
//!
//! Likewise the layer and viewport index a pre-rasterization stage writes (`gl_Layer`,
//! `gl_ViewportIndex`; zink's blit and clear vertex shaders write the instance as the layer):
//! the replay renders one layer of each attachment through one viewport, and the import
//! refuses layered rendering, so the only value Vulkan defines for them is 0, the one used
//! without them. They become private variables, and the capabilities only they needed go.

use rspirv::dr::{Module, Operand};
use rspirv::spirv::{BuiltIn, Capability, Decoration, ExecutionModel, Op, StorageClass, Word};

use super::SpirvError;

/// The first SPIR-V version whose entry points list every global variable they use (1.4).
const INTERFACE_LISTS_ALL: u32 = 0x0001_0400;

/// Makes each fragment output whose location is not in `attached` (a bit per location) a
/// private variable. Other execution models are left.
pub(super) fn unattached_private(
    module: &mut Module,
    model: ExecutionModel,
    attached: u32,
) -> Result<(), SpirvError> {
    if model != ExecutionModel::Fragment {
        return Ok(());
    }
    let outputs = output_variables(module);
    let mut unattached: Vec<Word> = module
        .annotations
        .iter()
        .filter_map(|i| match (i.class.opcode, i.operands.as_slice()) {
            (
                Op::Decorate,
                [
                    Operand::IdRef(t),
                    Operand::Decoration(Decoration::Location),
                    Operand::LiteralBit32(location),
                ],
            ) if outputs.contains(t) && (*location >= 32 || attached & (1 << location) == 0) => {
                Some(*t)
            }
            _ => None,
        })
        .collect();
    unattached.sort_unstable();
    unattached.dedup();
    if unattached.is_empty() {
        return Ok(());
    }
    super::reclass::reclass(
        module,
        &unattached,
        StorageClass::Output,
        StorageClass::Private,
    )?
    .map_err(|(var, op, n)| SpirvError::Unsupported {
        feature: "use of a fragment output with no attachment",
        detail: format!("output %{var} is used through a pointer by Op{op:?} (operand {n})"),
    })?;
    module.annotations.retain(|i| {
        !matches!(
            i.operands.as_slice(),
            [Operand::IdRef(t), Operand::Decoration(
                Decoration::Location | Decoration::Index | Decoration::Component
            ), ..] if unattached.contains(t)
        )
    });
    leave_interfaces(module, &unattached);
    Ok(())
}

/// Makes every `Layer` and `ViewportIndex` output variable a private one and drops the
/// capabilities that declared them (`ShaderLayer`, `ShaderViewportIndex`,
/// `ShaderViewportIndexLayerEXT`) once nothing else is decorated so.
pub(super) fn layer_outputs_private(module: &mut Module) -> Result<(), SpirvError> {
    let outputs = output_variables(module);
    let layered =
        |o: &Operand| matches!(o, Operand::BuiltIn(BuiltIn::Layer | BuiltIn::ViewportIndex));
    let mut vars: Vec<Word> = module
        .annotations
        .iter()
        .filter_map(|i| match i.operands.as_slice() {
            [
                Operand::IdRef(t),
                Operand::Decoration(Decoration::BuiltIn),
                b,
            ] if layered(b) && outputs.contains(t) => Some(*t),
            _ => None,
        })
        .collect();
    vars.sort_unstable();
    vars.dedup();
    if !vars.is_empty() {
        super::reclass::reclass(module, &vars, StorageClass::Output, StorageClass::Private)?
            .map_err(|(var, op, n)| SpirvError::Unsupported {
                feature: "use of a layer or viewport index output",
                detail: format!(
                    "output %{var} is used through a pointer by Op{op:?} (operand {n})"
                ),
            })?;
        module.annotations.retain(
            |i| !matches!(i.operands.as_slice(), [Operand::IdRef(t), ..] if vars.contains(t)),
        );
        leave_interfaces(module, &vars);
    }
    // The capabilities go where nothing is left that needs them, also where nothing ever did
    // (zink declares `ShaderLayer` on vertex shaders that write no layer).
    let still = module
        .annotations
        .iter()
        .any(|i| i.operands.iter().any(layered));
    if !still {
        module.capabilities.retain(|c| {
            !matches!(
                c.operands.first(),
                Some(Operand::Capability(
                    Capability::ShaderLayer
                        | Capability::ShaderViewportIndex
                        | Capability::ShaderViewportIndexLayerEXT
                ))
            )
        });
    }
    Ok(())
}

/// The module's output variables.
fn output_variables(module: &Module) -> Vec<Word> {
    module
        .types_global_values
        .iter()
        .filter(|i| {
            i.class.opcode == Op::Variable
                && i.operands.first() == Some(&Operand::StorageClass(StorageClass::Output))
        })
        .filter_map(|i| i.result_id)
        .collect()
}

/// Takes `vars`, no longer outputs, off the entry points' interfaces where the module's SPIR-V
/// version lists only inputs and outputs there (before 1.4).
fn leave_interfaces(module: &mut Module, vars: &[Word]) {
    let version = module.header.as_ref().map_or(0, |h| h.version);
    if version < INTERFACE_LISTS_ALL {
        for e in &mut module.entry_points {
            e.operands
                .retain(|o| !matches!(o, Operand::IdRef(v) if vars.contains(v)));
        }
    }
}
