//! Modules shaped as Mesa's zink writes every OpenGL shader: SPIR-V 1.5 under the Vulkan
//! memory model, uniform blocks packed as arrays of 32-bit words (std430: array stride 4) in a
//! one-element block array, with `UniformBufferArrayDynamicIndexing` declared.

use rspirv::dr::{InsertPoint, Instruction};
use rspirv::spirv::{MemoryAccess, MemorySemantics, Scope};

use super::*;

/// What to add to the zink-shaped module.
#[derive(Clone, Copy, Default)]
struct Extra {
    /// A memory barrier that makes memory available (only the Vulkan model has that).
    make_available: bool,
    /// A load marked `NonPrivatePointer`.
    non_private: bool,
    /// A second read of the block, at the word the first one read (an index known only when
    /// the shader runs).
    dynamic: bool,
    /// A load of the whole array of words.
    whole: bool,
}

/// A fragment shader writing word 1 of the uniform block at set 0 binding 0 as its colour.
fn zink_module(extra: Extra) -> Vec<u32> {
    let mut b = Builder::new();
    b.set_version(1, 5);
    b.capability(Capability::Shader);
    b.capability(Capability::UniformBufferArrayDynamicIndexing);
    b.capability(Capability::VulkanMemoryModel);
    b.memory_model(AddressingModel::Logical, MemoryModel::Vulkan);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let uint = b.type_int(32, 0);
    let float = b.type_float(32, None);
    let vec4 = b.type_vector(float, 4);
    let (zero, one, four) = (
        b.constant_bit32(uint, 0),
        b.constant_bit32(uint, 1),
        b.constant_bit32(uint, 4),
    );
    let words = b.type_array(uint, four);
    b.decorate(words, Decoration::ArrayStride, [Operand::LiteralBit32(4)]);
    let block = b.type_struct([words]);
    b.decorate(block, Decoration::Block, []);
    b.member_decorate(block, 0, Decoration::Offset, [Operand::LiteralBit32(0)]);
    let blocks = b.type_array(block, one);
    let blocks_ptr = b.type_pointer(None, StorageClass::Uniform, blocks);
    let ubo = b.variable(blocks_ptr, None, StorageClass::Uniform, None);
    b.decorate(ubo, Decoration::DescriptorSet, [Operand::LiteralBit32(0)]);
    b.decorate(ubo, Decoration::Binding, [Operand::LiteralBit32(0)]);
    let word_ptr = b.type_pointer(None, StorageClass::Uniform, uint);
    let out_ptr = b.type_pointer(None, StorageClass::Output, vec4);
    let color = b.variable(out_ptr, None, StorageClass::Output, None);
    b.decorate(color, Decoration::Location, [Operand::LiteralBit32(0)]);
    let semantics = b.constant_bit32(
        uint,
        (MemorySemantics::ACQUIRE_RELEASE
            | MemorySemantics::UNIFORM_MEMORY
            | MemorySemantics::MAKE_AVAILABLE)
            .bits(),
    );
    let device = b.constant_bit32(uint, Scope::Device as u32);
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    let first = b
        .access_chain(word_ptr, None, ubo, [zero, zero, one])
        .unwrap();
    let copied = b.copy_object(word_ptr, None, first).unwrap();
    let access = extra
        .non_private
        .then_some(MemoryAccess::NON_PRIVATE_POINTER);
    let word = b.load(uint, None, copied, access, []).unwrap();
    if extra.make_available {
        b.insert_into_block(
            InsertPoint::End,
            Instruction::new(
                Op::MemoryBarrier,
                None,
                None,
                vec![Operand::IdRef(device), Operand::IdRef(semantics)],
            ),
        )
        .unwrap();
    }
    let word = if extra.dynamic {
        let at = b
            .access_chain(word_ptr, None, ubo, [zero, zero, word])
            .unwrap();
        b.load(uint, None, at, None, []).unwrap()
    } else {
        word
    };
    if extra.whole {
        let words_ptr = b.type_pointer(None, StorageClass::Uniform, words);
        let all = b.access_chain(words_ptr, None, ubo, [zero, zero]).unwrap();
        b.load(words, None, all, None, []).unwrap();
    }
    let value = b.bitcast(float, None, word).unwrap();
    let rgba = b
        .composite_construct(vec4, None, [value, value, value, value])
        .unwrap();
    b.store(color, rgba, None, []).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::Fragment, f, "main", [ubo, color]);
    b.execution_mode(f, ExecutionMode::OriginUpperLeft, []);
    b.module().assemble()
}

fn storage_opts() -> RewriteOptions<'static> {
    RewriteOptions {
        storage_blocks: &[(0, 0)],
        std140_blocks: &[],
        unnormalized: &[],
        mirror_once: &[],
        ..opts(false)
    }
}

fn storage_class_of_variables(m: &Module) -> Vec<StorageClass> {
    m.types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::Variable)
        .filter_map(|i| match i.operands.first() {
            Some(Operand::StorageClass(c)) => Some(*c),
            _ => None,
        })
        .collect()
}

fn capabilities(m: &Module) -> Vec<Capability> {
    m.capabilities
        .iter()
        .filter_map(|i| match i.operands.first() {
            Some(Operand::Capability(c)) => Some(*c),
            _ => None,
        })
        .collect()
}

#[test]
fn a_word_packed_uniform_block_is_past_std140_and_within_std430() {
    let found = uniform_blocks_beyond_std140(&zink_module(Extra::default()));
    assert_eq!(found.len(), 1);
    let b = &found[0];
    assert_eq!((b.set, b.binding), (0, 0));
    assert!(b.problem.contains("stride 4"), "{}", b.problem);
    assert_eq!(b.beyond_std430, None);
    // Four words make one vector of four at a stride of 16.
    assert_eq!(b.widened_end, Some(16));
}

/// The words become vectors of four at a stride of 16 (std140, which every uniform binding
/// reads), and the block stays a uniform block: no storage read, which a driver may leave
/// undone in helper invocations and so break the derivatives of what is made from it.
#[test]
fn a_word_packed_uniform_block_is_widened_to_std140_and_stays_uniform() {
    let out = rewrite(
        &zink_module(Extra {
            dynamic: true,
            ..Extra::default()
        }),
        ExecutionModel::Fragment,
        "main",
        &RewriteOptions {
            std140_blocks: &[(0, 0)],
            ..opts(false)
        },
    )
    .unwrap();
    let m = load(&out);
    let classes = storage_class_of_variables(&m);
    assert!(classes.contains(&StorageClass::Uniform), "{classes:?}");
    assert!(
        !classes.contains(&StorageClass::StorageBuffer),
        "{classes:?}"
    );
    let stride16: Vec<Word> = m
        .annotations
        .iter()
        .filter(|i| {
            i.operands.get(1) == Some(&Operand::Decoration(Decoration::ArrayStride))
                && i.operands.get(2) == Some(&Operand::LiteralBit32(16))
        })
        .filter_map(|i| match i.operands[0] {
            Operand::IdRef(id) => Some(id),
            _ => None,
        })
        .collect();
    assert_eq!(stride16.len(), 1, "one array of vectors");
    // Word 1 is component 1 of vector 0; the word read at run time is split by shift and mask.
    let chains: Vec<usize> = m
        .all_inst_iter()
        .filter(|i| i.class.opcode == Op::AccessChain)
        .map(|i| i.operands.len())
        .collect();
    assert_eq!(chains, vec![5, 5], "base and four indices each: {chains:?}");
    let ops: Vec<Op> = m.all_inst_iter().map(|i| i.class.opcode).collect();
    assert!(ops.contains(&Op::ShiftRightLogical) && ops.contains(&Op::BitwiseAnd));
    // spirv-val's Vulkan rules for uniform blocks (std140, relaxed) without scalar layout:
    // the module before widening fails them.
    super::validators::spirv_val(&out, "zink-std140").unwrap();
    assert!(super::validators::spirv_val(&zink_module(Extra::default()), "zink-std430").is_err());
    super::validators::naga_accepts(&out).unwrap();
}

/// An array loaded whole cannot be widened in place: the block is read as a storage block.
#[test]
fn a_block_whose_array_is_loaded_whole_is_not_widened() {
    let module = zink_module(Extra {
        whole: true,
        ..Extra::default()
    });
    let found = uniform_blocks_beyond_std140(&module);
    assert_eq!(found[0].widened_end, None);
    let err = rewrite(
        &module,
        ExecutionModel::Fragment,
        "main",
        &RewriteOptions {
            std140_blocks: &[(0, 0)],
            ..opts(false)
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("set 0 binding 0") && err.contains("OpLoad"),
        "{err}"
    );
    rewrite(&module, ExecutionModel::Fragment, "main", &storage_opts()).unwrap();
}

#[test]
fn a_zink_module_becomes_a_glsl450_module_reading_a_storage_block() {
    let out = rewrite(
        &zink_module(Extra {
            non_private: true,
            ..Extra::default()
        }),
        ExecutionModel::Fragment,
        "main",
        &storage_opts(),
    )
    .unwrap();
    let m = load(&out);
    assert_eq!(
        m.memory_model.as_ref().unwrap().operands[1],
        Operand::MemoryModel(MemoryModel::GLSL450)
    );
    let caps = capabilities(&m);
    assert!(!caps.contains(&Capability::VulkanMemoryModel), "{caps:?}");
    // Its one-block array can only be indexed by 0.
    assert!(
        !caps.contains(&Capability::UniformBufferArrayDynamicIndexing),
        "{caps:?}"
    );
    let classes = storage_class_of_variables(&m);
    assert!(
        classes.contains(&StorageClass::StorageBuffer),
        "{classes:?}"
    );
    assert!(!classes.contains(&StorageClass::Uniform), "{classes:?}");
    // Every pointer into the block, the chain and its copy, is a storage-buffer pointer.
    let storage_pointers: BTreeSet<Word> = m
        .types_global_values
        .iter()
        .filter(|i| {
            i.class.opcode == Op::TypePointer
                && i.operands[0] == Operand::StorageClass(StorageClass::StorageBuffer)
        })
        .filter_map(|i| i.result_id)
        .collect();
    for i in m.all_inst_iter().filter(|i| {
        matches!(
            i.class.opcode,
            Op::AccessChain | Op::CopyObject | Op::Variable
        ) && i.operands.first() != Some(&Operand::StorageClass(StorageClass::Output))
    }) {
        assert!(
            storage_pointers.contains(&i.result_type.unwrap()),
            "{:?} keeps a uniform pointer",
            i.class.opcode
        );
    }
    assert!(
        m.annotations
            .iter()
            .any(|i| { i.operands.get(1) == Some(&Operand::Decoration(Decoration::NonWritable)) })
    );
    // NonPrivatePointer means nothing under GLSL450's model.
    assert!(
        !m.all_inst_iter()
            .any(|i| i.operands.iter().any(|o| matches!(
                o,
                Operand::MemoryAccess(a) if a.contains(MemoryAccess::NON_PRIVATE_POINTER)
            )))
    );
    super::validators::naga_accepts(&out).unwrap();
    super::validators::spirv_val(&out, "zink-storage").unwrap();
}

#[test]
fn without_storage_blocks_the_uniform_block_stays() {
    let out = rewrite(
        &zink_module(Extra::default()),
        ExecutionModel::Fragment,
        "main",
        &opts(false),
    )
    .unwrap();
    let classes = storage_class_of_variables(&load(&out));
    assert!(classes.contains(&StorageClass::Uniform), "{classes:?}");
}

#[test]
fn availability_the_vulkan_model_alone_gives_is_refused_by_name() {
    let err = rewrite(
        &zink_module(Extra {
            make_available: true,
            ..Extra::default()
        }),
        ExecutionModel::Fragment,
        "main",
        &storage_opts(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("Vulkan memory model availability or visibility"),
        "{err}"
    );
    assert!(err.contains("OpMemoryBarrier"), "{err}");
    assert!(err.contains("MAKE_AVAILABLE"), "{err}");
}

/// A vec3 across a 16-byte boundary: scalar layout, which no wgpu binding reads.
#[test]
fn a_scalar_block_is_past_std430_too() {
    let mut b = Builder::new();
    b.set_version(1, 0);
    b.capability(Capability::Shader);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let float = b.type_float(32, None);
    let vec3 = b.type_vector(float, 3);
    let block = b.type_struct([float, vec3]);
    b.decorate(block, Decoration::Block, []);
    b.member_decorate(block, 0, Decoration::Offset, [Operand::LiteralBit32(0)]);
    b.member_decorate(block, 1, Decoration::Offset, [Operand::LiteralBit32(8)]);
    let ptr = b.type_pointer(None, StorageClass::Uniform, block);
    let ubo = b.variable(ptr, None, StorageClass::Uniform, None);
    b.decorate(ubo, Decoration::DescriptorSet, [Operand::LiteralBit32(1)]);
    b.decorate(ubo, Decoration::Binding, [Operand::LiteralBit32(2)]);
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::Fragment, f, "main", []);
    b.execution_mode(f, ExecutionMode::OriginUpperLeft, []);
    let found = uniform_blocks_beyond_std140(&b.module().assemble());
    assert_eq!(found.len(), 1);
    assert_eq!((found[0].set, found[0].binding), (1, 2));
    let why = found[0]
        .beyond_std430
        .as_ref()
        .expect("past std430")
        .to_string();
    assert_eq!(found[0].problem, "has a 12-byte vector at offset 8");
    assert_eq!(why, "has a 12-byte vector at offset 8");
}

/// A vertex shader writing `gl_Layer` (zink's blit and clear shaders write the instance there):
/// the replay renders one layer, so the output becomes private and `ShaderLayer` goes; the
/// module passes spirv-val and naga.
#[test]
fn a_layer_output_becomes_private() {
    let mut b = Builder::new();
    b.set_version(1, 5);
    b.capability(Capability::Shader);
    b.capability(Capability::ShaderLayer);
    b.memory_model(AddressingModel::Logical, MemoryModel::GLSL450);
    let void = b.type_void();
    let fn_ty = b.type_function(void, []);
    let int = b.type_int(32, 1);
    let float = b.type_float(32, None);
    let vec4 = b.type_vector(float, 4);
    let zero = b.constant_bit32(int, 0);
    let fzero = b.constant_bit32(float, 0);
    let origin = b.constant_composite(vec4, [fzero, fzero, fzero, fzero]);
    let int_out = b.type_pointer(None, StorageClass::Output, int);
    let layer = b.variable(int_out, None, StorageClass::Output, None);
    b.decorate(
        layer,
        Decoration::BuiltIn,
        [Operand::BuiltIn(rspirv::spirv::BuiltIn::Layer)],
    );
    let vec_out = b.type_pointer(None, StorageClass::Output, vec4);
    let position = b.variable(vec_out, None, StorageClass::Output, None);
    b.decorate(
        position,
        Decoration::BuiltIn,
        [Operand::BuiltIn(rspirv::spirv::BuiltIn::Position)],
    );
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    b.store(position, origin, None, []).unwrap();
    b.store(layer, zero, None, []).unwrap();
    b.ret().unwrap();
    b.end_function().unwrap();
    b.entry_point(ExecutionModel::Vertex, f, "main", [layer, position]);
    let out = rewrite(
        &b.module().assemble(),
        ExecutionModel::Vertex,
        "main",
        &opts(false),
    )
    .unwrap();
    let m = load(&out);
    assert!(!capabilities(&m).contains(&Capability::ShaderLayer));
    assert!(
        !m.annotations
            .iter()
            .any(|a| a.operands.get(2) == Some(&Operand::BuiltIn(rspirv::spirv::BuiltIn::Layer)))
    );
    assert!(storage_class_of_variables(&m).contains(&StorageClass::Private));
    super::validators::spirv_val(&out, "layer").unwrap();
    super::validators::naga_accepts(&out).unwrap();
}

/// Qt 5 Quick's OpenGL renderer through zink: the vertex shader declares `ShaderLayer` and
/// writes no layer. The capability, which needs a device feature wgpu does not turn on, goes.
#[test]
fn a_layer_capability_nothing_uses_is_dropped() {
    let words = fixture("qt5_gl_zink/vertex");
    assert!(capabilities(&load(&words)).contains(&Capability::ShaderLayer));
    let out = rewrite(&words, ExecutionModel::Vertex, "main", &opts(true)).unwrap();
    assert!(!capabilities(&load(&out)).contains(&Capability::ShaderLayer));
}
