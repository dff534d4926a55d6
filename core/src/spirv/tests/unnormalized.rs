//! Samples through a sampler of unnormalized coordinates: the coordinate divided by the
//! image's level-0 size, on the module of `tests/fixtures/subpass/unnormalized.spvasm`.

use super::*;

fn module() -> Vec<u32> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/subpass/unnormalized.spv");
    words(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn an_unnormalized_coordinate_is_divided_by_the_image_size() {
    let out = rewrite(
        &module(),
        ExecutionModel::Fragment,
        "main",
        &RewriteOptions {
            unnormalized: &[(0, 1, false)],
            mirror_once: &[],
            ..opts(false)
        },
    )
    .unwrap();
    let m = load(&out);
    assert!(
        m.capabilities
            .iter()
            .any(|c| c.operands[0] == Operand::Capability(Capability::ImageQuery))
    );
    let sample = m
        .all_inst_iter()
        .find(|i| i.class.opcode == Op::ImageSampleExplicitLod)
        .unwrap();
    let coord = match sample.operands[1] {
        Operand::IdRef(id) => id,
        _ => panic!("no coordinate"),
    };
    let div = m
        .all_inst_iter()
        .find(|i| i.result_id == Some(coord))
        .unwrap();
    assert_eq!(div.class.opcode, Op::FDiv);
    assert!(
        m.all_inst_iter()
            .any(|i| i.class.opcode == Op::ImageQuerySizeLod)
    );
    super::validators::spirv_val(&out, "unnormalized").unwrap();
    super::validators::naga_accepts(&out).unwrap();
    // Without the option the module samples as it was written.
    let plain = rewrite(&module(), ExecutionModel::Fragment, "main", &opts(false)).unwrap();
    assert!(
        !load(&plain)
            .all_inst_iter()
            .any(|i| i.class.opcode == Op::FDiv)
    );
}

/// Through a nearest sampler the coordinate goes to its texel's centre first: `floor(u) +
/// 0.5`, divided by the size (a whole `u` read back through the division can land just below
/// its texel); the module stays valid with GLSL.std.450 imported for the floor.
#[test]
fn a_nearest_unnormalized_coordinate_is_centred_on_its_texel() {
    let out = rewrite(
        &module(),
        ExecutionModel::Fragment,
        "main",
        &RewriteOptions {
            unnormalized: &[(0, 1, true)],
            mirror_once: &[],
            ..opts(false)
        },
    )
    .unwrap();
    let m = load(&out);
    let by_id = |id: Word| m.all_inst_iter().find(|i| i.result_id == Some(id)).unwrap();
    let arg = |i: &rspirv::dr::Instruction, k: usize| match i.operands[k] {
        Operand::IdRef(id) => id,
        _ => panic!("operand {k} of {i:?}"),
    };
    let sample = m
        .all_inst_iter()
        .find(|i| i.class.opcode == Op::ImageSampleExplicitLod)
        .unwrap();
    let div = by_id(arg(sample, 1));
    assert_eq!(div.class.opcode, Op::FDiv);
    let add = by_id(arg(div, 0));
    assert_eq!(add.class.opcode, Op::FAdd);
    let floor = by_id(arg(add, 0));
    assert_eq!(floor.class.opcode, Op::ExtInst);
    assert_eq!(floor.operands[1], Operand::LiteralExtInstInteger(8));
    super::validators::spirv_val(&out, "unnormalized-nearest").unwrap();
    super::validators::naga_accepts(&out).unwrap();
}
