//! A Vulkan compute program, written directly against the API (ash), that writes its
//! descriptors through descriptor update templates: storage buffers, a uniform buffer and a
//! storage image from one application struct, once into a descriptor set
//! (`vkUpdateDescriptorSetWithTemplate`) and once pushed (`vkCmdPushDescriptorSetWithTemplateKHR`). No library framelab captures uses
//! templates, so this is the program the binary import's template decoding is tested on
//! (captured with GFXReconstruct; see `tests/fixtures/gfxr/README.md`).
//!
//! It fills `input` through a mapping, then dispatches twice (through the set, then through the
//! pushed descriptors) one 16x16 group that writes `output[i] = input[i] * scale + bias` and a
//! 16x16 RGBA8 image, each dispatch into its own output buffer and image; it reads both
//! outputs back and checks them, and exits non-zero on any mismatch.

// Every Vulkan call through ash is `unsafe`: the program owns each object it creates and
// destroys it after the device is idle.
#![allow(unsafe_code)]

use std::ffi::{CStr, c_void};

use anyhow::{Context, Result, bail};
use ash::vk;

const SIDE: u32 = 16;
const COUNT: usize = (SIDE * SIDE) as usize;
const SCALE: u32 = 3;
const BIAS: u32 = 5;

const SHADER: &str = r"
struct Params { scale: u32, bias: u32, pad0: u32, pad1: u32 }
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var shaded: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(16, 16)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.y * 16u + id.x;
    output[i] = input[i] * params.scale + params.bias;
    let shade = f32(input[i] % 7u) / 6.0;
    textureStore(shaded, vec2<i32>(id.xy), vec4<f32>(f32(id.x) / 15.0, f32(id.y) / 15.0, shade, 1.0));
}
";

/// What the template reads: one descriptor per binding, at the offsets its entries give.
#[repr(C)]
struct Descriptors {
    input: vk::DescriptorBufferInfo,
    output: vk::DescriptorBufferInfo,
    params: vk::DescriptorBufferInfo,
    target: vk::DescriptorImageInfo,
}

fn spirv() -> Result<Vec<u32>> {
    let module = naga::front::wgsl::parse_str(SHADER).context("the shader parses")?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .context("the shader validates")?;
    naga::back::spv::write_vec(&module, &info, &naga::back::spv::Options::default(), None)
        .context("the shader compiles to SPIR-V")
}

struct Buffer {
    buffer: vk::Buffer,
    memory: vk::DeviceMemory,
}

fn memory_type(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    bits: u32,
    wanted: vk::MemoryPropertyFlags,
) -> Result<u32> {
    let props = unsafe { instance.get_physical_device_memory_properties(physical) };
    (0..props.memory_type_count)
        .find(|&i| {
            bits & (1 << i) != 0
                && props.memory_types[i as usize]
                    .property_flags
                    .contains(wanted)
        })
        .context("no memory type fits")
}

fn buffer(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    device: &ash::Device,
    size: u64,
    usage: vk::BufferUsageFlags,
) -> Result<Buffer> {
    unsafe {
        let buffer = device.create_buffer(
            &vk::BufferCreateInfo::default().size(size).usage(usage),
            None,
        )?;
        let req = device.get_buffer_memory_requirements(buffer);
        let host = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let memory = device.allocate_memory(
            &vk::MemoryAllocateInfo::default()
                .allocation_size(req.size)
                .memory_type_index(memory_type(instance, physical, req.memory_type_bits, host)?),
            None,
        )?;
        device.bind_buffer_memory(buffer, memory, 0)?;
        Ok(Buffer { buffer, memory })
    }
}

fn write_u32s(device: &ash::Device, b: &Buffer, values: &[u32]) -> Result<()> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    unsafe {
        let p = device.map_memory(b.memory, 0, bytes.len() as u64, vk::MemoryMapFlags::empty())?;
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), p.cast::<u8>(), bytes.len());
        device.unmap_memory(b.memory);
    }
    Ok(())
}

fn read_u32s(device: &ash::Device, b: &Buffer, count: usize) -> Result<Vec<u32>> {
    let mut bytes = vec![0u8; count * 4];
    unsafe {
        let p = device.map_memory(b.memory, 0, bytes.len() as u64, vk::MemoryMapFlags::empty())?;
        std::ptr::copy_nonoverlapping(p.cast::<u8>(), bytes.as_mut_ptr(), bytes.len());
        device.unmap_memory(b.memory);
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// A 16x16 RGBA8 storage image with its memory and view.
fn storage_image(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    device: &ash::Device,
) -> Result<(vk::Image, vk::DeviceMemory, vk::ImageView)> {
    unsafe {
        let image = device.create_image(
            &vk::ImageCreateInfo::default()
                .image_type(vk::ImageType::TYPE_2D)
                .format(vk::Format::R8G8B8A8_UNORM)
                .extent(vk::Extent3D {
                    width: SIDE,
                    height: SIDE,
                    depth: 1,
                })
                .mip_levels(1)
                .array_layers(1)
                .samples(vk::SampleCountFlags::TYPE_1)
                .tiling(vk::ImageTiling::OPTIMAL)
                .usage(vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC),
            None,
        )?;
        let req = device.get_image_memory_requirements(image);
        let memory = device.allocate_memory(
            &vk::MemoryAllocateInfo::default()
                .allocation_size(req.size)
                .memory_type_index(memory_type(
                    instance,
                    physical,
                    req.memory_type_bits,
                    vk::MemoryPropertyFlags::DEVICE_LOCAL,
                )?),
            None,
        )?;
        device.bind_image_memory(image, memory, 0)?;
        let view = device.create_image_view(
            &vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(vk::Format::R8G8B8A8_UNORM)
                .subresource_range(color_range()),
            None,
        )?;
        Ok((image, memory, view))
    }
}

/// The loader, instance and first device with a compute queue (and push descriptors).
struct Vulkan {
    /// Holds the loader for as long as the instance lives.
    _entry: ash::Entry,
    instance: ash::Instance,
    physical: vk::PhysicalDevice,
    name: String,
    family: u32,
    device: ash::Device,
    queue: vk::Queue,
}

fn open() -> Result<Vulkan> {
    let entry = unsafe { ash::Entry::load() }.context("the Vulkan loader")?;
    let app = vk::ApplicationInfo::default()
        .application_name(c"framelab-template-compute")
        .api_version(vk::API_VERSION_1_1);
    let instance = unsafe {
        entry.create_instance(
            &vk::InstanceCreateInfo::default().application_info(&app),
            None,
        )?
    };
    let physical = *unsafe { instance.enumerate_physical_devices()? }
        .first()
        .context("no Vulkan device")?;
    let name = unsafe { instance.get_physical_device_properties(physical) }.device_name;
    let name = unsafe { CStr::from_ptr(name.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    let family = unsafe { instance.get_physical_device_queue_family_properties(physical) }
        .iter()
        .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE))
        .context("no compute queue")? as u32;
    let priorities = [1.0];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(family)
        .queue_priorities(&priorities)];
    let extensions = [ash::khr::push_descriptor::NAME.as_ptr()];
    let device = unsafe {
        instance.create_device(
            physical,
            &vk::DeviceCreateInfo::default()
                .queue_create_infos(&queues)
                .enabled_extension_names(&extensions),
            None,
        )?
    };
    let queue = unsafe { device.get_device_queue(family, 0) };
    Ok(Vulkan {
        _entry: entry,
        instance,
        physical,
        name,
        family,
        device,
        queue,
    })
}

/// The set layout's bindings (two storage buffers, a uniform buffer, a storage image) and
/// the template entries reading them from `Descriptors`.
fn bindings_and_entries() -> (
    Vec<vk::DescriptorSetLayoutBinding<'static>>,
    Vec<vk::DescriptorUpdateTemplateEntry>,
) {
    let kinds = [
        vk::DescriptorType::STORAGE_BUFFER,
        vk::DescriptorType::STORAGE_BUFFER,
        vk::DescriptorType::UNIFORM_BUFFER,
        vk::DescriptorType::STORAGE_IMAGE,
    ];
    let bindings: Vec<vk::DescriptorSetLayoutBinding> = kinds
        .iter()
        .enumerate()
        .map(|(i, &ty)| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(i as u32)
                .descriptor_type(ty)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE)
        })
        .collect();
    let offsets = [
        std::mem::offset_of!(Descriptors, input),
        std::mem::offset_of!(Descriptors, output),
        std::mem::offset_of!(Descriptors, params),
        std::mem::offset_of!(Descriptors, target),
    ];
    let entries: Vec<vk::DescriptorUpdateTemplateEntry> = kinds
        .iter()
        .zip(offsets)
        .enumerate()
        .map(|(i, (&ty, offset))| vk::DescriptorUpdateTemplateEntry {
            dst_binding: i as u32,
            dst_array_element: 0,
            descriptor_count: 1,
            descriptor_type: ty,
            offset,
            stride: 0,
        })
        .collect();
    (bindings, entries)
}

/// The descriptor objects both dispatches use: a set written through a template, and the
/// push-descriptor layout and template, with their pipeline layouts.
struct Layouts {
    set_layout: vk::DescriptorSetLayout,
    push_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    pipeline_layout: vk::PipelineLayout,
    push_pipeline_layout: vk::PipelineLayout,
    template: vk::DescriptorUpdateTemplate,
    push_template: vk::DescriptorUpdateTemplate,
}

/// # Safety
/// `device` is a live device; the caller destroys what this creates.
unsafe fn descriptor_objects(
    device: &ash::Device,
    bindings: &[vk::DescriptorSetLayoutBinding<'_>],
    entries: &[vk::DescriptorUpdateTemplateEntry],
) -> Result<Layouts> {
    unsafe {
        let set_layout = device.create_descriptor_set_layout(
            &vk::DescriptorSetLayoutCreateInfo::default().bindings(bindings),
            None,
        )?;
        let push_layout = device.create_descriptor_set_layout(
            &vk::DescriptorSetLayoutCreateInfo::default()
                .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
                .bindings(bindings),
            None,
        )?;
        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_BUFFER,
                descriptor_count: 2,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::UNIFORM_BUFFER,
                descriptor_count: 1,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_IMAGE,
                descriptor_count: 1,
            },
        ];
        let pool = device.create_descriptor_pool(
            &vk::DescriptorPoolCreateInfo::default()
                .max_sets(1)
                .pool_sizes(&sizes),
            None,
        )?;
        let layouts = [set_layout];
        let set = device.allocate_descriptor_sets(
            &vk::DescriptorSetAllocateInfo::default()
                .descriptor_pool(pool)
                .set_layouts(&layouts),
        )?[0];
        let pipeline_layout = device.create_pipeline_layout(
            &vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts),
            None,
        )?;
        let push_layouts = [push_layout];
        let push_pipeline_layout = device.create_pipeline_layout(
            &vk::PipelineLayoutCreateInfo::default().set_layouts(&push_layouts),
            None,
        )?;
        let template = device.create_descriptor_update_template(
            &vk::DescriptorUpdateTemplateCreateInfo::default()
                .descriptor_update_entries(entries)
                .template_type(vk::DescriptorUpdateTemplateType::DESCRIPTOR_SET)
                .descriptor_set_layout(set_layout),
            None,
        )?;
        let push_template = device.create_descriptor_update_template(
            &vk::DescriptorUpdateTemplateCreateInfo::default()
                .descriptor_update_entries(entries)
                .template_type(vk::DescriptorUpdateTemplateType::PUSH_DESCRIPTORS_KHR)
                .pipeline_bind_point(vk::PipelineBindPoint::COMPUTE)
                .pipeline_layout(push_pipeline_layout)
                .set(0),
            None,
        )?;
        Ok(Layouts {
            set_layout,
            push_layout,
            pool,
            set,
            pipeline_layout,
            push_pipeline_layout,
            template,
            push_template,
        })
    }
}

/// Records both dispatches: the images made general, one through the set, one through the
/// pushed descriptors, and their writes made visible to the host.
///
/// # Safety
/// `cb` is a command buffer of `device` in the initial state.
unsafe fn record(
    (device, push): (&ash::Device, &ash::khr::push_descriptor::Device),
    cb: vk::CommandBuffer,
    images: [vk::Image; 2],
    (pipelines, l): (&[vk::Pipeline], &Layouts),
    pushed: &Descriptors,
) -> Result<()> {
    unsafe {
        device.begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default())?;
        let to_general = |image: vk::Image| {
            vk::ImageMemoryBarrier::default()
                .image(image)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::GENERAL)
                .dst_access_mask(vk::AccessFlags::SHADER_WRITE)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .subresource_range(color_range())
        };
        device.cmd_pipeline_barrier(
            cb,
            vk::PipelineStageFlags::TOP_OF_PIPE,
            vk::PipelineStageFlags::COMPUTE_SHADER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[to_general(images[0]), to_general(images[1])],
        );
        device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, pipelines[0]);
        device.cmd_bind_descriptor_sets(
            cb,
            vk::PipelineBindPoint::COMPUTE,
            l.pipeline_layout,
            0,
            &[l.set],
            &[],
        );
        device.cmd_dispatch(cb, 1, 1, 1);
        device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, pipelines[1]);
        push.cmd_push_descriptor_set_with_template(
            cb,
            l.push_template,
            l.push_pipeline_layout,
            0,
            std::ptr::from_ref(pushed).cast::<c_void>(),
        );
        device.cmd_dispatch(cb, 1, 1, 1);
        device.cmd_pipeline_barrier(
            cb,
            vk::PipelineStageFlags::COMPUTE_SHADER,
            vk::PipelineStageFlags::HOST,
            vk::DependencyFlags::empty(),
            &[vk::MemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::SHADER_WRITE)
                .dst_access_mask(vk::AccessFlags::HOST_READ)],
            &[],
            &[],
        );
        device.end_command_buffer(cb)?;
        Ok(())
    }
}

fn main() -> Result<()> {
    let code = spirv()?;
    let Vulkan {
        _entry,
        instance,
        physical,
        name,
        family,
        device,
        queue,
    } = open()?;
    let push = ash::khr::push_descriptor::Device::new(&instance, &device);

    let bytes = (COUNT * 4) as u64;
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let input = buffer(&instance, physical, &device, bytes, storage)?;
    let output = buffer(&instance, physical, &device, bytes, storage)?;
    let params = buffer(
        &instance,
        physical,
        &device,
        16,
        vk::BufferUsageFlags::UNIFORM_BUFFER,
    )?;
    let values: Vec<u32> = (0..COUNT as u32).map(|i| i * 5 + 1).collect();
    write_u32s(&device, &input, &values)?;
    write_u32s(&device, &params, &[SCALE, BIAS, 0, 0])?;

    let first = storage_image(&instance, physical, &device)?;
    let second = storage_image(&instance, physical, &device)?;
    let output2 = buffer(&instance, physical, &device, bytes, storage)?;

    let (bindings, entries) = bindings_and_entries();
    unsafe {
        let l = descriptor_objects(&device, &bindings, &entries)?;
        let whole = |b: &Buffer| vk::DescriptorBufferInfo {
            buffer: b.buffer,
            offset: 0,
            range: vk::WHOLE_SIZE,
        };
        let descriptors = |out: &Buffer, view: vk::ImageView| Descriptors {
            input: whole(&input),
            output: whole(out),
            params: vk::DescriptorBufferInfo {
                buffer: params.buffer,
                offset: 0,
                range: 16,
            },
            target: vk::DescriptorImageInfo {
                sampler: vk::Sampler::null(),
                image_view: view,
                image_layout: vk::ImageLayout::GENERAL,
            },
        };
        let data = descriptors(&output, first.2);
        device.update_descriptor_set_with_template(
            l.set,
            l.template,
            std::ptr::from_ref(&data).cast::<c_void>(),
        );
        let pushed = descriptors(&output2, second.2);

        let module = device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&code), None)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main");
        let pipelines = device
            .create_compute_pipelines(
                vk::PipelineCache::null(),
                &[
                    vk::ComputePipelineCreateInfo::default()
                        .stage(stage)
                        .layout(l.pipeline_layout),
                    vk::ComputePipelineCreateInfo::default()
                        .stage(stage)
                        .layout(l.push_pipeline_layout),
                ],
                None,
            )
            .map_err(|(_, e)| e)?;

        let command_pool = device.create_command_pool(
            &vk::CommandPoolCreateInfo::default().queue_family_index(family),
            None,
        )?;
        let cb = device.allocate_command_buffers(
            &vk::CommandBufferAllocateInfo::default()
                .command_pool(command_pool)
                .command_buffer_count(1),
        )?[0];
        record(
            (&device, &push),
            cb,
            [first.0, second.0],
            (&pipelines, &l),
            &pushed,
        )?;
        let cbs = [cb];
        device.queue_submit(
            queue,
            &[vk::SubmitInfo::default().command_buffers(&cbs)],
            vk::Fence::null(),
        )?;
        device.queue_wait_idle(queue)?;

        let mut wrong = 0;
        for out in [&output, &output2] {
            let got = read_u32s(&device, out, COUNT)?;
            wrong += got
                .iter()
                .zip(&values)
                .filter(|(g, v)| **g != **v * SCALE + BIAS)
                .count();
        }

        device.destroy_command_pool(command_pool, None);
        for p in pipelines {
            device.destroy_pipeline(p, None);
        }
        device.destroy_shader_module(module, None);
        device.destroy_descriptor_update_template(l.template, None);
        device.destroy_descriptor_update_template(l.push_template, None);
        device.destroy_pipeline_layout(l.pipeline_layout, None);
        device.destroy_pipeline_layout(l.push_pipeline_layout, None);
        device.destroy_descriptor_pool(l.pool, None);
        device.destroy_descriptor_set_layout(l.set_layout, None);
        device.destroy_descriptor_set_layout(l.push_layout, None);
        for (image, memory, view) in [first, second] {
            device.destroy_image_view(view, None);
            device.destroy_image(image, None);
            device.free_memory(memory, None);
        }
        for b in [&input, &output, &output2, &params] {
            device.destroy_buffer(b.buffer, None);
            device.free_memory(b.memory, None);
        }
        device.destroy_device(None);
        instance.destroy_instance(None);
        if wrong != 0 {
            bail!("{wrong} of {} outputs are wrong on {name}", 2 * COUNT);
        }
    }
    println!("{} outputs right on {name}", 2 * COUNT);
    Ok(())
}

fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}
