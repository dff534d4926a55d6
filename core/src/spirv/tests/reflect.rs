//! Reflection of real modules and of modules built here.

use super::*;

// ---- reflection -------------------------------------------------------------------------------

#[test]
fn reflects_vkcube_vertex_shader() {
    let r = reflect(&fixture("vkcube_f3/sh37")).unwrap();
    assert_eq!(
        r.entry_points,
        vec![EntryPoint {
            model: ExecutionModel::Vertex,
            name: "main".to_owned()
        }]
    );
    assert_eq!(
        r.resources,
        vec![ResourceVar {
            set: 0,
            binding: 0,
            count: None,
            kind: ResourceKind::UniformBuffer,
            non_writable: false,
            non_readable: false,
            id: r.resources[0].id,
            name: Some("ubuf".to_owned()),
            block_size: Some(1216),
        }]
    );
    assert_eq!(r.push_constant_size, 0);
    assert_eq!(r.capabilities, vec![Capability::Shader]);
}

#[test]
fn reflects_vkcube_fragment_shader() {
    let r = reflect(&fixture("vkcube_f3/sh38")).unwrap();
    assert_eq!(
        r.entry_points,
        vec![EntryPoint {
            model: ExecutionModel::Fragment,
            name: "main".to_owned()
        }]
    );
    assert_eq!(r.resources.len(), 1);
    let tex = &r.resources[0];
    assert_eq!((tex.set, tex.binding, tex.count), (0, 1, None));
    assert_eq!(tex.kind, ResourceKind::CombinedImageSampler(TEXTURE_2D));
    assert_eq!(tex.name.as_deref(), Some("tex"));
    assert_eq!(r.push_constant_size, 0);
}

#[test]
fn reflects_storage_texel_buffer_and_storage_image() {
    let r = reflect(&fixture("mpv_testsrc_f5/sh73")).unwrap();
    assert_eq!(r.entry_points[0].model, ExecutionModel::GLCompute);
    assert_eq!(r.resources.len(), 2);
    assert_eq!(
        r.resources[0].kind,
        ResourceKind::StorageTexelBuffer(ImageFormat::R8)
    );
    assert_eq!(
        r.resources[1].kind,
        ResourceKind::StorageImage(ImageInfo {
            format: ImageFormat::Rgba8,
            ..TEXTURE_2D
        })
    );
    assert!(r.resources[1].non_readable);
    assert!(!r.resources[1].non_writable);
    assert!(r.capabilities.contains(&Capability::ImageBuffer));
}

#[test]
fn reflects_push_constants_and_uniform_block_with_matrices() {
    let r = reflect(&fixture("mpv_testsrc_f5/sh83")).unwrap();
    // Six members, the last a vec2 at offset 64.
    assert_eq!(r.push_constant_size, 72);
    assert_eq!(
        binding_of(&r, 0, 0),
        vec![&ResourceKind::CombinedImageSampler(TEXTURE_2D)]
    );
    assert_eq!(binding_of(&r, 0, 1), vec![&ResourceKind::UniformBuffer]);
}

#[test]
fn reflects_every_fixture_module() {
    let mut kinds = BTreeSet::new();
    for (name, words) in all_fixtures() {
        let r = reflect(&words).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!r.entry_points.is_empty(), "{name}: no entry point");
        assert!(
            r.resources
                .windows(2)
                .all(|w| (w[0].set, w[0].binding) <= (w[1].set, w[1].binding)),
            "{name}: resources not sorted"
        );
        for v in &r.resources {
            kinds.insert(format!("{:?}", std::mem::discriminant(&v.kind)));
        }
    }
    // Uniform and storage buffers, combined samplers, storage images and texel buffers.
    assert!(kinds.len() >= 5, "{kinds:?}");
}

#[test]
fn push_constant_size_follows_matrix_and_array_strides() {
    let mut b = Builder::new();
    b.set_version(1, 0);
    b.capability(Capability::Shader);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let float = b.type_float(32, None);
    let vec4 = b.type_vector(float, 4);
    let vec3 = b.type_vector(float, 3);
    let mat4 = b.type_matrix(vec4, 4);
    let mat4x3 = b.type_matrix(vec3, 4);
    let uint = b.type_int(32, 0);
    let three = b.constant_bit32(uint, 3);
    let floats = b.type_array(float, three);
    b.decorate(floats, Decoration::ArrayStride, [Operand::LiteralBit32(16)]);
    let inner = b.type_struct([vec3, float]);
    for (m, offset) in [(0, 0), (1, 12)] {
        b.member_decorate(
            inner,
            m,
            Decoration::Offset,
            [Operand::LiteralBit32(offset)],
        );
    }
    // mat4 (64 bytes) at 0, float[3] (stride 16) at 64, a row-major 4x3 matrix (3 rows of
    // stride 16) at 112, the inner struct (16 bytes) at 160: 176 in all.
    let block = b.type_struct([mat4, floats, mat4x3, inner]);
    b.decorate(block, Decoration::Block, []);
    for (m, offset) in [(0, 0), (1, 64), (2, 112), (3, 160)] {
        b.member_decorate(
            block,
            m,
            Decoration::Offset,
            [Operand::LiteralBit32(offset)],
        );
    }
    for m in [0, 2] {
        b.member_decorate(
            block,
            m,
            Decoration::MatrixStride,
            [Operand::LiteralBit32(16)],
        );
    }
    b.member_decorate(block, 0, Decoration::ColMajor, []);
    b.member_decorate(block, 2, Decoration::RowMajor, []);
    let ptr = b.type_pointer(None, StorageClass::PushConstant, block);
    b.variable(ptr, None, StorageClass::PushConstant, None);
    let (void, fn_ty) = {
        let void = b.type_void();
        (void, b.type_function(void, []))
    };
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::GLCompute, f, "main", []);
    b.execution_mode(f, ExecutionMode::LocalSize, [1, 1, 1]);
    let r = reflect(&b.module().assemble()).unwrap();
    assert_eq!(r.push_constant_size, 176);
}

/// A block of two copies of a struct of two copies of ... sixty levels deep: a walk that does
/// not remember sizes would never finish.
#[test]
fn push_constant_size_of_a_deeply_shared_struct_is_quick() {
    let mut b = Builder::new();
    b.set_version(1, 0);
    b.capability(Capability::Shader);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let mut ty = b.type_float(32, None);
    for _ in 0..60 {
        let pair = b.type_struct([ty, ty]);
        for m in 0..2 {
            b.member_decorate(pair, m, Decoration::Offset, [Operand::LiteralBit32(0)]);
        }
        ty = pair;
    }
    b.decorate(ty, Decoration::Block, []);
    let ptr = b.type_pointer(None, StorageClass::PushConstant, ty);
    b.variable(ptr, None, StorageClass::PushConstant, None);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::GLCompute, f, "main", []);
    assert_eq!(
        reflect(&b.module().assemble()).unwrap().push_constant_size,
        4
    );
}

#[test]
fn decorations_through_a_group_are_reflected() {
    let module = combined_sampler_module(Shape {
        grouped: true,
        ..Shape::default()
    });
    let r = reflect(&module).unwrap();
    assert_eq!(
        binding_of(&r, 1, 3),
        vec![&ResourceKind::CombinedImageSampler(TEXTURE_2D)]
    );
}

#[test]
fn spec_constant_array_length_is_refused() {
    let module = combined_sampler_module(Shape {
        spec_array: true,
        ..Shape::default()
    });
    let err = reflect(&module).unwrap_err();
    assert!(
        matches!(err, SpirvError::Unsupported { feature, .. } if feature.contains("specialization constant")),
        "{err:?}"
    );
}
