//! Samples through a sampler that mirrors once and clamps: the mirrored components of the
//! coordinate replaced by their absolute value, on the module of
//! `tests/fixtures/subpass/unnormalized.spvasm` (a 2D sample through set 0 binding 1).

use super::*;

fn module() -> Vec<u32> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/subpass/unnormalized.spv");
    words(&std::fs::read(path).unwrap()).unwrap()
}

fn mirrored(axes: u8) -> (Vec<u32>, rspirv::dr::Module) {
    let out = rewrite(
        &module(),
        ExecutionModel::Fragment,
        "main",
        &RewriteOptions {
            mirror_once: &[(0, 1, axes)],
            ..opts(false)
        },
    )
    .unwrap();
    let m = load(&out);
    (out, m)
}

/// The instruction that makes the sample's coordinate.
fn coordinate(m: &rspirv::dr::Module) -> rspirv::dr::Instruction {
    let sample = m
        .all_inst_iter()
        .find(|i| i.class.opcode == Op::ImageSampleExplicitLod)
        .unwrap();
    let Operand::IdRef(coord) = sample.operands[1] else {
        panic!("no coordinate");
    };
    m.all_inst_iter()
        .find(|i| i.result_id == Some(coord))
        .unwrap()
        .clone()
}

#[test]
fn both_axes_mirrored_sample_at_the_absolute_coordinate() {
    let (out, m) = mirrored(0b011);
    let abs = coordinate(&m);
    assert_eq!(abs.class.opcode, Op::ExtInst);
    assert_eq!(abs.operands[1], Operand::LiteralExtInstInteger(4));
    super::validators::spirv_val(&out, "mirror-once").unwrap();
    super::validators::naga_accepts(&out).unwrap();
}

/// Only `u` mirrored: `v` comes from the coordinate as it was (a shuffle taking component 0
/// of the absolute value and component 1 of the original); `w` on a 2D image is nothing.
#[test]
fn one_axis_mirrored_keeps_the_other_as_it_was() {
    let (out, m) = mirrored(0b101);
    let shuffle = coordinate(&m);
    assert_eq!(shuffle.class.opcode, Op::VectorShuffle);
    assert_eq!(
        shuffle.operands[2..],
        [Operand::LiteralBit32(2), Operand::LiteralBit32(1)]
    );
    super::validators::spirv_val(&out, "mirror-once-u").unwrap();
    super::validators::naga_accepts(&out).unwrap();
    // No mirrored axis on this image: the module is what it is without the option.
    let plain = rewrite(&module(), ExecutionModel::Fragment, "main", &opts(false)).unwrap();
    assert_eq!(mirrored(0b100).0, plain);
}
