//! Input attachments read as textures: `subpassLoad` becomes a fetch at the fragment's own
//! position, on the module of `tests/fixtures/subpass` and on a multisampled one built here.

use rspirv::spirv::ImageOperands;

use super::*;

fn subpass_fixture() -> Vec<u32> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/subpass/subpass_load.spv");
    words(&std::fs::read(path).unwrap()).unwrap()
}

/// A fragment shader writing `subpassLoad(in, sample 3)` of multisampled subpass data.
fn multisampled_module() -> Vec<u32> {
    let mut b = Builder::new();
    b.set_version(1, 0);
    b.capability(Capability::Shader);
    b.capability(Capability::InputAttachment);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let float = b.type_float(32, None);
    let vec4 = b.type_vector(float, 4);
    let int = b.type_int(32, 1);
    let ivec2 = b.type_vector(int, 2);
    let zero = b.constant_bit32(int, 0);
    let three = b.constant_bit32(int, 3);
    let origin = b.constant_composite(ivec2, [zero, zero]);
    let image = b.type_image(
        float,
        Dim::DimSubpassData,
        0,
        0,
        1,
        2,
        ImageFormat::Unknown,
        None,
    );
    let image_ptr = b.type_pointer(None, StorageClass::UniformConstant, image);
    let input = b.variable(image_ptr, None, StorageClass::UniformConstant, None);
    b.decorate(input, Decoration::DescriptorSet, [Operand::LiteralBit32(0)]);
    b.decorate(input, Decoration::Binding, [Operand::LiteralBit32(0)]);
    b.decorate(
        input,
        Decoration::InputAttachmentIndex,
        [Operand::LiteralBit32(0)],
    );
    let out_ptr = b.type_pointer(None, StorageClass::Output, vec4);
    let color = b.variable(out_ptr, None, StorageClass::Output, None);
    b.decorate(color, Decoration::Location, [Operand::LiteralBit32(0)]);
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    let loaded = b.load(image, None, input, None, []).unwrap();
    let texel = b
        .image_read(
            vec4,
            None,
            loaded,
            origin,
            Some(ImageOperands::SAMPLE),
            [Operand::IdRef(three)],
        )
        .unwrap();
    b.store(color, texel, None, []).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::Fragment, f, "main", [color]);
    b.execution_mode(f, ExecutionMode::OriginUpperLeft, []);
    b.module().assemble()
}

/// What the rewrite left: no subpass data, a fetch at ivec2(gl_FragCoord.xy) + offset with
/// the image operands given, gl_FragCoord in the entry point's interface.
fn check(out: &[u32], operands: ImageOperands) {
    let m = load(out);
    assert!(
        !m.types_global_values
            .iter()
            .any(|i| i.operands.get(1) == Some(&Operand::Dim(Dim::DimSubpassData))),
        "subpass data left"
    );
    let fetch = m
        .all_inst_iter()
        .find(|i| i.class.opcode == Op::ImageFetch)
        .expect("a fetch");
    assert_eq!(fetch.operands[2], Operand::ImageOperands(operands));
    let coord = match fetch.operands[1] {
        Operand::IdRef(id) => id,
        _ => panic!("no coordinate"),
    };
    let add = m
        .all_inst_iter()
        .find(|i| i.result_id == Some(coord))
        .unwrap();
    assert_eq!(add.class.opcode, Op::IAdd);
    assert!(!m.all_inst_iter().any(|i| i.class.opcode == Op::ImageRead));
    let frag_coord = m
        .annotations
        .iter()
        .find(|a| a.operands.get(2) == Some(&Operand::BuiltIn(BuiltIn::FragCoord)))
        .and_then(|a| match a.operands[0] {
            Operand::IdRef(id) => Some(id),
            _ => None,
        })
        .expect("gl_FragCoord declared");
    assert!(
        m.entry_points[0]
            .operands
            .contains(&Operand::IdRef(frag_coord))
    );
    assert!(
        !m.annotations
            .iter()
            .any(|a| a.operands.get(1)
                == Some(&Operand::Decoration(Decoration::InputAttachmentIndex)))
    );
}

#[test]
fn a_subpass_load_becomes_a_fetch_at_the_fragment_position() {
    let out = rewrite(
        &subpass_fixture(),
        ExecutionModel::Fragment,
        "main",
        &opts(false),
    )
    .unwrap();
    check(&out, ImageOperands::LOD);
    super::validators::spirv_val(&out, "subpass").unwrap();
    super::validators::naga_accepts(&out).unwrap();
}

#[test]
fn a_multisampled_subpass_load_fetches_its_sample() {
    let out = rewrite(
        &multisampled_module(),
        ExecutionModel::Fragment,
        "main",
        &opts(false),
    )
    .unwrap();
    check(&out, ImageOperands::SAMPLE);
    super::validators::spirv_val(&out, "subpass-ms").unwrap();
}
