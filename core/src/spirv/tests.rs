//! Reflection and rewriting on the shader modules of real captures (tests/fixtures/gfxr/extracted)
//! and on small modules built here for what those lack: geometry shaders, arrays of combined
//! image samplers, uses the split cannot follow, SPIR-V 1.4 interface lists.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use rspirv::binary::Assemble;
use rspirv::dr::{Builder, Function, Module, Operand};
use rspirv::spirv::{
    AddressingModel, BuiltIn, Capability, Decoration, Dim, ExecutionMode, ExecutionModel,
    FunctionControl, ImageFormat, MemoryModel, Op, StorageClass, Word,
};

use super::*;

fn extracted() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/gfxr/extracted")
}

fn fixture(path: &str) -> Vec<u32> {
    let path = extracted().join(path);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    words(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every extracted module of every capture, sorted by path.
fn all_fixtures() -> Vec<(String, Vec<u32>)> {
    let mut out = Vec::new();
    let mut captures: Vec<_> = std::fs::read_dir(extracted())
        .expect("fixtures directory")
        .map(|e| e.expect("entry").path())
        .collect();
    captures.sort();
    for capture in captures {
        let mut modules: Vec<_> = std::fs::read_dir(&capture)
            .expect("capture directory")
            .map(|e| e.expect("entry").path())
            .collect();
        modules.sort();
        for module in modules {
            let name = module
                .strip_prefix(extracted())
                .expect("under extracted")
                .display()
                .to_string();
            out.push((name.clone(), fixture(&name)));
        }
    }
    assert!(out.len() >= 40, "only {} fixture modules found", out.len());
    out
}

/// Binding b becomes 2b (whole or image) and 2b+1 (sampler).
fn doubled(_set: u32, binding: u32, role: Role) -> Option<u32> {
    let even = binding.checked_mul(2)?;
    match role {
        Role::Whole | Role::SplitImage => Some(even),
        Role::SplitSampler => even.checked_add(1),
    }
}

fn opts(flip_y: bool) -> RewriteOptions<'static> {
    RewriteOptions {
        flip_y,
        binding: &doubled,
        specialization: &[],
        texel_formats: &[],
    }
}

fn load(words: &[u32]) -> Module {
    rspirv::dr::load_words(words).expect("rewritten module loads")
}

fn entry_function<'m>(module: &'m Module, name: &str) -> &'m Function {
    let id = module
        .entry_points
        .iter()
        .find(|e| e.operands.get(2) == Some(&Operand::LiteralString(name.to_owned())))
        .and_then(|e| match e.operands.get(1) {
            Some(Operand::IdRef(id)) => Some(*id),
            _ => None,
        })
        .expect("entry point");
    module
        .functions
        .iter()
        .find(|f| f.def_id() == Some(id))
        .expect("entry function")
}

fn count_op(module: &Module, op: Op) -> usize {
    module
        .all_inst_iter()
        .filter(|i| i.class.opcode == op)
        .count()
}

fn binding_of(r: &Reflection, set: u32, binding: u32) -> Vec<&ResourceKind> {
    r.resources
        .iter()
        .filter(|v| v.set == set && v.binding == binding)
        .map(|v| &v.kind)
        .collect()
}

const TEXTURE_2D: ImageInfo = ImageInfo {
    dim: Dim::Dim2D,
    arrayed: false,
    multisampled: false,
    depth: Some(false),
    sampled_type: ScalarKind::Float,
    format: ImageFormat::Unknown,
};

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

// ---- rewriting --------------------------------------------------------------------------------

#[test]
fn splits_vkcube_combined_image_sampler() {
    let out = rewrite(
        &fixture("vkcube_f3/sh38"),
        ExecutionModel::Fragment,
        "main",
        &opts(false),
    )
    .unwrap();
    let r = reflect(&out).unwrap();
    assert!(
        !r.resources
            .iter()
            .any(|v| matches!(v.kind, ResourceKind::CombinedImageSampler(_))),
        "{:?}",
        r.resources
    );
    assert_eq!(
        binding_of(&r, 0, 2),
        vec![&ResourceKind::SampledImage(TEXTURE_2D)]
    );
    assert_eq!(
        binding_of(&r, 0, 3),
        vec![&ResourceKind::Sampler { comparison: false }]
    );
    let names: Vec<_> = r.resources.iter().map(|v| v.name.as_deref()).collect();
    assert_eq!(names, vec![Some("tex_image"), Some("tex_sampler")]);

    let module = load(&out);
    let main = entry_function(&module, "main");
    let ops: Vec<Op> = main.all_inst_iter().map(|i| i.class.opcode).collect();
    let at = ops
        .iter()
        .position(|op| *op == Op::SampledImage)
        .expect("OpSampledImage");
    assert_eq!(&ops[at - 2..at], &[Op::Load, Op::Load]);
    assert!(ops[at..].contains(&Op::ImageSampleImplicitLod));
    // The header's bound covers the new ids.
    let bound = module.header.as_ref().unwrap().bound;
    assert!(
        module
            .all_inst_iter()
            .all(|i| i.result_id.is_none_or(|id| id < bound))
    );
}

#[test]
fn renumbers_every_binding() {
    let out = rewrite(
        &fixture("mpv_testsrc_f5/sh83"),
        ExecutionModel::Fragment,
        "main",
        &opts(true),
    )
    .unwrap();
    let r = reflect(&out).unwrap();
    let layout: Vec<_> = r.resources.iter().map(|v| (v.set, v.binding)).collect();
    assert_eq!(layout, vec![(0, 0), (0, 1), (0, 2)]);
    assert!(matches!(r.resources[0].kind, ResourceKind::SampledImage(_)));
    assert!(matches!(r.resources[1].kind, ResourceKind::Sampler { .. }));
    assert_eq!(r.resources[2].kind, ResourceKind::UniformBuffer);
    assert_eq!(r.push_constant_size, 72);
    // A fragment shader is never flipped.
    assert_eq!(count_op(&load(&out), Op::FNegate), 0);

    let compute = rewrite(
        &fixture("mpv_testsrc_f5/sh73"),
        ExecutionModel::GLCompute,
        "main",
        &RewriteOptions {
            flip_y: true,
            binding: &|_, b, _| Some(b + 10),
            specialization: &[],
            texel_formats: &[],
        },
    )
    .unwrap();
    let r = reflect(&compute).unwrap();
    let layout: Vec<_> = r.resources.iter().map(|v| v.binding).collect();
    assert_eq!(layout, vec![10, 11]);
}

/// The ids of the instructions in `f` that store a value computed by OpFNegate's result, with
/// the pointer they store to.
fn flipped_stores(f: &Function) -> Vec<Word> {
    let insts: Vec<_> = f.all_inst_iter().collect();
    let mut stores = Vec::new();
    for (n, i) in insts.iter().enumerate() {
        if i.class.opcode != Op::FNegate {
            continue;
        }
        let negated = i.result_id.unwrap();
        let insert = insts[n + 1];
        assert_eq!(insert.class.opcode, Op::CompositeInsert);
        assert_eq!(insert.operands[0], Operand::IdRef(negated));
        assert_eq!(insert.operands[2], Operand::LiteralBit32(1));
        let store = insts[n + 2];
        assert_eq!(store.class.opcode, Op::Store);
        assert_eq!(store.operands[1], Operand::IdRef(insert.result_id.unwrap()));
        let Operand::IdRef(pointer) = store.operands[0] else {
            panic!("store pointer")
        };
        stores.push(pointer);
    }
    stores
}

#[test]
fn flips_gl_position_in_a_per_vertex_block() {
    let input = fixture("vkcube_f3/sh37");
    let out = rewrite(&input, ExecutionModel::Vertex, "main", &opts(true)).unwrap();
    let module = load(&out);
    let main = entry_function(&module, "main");
    let stores = flipped_stores(main);
    assert_eq!(stores.len(), 1);
    // The store goes through an access chain into gl_PerVertex member 0 (gl_Position), right
    // before the return.
    let chain = main
        .all_inst_iter()
        .find(|i| i.result_id == Some(stores[0]))
        .expect("access chain");
    assert_eq!(chain.class.opcode, Op::AccessChain);
    let per_vertex = module
        .debug_names
        .iter()
        .find(|n| n.operands[1] == Operand::LiteralString(String::new()))
        .map(|n| n.operands[0].clone())
        .expect("gl_PerVertex variable named \"\"");
    assert_eq!(chain.operands[0], per_vertex);
    let Operand::IdRef(member) = chain.operands[1] else {
        panic!("member index")
    };
    let member = module
        .types_global_values
        .iter()
        .find(|i| i.result_id == Some(member))
        .expect("member constant");
    assert_eq!(member.operands[0], Operand::LiteralBit32(0));
    let ops: Vec<Op> = main.all_inst_iter().map(|i| i.class.opcode).collect();
    let ret = ops.iter().position(|op| *op == Op::Return).unwrap();
    assert_eq!(
        &ops[ret - 3..ret],
        &[Op::FNegate, Op::CompositeInsert, Op::Store]
    );

    let unflipped = rewrite(&input, ExecutionModel::Vertex, "main", &opts(false)).unwrap();
    assert_eq!(count_op(&load(&unflipped), Op::FNegate), 0);
    assert_eq!(count_op(&load(&input), Op::FNegate), 0);
}

#[test]
fn flips_a_position_variable() {
    // naga declares the position as its own Output variable decorated BuiltIn Position.
    let out = rewrite(
        &fixture("framelab_inspect_f3/sh138"),
        ExecutionModel::Vertex,
        "vs_main",
        &RewriteOptions {
            flip_y: true,
            binding: &|_, b, _| Some(b),
            specialization: &[],
            texel_formats: &[],
        },
    )
    .unwrap();
    let module = load(&out);
    let stores = flipped_stores(entry_function(&module, "vs_main"));
    assert_eq!(stores.len(), 1);
    let position = module
        .annotations
        .iter()
        .find(|d| {
            d.operands[1..]
                == [
                    Operand::Decoration(Decoration::BuiltIn),
                    Operand::BuiltIn(BuiltIn::Position),
                ]
        })
        .map(|d| d.operands[0].clone())
        .unwrap();
    assert_eq!(Operand::IdRef(stores[0]), position);
}

#[test]
fn flips_before_each_emitted_vertex_of_a_geometry_shader() {
    let out = rewrite(
        &geometry_module(),
        ExecutionModel::Geometry,
        "main",
        &opts(true),
    )
    .unwrap();
    let module = load(&out);
    let main = entry_function(&module, "main");
    assert_eq!(flipped_stores(main).len(), 2);
    let ops: Vec<Op> = main.all_inst_iter().map(|i| i.class.opcode).collect();
    for (n, op) in ops.iter().enumerate() {
        if *op == Op::EmitVertex {
            assert_eq!(ops[n - 1], Op::Store);
            assert_eq!(ops[n - 3], Op::FNegate);
        }
    }
    let ret = ops.iter().position(|op| *op == Op::Return).unwrap();
    assert_ne!(ops[ret - 1], Op::Store);
}

#[test]
fn sampled_image_used_in_another_block_is_joined_there() {
    let module = combined_sampler_module(Shape {
        cross_block: true,
        ..Shape::default()
    });
    let out = rewrite(&module, ExecutionModel::Fragment, "main", &opts(false)).unwrap();
    let module = load(&out);
    let main = entry_function(&module, "main");
    for block in &main.blocks {
        // Each OpImageSampleImplicitLod samples an OpSampledImage made in its own block.
        for i in &block.instructions {
            if i.class.opcode == Op::ImageSampleImplicitLod {
                let Operand::IdRef(sampled) = i.operands[0] else {
                    panic!()
                };
                assert!(
                    block
                        .instructions
                        .iter()
                        .any(|j| j.result_id == Some(sampled)
                            && j.class.opcode == Op::SampledImage),
                    "sampled image from another block"
                );
            }
        }
    }
    assert_eq!(count_op(&module, Op::SampledImage), 2);
}

#[test]
fn spirv_1_4_interface_lists_the_split_variables() {
    let module = combined_sampler_module(Shape {
        version_1_4: true,
        ..Shape::default()
    });
    let out = rewrite(&module, ExecutionModel::Fragment, "main", &opts(false)).unwrap();
    let r = reflect(&out).unwrap();
    let split: Vec<Word> = r.resources.iter().map(|v| v.id).collect();
    assert_eq!(split.len(), 2);
    let module = load(&out);
    let interface: Vec<Word> = module.entry_points[0].operands[3..]
        .iter()
        .map(|op| match op {
            Operand::IdRef(id) => *id,
            other => panic!("{other:?}"),
        })
        .collect();
    for id in &split {
        assert!(interface.contains(id), "{id} not in {interface:?}");
    }
    // Only the output and the two new variables.
    assert_eq!(interface.len(), 3);
}

// ---- errors -----------------------------------------------------------------------------------

#[test]
fn words_refuses_partial_words_and_bad_magic() {
    let bytes = std::fs::read(extracted().join("vkcube_f3/sh37")).unwrap();
    assert_eq!(
        words(&bytes[..bytes.len() - 1]),
        Err(SpirvError::NotWords {
            len: bytes.len() - 1
        })
    );
    let mut wrong = bytes.clone();
    wrong[0] = 0;
    assert!(matches!(words(&wrong), Err(SpirvError::BadMagic { found }) if found == 0x0723_0200));
    assert!(matches!(words(&[]), Err(SpirvError::Malformed { .. })));
    // A big-endian file reads as the same words.
    let swapped: Vec<u8> = bytes
        .chunks_exact(4)
        .flat_map(|c| [c[3], c[2], c[1], c[0]])
        .collect();
    assert_eq!(words(&swapped).unwrap(), words(&bytes).unwrap());
}

#[test]
fn truncated_module_is_malformed_at_the_cut_instruction() {
    let words = fixture("vkcube_f3/sh37");
    let cut = words.len() - 3;
    let err = reflect(&words[..cut]).unwrap_err();
    let SpirvError::Malformed { at_word, .. } = err else {
        panic!("{err:?}")
    };
    assert!(at_word <= cut && at_word > 5, "{at_word}");
    assert!(matches!(
        reflect(&words[..3]),
        Err(SpirvError::Malformed { .. })
    ));
    let mut bad = words.clone();
    bad[0] ^= 1;
    assert!(matches!(reflect(&bad), Err(SpirvError::BadMagic { .. })));
    assert!(matches!(
        rewrite(&words[..cut], ExecutionModel::Vertex, "main", &opts(true)),
        Err(SpirvError::Malformed { .. })
    ));
}

#[test]
fn binding_missing_from_the_layout_is_an_error() {
    let err = rewrite(
        &fixture("vkcube_f3/sh37"),
        ExecutionModel::Vertex,
        "main",
        &RewriteOptions {
            flip_y: false,
            binding: &|_, _, _| None,
            specialization: &[],
            texel_formats: &[],
        },
    )
    .unwrap_err();
    assert_eq!(
        err,
        SpirvError::BindingNotInLayout {
            set: 0,
            binding: 0,
            role: Role::Whole
        }
    );
    let err = rewrite(
        &fixture("vkcube_f3/sh38"),
        ExecutionModel::Fragment,
        "main",
        &RewriteOptions {
            flip_y: false,
            binding: &|_, b, role| (role != Role::SplitSampler).then_some(b),
            specialization: &[],
            texel_formats: &[],
        },
    )
    .unwrap_err();
    assert_eq!(
        err,
        SpirvError::BindingNotInLayout {
            set: 0,
            binding: 1,
            role: Role::SplitSampler
        }
    );
}

#[test]
fn missing_entry_point_is_an_error() {
    let words = fixture("vkcube_f3/sh37");
    for (model, name) in [
        (ExecutionModel::Vertex, "vs_main"),
        (ExecutionModel::Fragment, "main"),
    ] {
        assert_eq!(
            rewrite(&words, model, name, &opts(true)),
            Err(SpirvError::EntryPointNotFound {
                model,
                name: name.to_owned()
            })
        );
    }
}

#[test]
fn uses_the_split_cannot_follow_are_refused() {
    for (shape, feature, opcode) in [
        (
            Shape {
                array: true,
                ..Shape::default()
            },
            "array of combined image samplers",
            "",
        ),
        (
            Shape {
                copy: true,
                ..Shape::default()
            },
            "use of a combined image sampler other than loading it",
            "OpCopyObject",
        ),
        (
            Shape {
                grouped: true,
                ..Shape::default()
            },
            "descriptor decorated through a decoration group",
            "",
        ),
    ] {
        let err = rewrite(
            &combined_sampler_module(shape),
            ExecutionModel::Fragment,
            "main",
            &opts(false),
        )
        .unwrap_err();
        let SpirvError::Unsupported { feature: f, detail } = &err else {
            panic!("{err:?}")
        };
        assert_eq!(*f, feature);
        assert!(detail.contains("set 1 binding 3"), "{detail}");
        assert!(detail.contains(opcode), "{detail}");
    }
}

/// Every prefix, and many deterministic corruptions, of real modules: errors, never panics.
#[test]
fn damaged_modules_never_panic() {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let geometry = geometry_module();
    let inputs = [
        (
            "vkcube_f3/sh37",
            fixture("vkcube_f3/sh37"),
            ExecutionModel::Vertex,
        ),
        (
            "vkcube_f3/sh38",
            fixture("vkcube_f3/sh38"),
            ExecutionModel::Fragment,
        ),
        (
            "mpv_testsrc_f5/sh83",
            fixture("mpv_testsrc_f5/sh83"),
            ExecutionModel::Fragment,
        ),
        ("geometry", geometry, ExecutionModel::Geometry),
    ];
    let run = |words: &[u32], model| {
        let _ = reflect(words);
        let _ = rewrite(words, model, "main", &opts(true));
    };
    let mut variants = 0;
    for (name, words, model) in &inputs {
        for len in 0..words.len() {
            run(&words[..len], *model);
        }
        for _ in 0..1500 {
            let mut damaged = words.clone();
            for _ in 0..=(next() % 3) {
                let at = 5 + (next() % (words.len() as u64 - 5)) as usize;
                damaged[at] = match next() % 4 {
                    0 => damaged[at] ^ (1 << (next() % 32)),
                    1 => damaged[at].wrapping_add(1),
                    2 => next() as u32 % 64,
                    _ => next() as u32,
                };
            }
            if std::panic::catch_unwind(|| run(&damaged, *model)).is_err() {
                panic!("{name}: panicked on {damaged:?}");
            }
            variants += 1;
        }
    }
    assert_eq!(variants, 6000);
}

// ---- naga -------------------------------------------------------------------------------------

fn naga_accepts(words: &[u32]) -> Result<(), String> {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let module = naga::front::spv::parse_u8_slice(&bytes, &naga::front::spv::Options::default())
        .map_err(|e| format!("parse: {e:?}"))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| format!("validate: {e:?}"))?;
    Ok(())
}

#[test]
fn naga_reads_rewritten_vkcube_modules() {
    let fragment = rewrite(
        &fixture("vkcube_f3/sh38"),
        ExecutionModel::Fragment,
        "main",
        &opts(false),
    )
    .unwrap();
    naga_accepts(&fragment).unwrap();
    let vertex = rewrite(
        &fixture("vkcube_f3/sh37"),
        ExecutionModel::Vertex,
        "main",
        &opts(true),
    )
    .unwrap();
    naga_accepts(&vertex).unwrap();
}

/// naga's SPIR-V front end is stricter than Vulkan in places (capabilities it lacks, matrix
/// strides): the rewrite must not add to what it refuses.
#[test]
fn naga_accepts_every_rewritten_fixture_it_accepted_before() {
    let mut accepted = 0;
    for (name, words) in all_fixtures() {
        for e in reflect(&words).unwrap().entry_points {
            let out = rewrite(&words, e.model, &e.name, &opts(true)).unwrap();
            match (naga_accepts(&words), naga_accepts(&out)) {
                (_, Ok(())) => accepted += 1,
                (Ok(()), Err(after)) => panic!("{name} {}: {after}", e.name),
                (Err(_), Err(_)) => {}
            }
        }
    }
    // Every vkcube module among them: the fragment shaders only once split.
    assert!(accepted >= 24, "{accepted}");
}

// ---- spirv-val (development) ------------------------------------------------------------------

/// Rewrites every entry point of every fixture module and runs SPIRV-Tools' validator on the
/// result. Needs `spirv-val` on PATH, and fails when it is missing: run with `--ignored`.
#[test]
#[ignore = "needs spirv-val (SPIRV-Tools) on PATH"]
fn rewritten_fixtures_pass_spirv_val() {
    let dir = std::env::temp_dir().join(format!("framelab-spirv-val-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut failures = Vec::new();
    let mut checked = 0;
    let mut modules: Vec<(String, Vec<u32>)> = all_fixtures();
    for shape in [
        Shape::default(),
        Shape {
            cross_block: true,
            ..Shape::default()
        },
        Shape {
            version_1_4: true,
            ..Shape::default()
        },
    ] {
        modules.push((format!("built {shape:?}"), combined_sampler_module(shape)));
    }
    modules.push(("built geometry".to_owned(), geometry_module()));
    for (name, words) in modules {
        let r = reflect(&words).unwrap();
        for e in &r.entry_points {
            for flip_y in [false, true] {
                let out = rewrite(&words, e.model, &e.name, &opts(flip_y))
                    .unwrap_or_else(|err| panic!("{name} {}: {err}", e.name));
                let file = dir.join(format!(
                    "{}-{}-{flip_y}.spv",
                    name.replace(['/', ' '], "_"),
                    e.name
                ));
                std::fs::write(&file, without_wgsl_source(&out)).unwrap();
                let env = match load(&out).header.as_ref().unwrap().version() {
                    (1, 0) => "vulkan1.0",
                    (1, 1..=3) => "vulkan1.1",
                    (1, 4) => "vulkan1.1spv1.4",
                    (1, 5) => "vulkan1.2",
                    _ => "vulkan1.3",
                };
                let result = std::process::Command::new("spirv-val")
                    .args(["--target-env", env])
                    .arg(&file)
                    .output()
                    .expect("spirv-val (SPIRV-Tools) must be installed for this test");
                checked += 1;
                if !result.status.success() {
                    failures.push(format!(
                        "{name} {} flip_y={flip_y}: {}",
                        e.name,
                        String::from_utf8_lossy(&result.stderr)
                    ));
                }
            }
        }
    }
    if std::env::var_os("FRAMELAB_KEEP_SPIRV").is_none() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!(
        "spirv-val accepted {checked} rewritten modules (in {})",
        dir.display()
    );
    assert!(checked >= 80, "{checked}");
}

/// naga writes `OpSource WGSL`, which SPIRV-Tools before 2023.2 does not know; the source
/// language says nothing about validity.
fn without_wgsl_source(words: &[u32]) -> Vec<u8> {
    let mut module = load(words);
    module
        .debug_string_source
        .retain(|i| i.class.opcode != Op::Source);
    module
        .assemble()
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect()
}

// ---- modules built here -----------------------------------------------------------------------

/// Variations of a fragment shader sampling a combined image sampler at set 1 binding 3.
#[derive(Debug, Default, Clone, Copy)]
struct Shape {
    /// An array of two combined image samplers.
    array: bool,
    /// The array length is a specialization constant.
    spec_array: bool,
    /// The variable is also passed to OpCopyObject.
    copy: bool,
    /// Loaded in the first block, sampled in the next.
    cross_block: bool,
    /// SPIR-V 1.4, where the interface lists the variable.
    version_1_4: bool,
    /// DescriptorSet and Binding come through a decoration group.
    grouped: bool,
}

fn combined_sampler_module(shape: Shape) -> Vec<u32> {
    let mut b = Builder::new();
    if shape.version_1_4 {
        b.set_version(1, 4);
    } else {
        b.set_version(1, 0);
    }
    b.capability(Capability::Shader);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let float = b.type_float(32, None);
    let vec2 = b.type_vector(float, 2);
    let vec4 = b.type_vector(float, 4);
    let image = b.type_image(float, Dim::Dim2D, 0, 0, 0, 1, ImageFormat::Unknown, None);
    let sampled = b.type_sampled_image(image);
    let uint = b.type_int(32, 0);
    let held = if shape.array || shape.spec_array {
        let two = if shape.spec_array {
            b.spec_constant_bit32(uint, 2)
        } else {
            b.constant_bit32(uint, 2)
        };
        b.type_array(sampled, two)
    } else {
        sampled
    };
    let ptr = b.type_pointer(None, StorageClass::UniformConstant, held);
    let tex = b.variable(ptr, None, StorageClass::UniformConstant, None);
    b.name(tex, "tex");
    let target = if shape.grouped {
        let group = b.decoration_group();
        b.group_decorate(group, [tex]);
        group
    } else {
        tex
    };
    b.decorate(
        target,
        Decoration::DescriptorSet,
        [Operand::LiteralBit32(1)],
    );
    b.decorate(target, Decoration::Binding, [Operand::LiteralBit32(3)]);
    let out_ptr = b.type_pointer(None, StorageClass::Output, vec4);
    let color = b.variable(out_ptr, None, StorageClass::Output, None);
    b.decorate(color, Decoration::Location, [Operand::LiteralBit32(0)]);
    let half = b.constant_bit32(float, 0.5f32.to_bits());
    let coord = b.constant_composite(vec2, [half, half]);
    let elem_ptr = b.type_pointer(None, StorageClass::UniformConstant, sampled);
    let zero = b.constant_bit32(uint, 0);

    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    let source = if shape.array || shape.spec_array {
        b.access_chain(elem_ptr, None, tex, [zero]).unwrap()
    } else {
        tex
    };
    if shape.copy {
        b.copy_object(ptr, None, tex).unwrap();
    }
    let joined = b.load(sampled, None, source, None, []).unwrap();
    if shape.cross_block {
        let next = b.id();
        b.branch(next).unwrap();
        b.begin_block(Some(next)).unwrap();
    }
    let texel = b
        .image_sample_implicit_lod(vec4, None, joined, coord, None, [])
        .unwrap();
    b.store(color, texel, None, []).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    let interface = if shape.version_1_4 {
        vec![color, tex]
    } else {
        vec![color]
    };
    b.entry_point(ExecutionModel::Fragment, f, "main", interface);
    b.execution_mode(f, ExecutionMode::OriginUpperLeft, []);
    b.module().assemble()
}

/// A geometry shader emitting two vertices through a BuiltIn Position variable.
fn geometry_module() -> Vec<u32> {
    let mut b = Builder::new();
    b.set_version(1, 0);
    b.capability(Capability::Geometry);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let float = b.type_float(32, None);
    let vec4 = b.type_vector(float, 4);
    let out_ptr = b.type_pointer(None, StorageClass::Output, vec4);
    let position = b.variable(out_ptr, None, StorageClass::Output, None);
    b.decorate(
        position,
        Decoration::BuiltIn,
        [Operand::BuiltIn(BuiltIn::Position)],
    );
    let one = b.constant_bit32(float, 1.0f32.to_bits());
    let corner = b.constant_composite(vec4, [one, one, one, one]);
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    for _ in 0..2 {
        b.store(position, corner, None, []).unwrap();
        b.emit_vertex().unwrap();
    }
    b.end_primitive().unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::Geometry, f, "main", [position]);
    b.execution_mode(f, ExecutionMode::InputPoints, []);
    b.execution_mode(f, ExecutionMode::OutputTriangleStrip, []);
    b.execution_mode(f, ExecutionMode::OutputVertices, [2]);
    b.execution_mode(f, ExecutionMode::Invocations, [1]);
    b.module().assemble()
}

/// mpv's upload shader: its R8 storage texel buffer becomes a read-only storage buffer of
/// words at the same set and binding, read by no OpImageRead any more, and the three
/// specialization constants it was given become plain constants without SpecId.
#[test]
fn texel_buffer_reads_become_word_loads_and_specialization_applies() {
    let words = fixture("mpv_testsrc_f5/sh73");
    let spec = [(0u32, 1u64), (1, 3), (2, 640 * 3)];
    let out = rewrite(
        &words,
        ExecutionModel::GLCompute,
        "main",
        &RewriteOptions {
            flip_y: false,
            binding: &doubled,
            specialization: &spec,
            texel_formats: &[],
        },
    )
    .unwrap();
    let r = reflect(&out).unwrap();
    assert_eq!(r.resources[0].kind, ResourceKind::StorageBuffer);
    assert_eq!((r.resources[0].set, r.resources[0].binding), (0, 0));
    assert!(r.resources[0].non_writable);
    let module = rspirv::dr::load_words(&out).unwrap();
    let ops: Vec<Op> = module.all_inst_iter().map(|i| i.class.opcode).collect();
    assert!(!ops.contains(&Op::ImageRead), "a texel buffer read is left");
    assert_eq!(
        ops.iter().filter(|&&o| o == Op::BitFieldUExtract).count(),
        3,
        "one byte extracted per read"
    );
    assert!(!ops.contains(&Op::SpecConstant));
    assert!(
        !module
            .annotations
            .iter()
            .any(|a| a.operands.get(1) == Some(&Operand::Decoration(Decoration::SpecId)))
    );
    let values: BTreeSet<u32> = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::Constant)
        .filter_map(|i| match i.operands.first() {
            Some(Operand::LiteralBit32(v)) => Some(*v),
            _ => None,
        })
        .collect();
    assert!(values.contains(&(640 * 3)), "{values:?}");
    // Unchanged without the values: reads of a texel buffer are rewritten all the same.
    let plain = rewrite(&words, ExecutionModel::GLCompute, "main", &opts(false)).unwrap();
    let module = rspirv::dr::load_words(&plain).unwrap();
    assert!(
        module
            .all_inst_iter()
            .any(|i| i.class.opcode == Op::SpecConstant)
    );
}
