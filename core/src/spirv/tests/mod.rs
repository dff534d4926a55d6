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
        lod_bias: &[],
        gl_depth: false,
        swizzles: &[],
        storage_blocks: &[],
        std140_blocks: &[],
        unnormalized: &[],
        mirror_once: &[],
        attached_outputs: None,
        scaled_inputs: &[],
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
    /// Sampled in a function that takes the sampler as a parameter (glslang's `sampler2D`
    /// argument), called from main.
    via_function: bool,
    /// A second variable at set 1 binding 4: with `via_function`, passed by a second call;
    /// without, declared and never used.
    second_call: bool,
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

    let other = shape.second_call.then(|| {
        let v = b.variable(ptr, None, StorageClass::UniformConstant, None);
        b.decorate(v, Decoration::DescriptorSet, [Operand::LiteralBit32(1)]);
        b.decorate(v, Decoration::Binding, [Operand::LiteralBit32(4)]);
        v
    });
    let helper = shape.via_function.then(|| {
        let helper_ty = b.type_function(vec4, [ptr]);
        let h = b
            .begin_function(vec4, None, FunctionControl::NONE, helper_ty)
            .unwrap();
        let param = b.function_parameter(ptr).unwrap();
        b.begin_block(None).unwrap();
        let joined = b.load(sampled, None, param, None, []).unwrap();
        let texel = b
            .image_sample_implicit_lod(vec4, None, joined, coord, None, [])
            .unwrap();
        b.ret_value(texel).unwrap();
        b.end_function().unwrap();
        h
    });
    let f = b
        .begin_function(void, None, FunctionControl::NONE, fn_ty)
        .unwrap();
    b.begin_block(None).unwrap();
    if let Some(h) = helper {
        let texel = b.function_call(vec4, None, h, [tex]).unwrap();
        if let Some(v) = other {
            b.function_call(vec4, None, h, [v]).unwrap();
        }
        b.store(color, texel, None, []).unwrap();
        b.ret().unwrap();
        b.end_function().unwrap();
        b.entry_point(ExecutionModel::Fragment, f, "main", vec![color]);
        b.execution_mode(f, ExecutionMode::OriginUpperLeft, []);
        return b.module().assemble();
    }
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

mod arrays;
mod demote;
mod errors;
mod mirror_once;
/// mpv's upload shader: its R8 storage texel buffer becomes a read-only storage buffer of
/// words at the same set and binding, read by no OpImageRead any more, and the three
/// specialization constants it was given become plain constants without SpecId.
mod reflect;
mod rewrite;
mod scaled;
mod specop;
mod subpass;
mod unnormalized;
mod usage;
mod validators;
mod zink;
