//! Rewriting: splits, renumbering, the clip-space flip, texel buffers and specialization.

use super::*;

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
            lod_bias: &[],
            gl_depth: false,
            swizzles: &[],
            storage_blocks: &[],
            std140_blocks: &[],
            unnormalized: &[],
            mirror_once: &[],
            attached_outputs: None,
            scaled_inputs: &[],
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

/// OpenGL's clip-space depth (-w to w, zink's `negativeOneToOne`) becomes Vulkan's (0 to w)
/// before the return: z and w extracted, (z + w) * 0.5 inserted as z and stored, after the y
/// flip when there is one and alone when there is not.
#[test]
fn maps_opengl_depth_before_the_return() {
    let input = fixture("vkcube_f3/sh37");
    for flip_y in [true, false] {
        let out = rewrite(
            &input,
            ExecutionModel::Vertex,
            "main",
            &RewriteOptions {
                gl_depth: true,
                swizzles: &[],
                storage_blocks: &[],
                std140_blocks: &[],
                unnormalized: &[],
                mirror_once: &[],
                attached_outputs: None,
                ..opts(flip_y)
            },
        )
        .unwrap();
        let module = load(&out);
        let main = entry_function(&module, "main");
        let insts: Vec<_> = main.all_inst_iter().collect();
        let ret = insts
            .iter()
            .position(|i| i.class.opcode == Op::Return)
            .unwrap();
        let ops: Vec<Op> = insts[ret - 6..ret].iter().map(|i| i.class.opcode).collect();
        assert_eq!(
            ops,
            [
                Op::CompositeExtract,
                Op::CompositeExtract,
                Op::FAdd,
                Op::FMul,
                Op::CompositeInsert,
                Op::Store,
            ]
        );
        let z = insts[ret - 6];
        let w = insts[ret - 5];
        assert_eq!(z.operands[1], Operand::LiteralBit32(2));
        assert_eq!(w.operands[1], Operand::LiteralBit32(3));
        let mul = insts[ret - 3];
        assert_eq!(mul.class.opcode, Op::FMul);
        let Operand::IdRef(half) = mul.operands[1] else {
            panic!("a constant operand")
        };
        let half = module
            .types_global_values
            .iter()
            .find(|i| i.result_id == Some(half))
            .expect("the constant");
        assert_eq!(half.operands[0], Operand::LiteralBit32(0.5f32.to_bits()));
        let insert = insts[ret - 2];
        assert_eq!(insert.operands[2], Operand::LiteralBit32(2));
        assert_eq!(count_op(&module, Op::FNegate), usize::from(flip_y));
    }
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
            lod_bias: &[],
            gl_depth: false,
            swizzles: &[],
            storage_blocks: &[],
            std140_blocks: &[],
            unnormalized: &[],
            mirror_once: &[],
            attached_outputs: None,
            scaled_inputs: &[],
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
            lod_bias: &[],
            gl_depth: false,
            swizzles: &[],
            storage_blocks: &[],
            std140_blocks: &[],
            unnormalized: &[],
            mirror_once: &[],
            attached_outputs: None,
            scaled_inputs: &[],
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

/// A combined image sampler sampled in a function that takes it as a parameter: the
/// parameter is removed, the function loads the split variables itself, and the module
/// keeps no use of the combined variable.
#[test]
fn combined_sampler_passed_to_a_function_is_split_there() {
    let words = combined_sampler_module(Shape {
        via_function: true,
        ..Shape::default()
    });
    let out = rewrite(&words, ExecutionModel::Fragment, "main", &opts(false)).unwrap();
    let module = load(&out);
    let r = reflect(&out).unwrap();
    assert_eq!(
        binding_of(&r, 1, 6),
        vec![&ResourceKind::SampledImage(TEXTURE_2D)]
    );
    assert_eq!(
        binding_of(&r, 1, 7),
        vec![&ResourceKind::Sampler { comparison: false }]
    );
    assert!(binding_of(&r, 1, 3).is_empty(), "no combined variable left");
    assert_eq!(count_op(&module, Op::SampledImage), 1);
    assert!(
        module.functions.iter().all(|f| f.parameters.is_empty()),
        "the sampler parameter is gone"
    );
    let calls = module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .filter(|i| i.class.opcode == Op::FunctionCall)
        .collect::<Vec<_>>();
    assert_eq!(calls.len(), 1);
    assert_eq!(calls[0].operands.len(), 1, "the call passes nothing");
}

/// A helper called with two different combined image samplers (Qt Quick 3D's shadow-map
/// sampling per light): the helper is copied, each copy loads one pair of split variables,
/// and the result is valid SPIR-V that naga takes.
#[test]
fn a_function_given_different_samplers_is_copied_per_sampler() {
    let words = combined_sampler_module(Shape {
        via_function: true,
        second_call: true,
        ..Shape::default()
    });
    let out = rewrite(&words, ExecutionModel::Fragment, "main", &opts(false)).unwrap();
    let module = load(&out);
    let r = reflect(&out).unwrap();
    for (image, sampler) in [(6, 7), (8, 9)] {
        assert_eq!(
            binding_of(&r, 1, image),
            vec![&ResourceKind::SampledImage(TEXTURE_2D)]
        );
        assert_eq!(
            binding_of(&r, 1, sampler),
            vec![&ResourceKind::Sampler { comparison: false }]
        );
    }
    assert!(binding_of(&r, 1, 3).is_empty() && binding_of(&r, 1, 4).is_empty());
    assert_eq!(module.functions.len(), 3, "main and a helper per sampler");
    assert_eq!(count_op(&module, Op::SampledImage), 2);
    let callees: BTreeSet<Word> = module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .filter(|i| i.class.opcode == Op::FunctionCall)
        .filter_map(|i| match i.operands.first() {
            Some(Operand::IdRef(f)) => Some(*f),
            _ => None,
        })
        .collect();
    assert_eq!(callees.len(), 2, "each call its own copy");
    super::validators::spirv_val(&out, "copied_helper").unwrap();
    assert!(super::validators::naga_accepts(&out).is_ok());
}

/// A sampler's LOD bias reaches the samples taken through it: an implicit-LOD sample gets a
/// Bias image operand holding the bias; a module with no biased binding is left alone.
#[test]
fn sampler_lod_bias_becomes_a_bias_operand() {
    let words = combined_sampler_module(Shape::default());
    let biased = RewriteOptions {
        lod_bias: &[(1, 3, -0.5)],
        ..opts(false)
    };
    let out = rewrite(&words, ExecutionModel::Fragment, "main", &biased).unwrap();
    let module = load(&out);
    let sample = module
        .functions
        .iter()
        .flat_map(|f| f.all_inst_iter())
        .find(|i| i.class.opcode == Op::ImageSampleImplicitLod)
        .unwrap();
    assert_eq!(
        sample.operands.get(2),
        Some(&Operand::ImageOperands(rspirv::spirv::ImageOperands::BIAS))
    );
    let Some(Operand::IdRef(c)) = sample.operands.get(3) else {
        panic!("no bias argument: {sample:?}")
    };
    let constant = module
        .types_global_values
        .iter()
        .find(|i| i.result_id == Some(*c))
        .unwrap();
    assert_eq!(
        constant.operands,
        vec![Operand::LiteralBit32((-0.5f32).to_bits())]
    );
    let elsewhere = RewriteOptions {
        lod_bias: &[(1, 4, -0.5)],
        ..opts(false)
    };
    let out = rewrite(&words, ExecutionModel::Fragment, "main", &elsewhere).unwrap();
    let plain = rewrite(&words, ExecutionModel::Fragment, "main", &opts(false)).unwrap();
    assert_eq!(out, plain, "a bias at another binding changes nothing");
}
