//! The GPU path works on this machine: an adapter is found (on CI that is Mesa's lavapipe) and
//! a compute shader's results come back. There is no skip: a machine without any adapter
//! fails here with the install hint, because every replay test depends on this.

use wgpu::util::DeviceExt;

#[test]
fn compute_round_trip_on_the_available_adapter() {
    let ctx = framelab_replay::open_device(None, wgpu::Features::TIMESTAMP_QUERY)
        .unwrap_or_else(|e| panic!("no usable GPU adapter: {e}"));
    eprintln!("adapter: {}", ctx.summary);
    let input: Vec<u32> = (0..256).collect();
    let buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("values"),
            contents: &input
                .iter()
                .flat_map(|v| v.to_le_bytes())
                .collect::<Vec<u8>>(),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        });
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("square"),
            source: wgpu::ShaderSource::Wgsl(
                "@group(0) @binding(0) var<storage, read_write> v: array<u32>;
             @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
                 v[id.x] = v[id.x] * v[id.x] + 1u;
             }"
                .into(),
            ),
        });
    let pipeline = ctx
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("square"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
    let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(4, 1, 1);
    }
    ctx.queue.submit([encoder.finish()]);
    let bytes =
        framelab_replay::read_buffer(&ctx.device, &ctx.queue, &buffer, 1024, "values").unwrap();
    let out: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let expected: Vec<u32> = (0..256u32).map(|v| v * v + 1).collect();
    assert_eq!(out, expected);
}
