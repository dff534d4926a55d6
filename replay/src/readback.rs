//! Copying GPU buffers back to the CPU: one blocking map of a staging buffer. Export and the
//! pixel tests read render targets through this, so a mapping failure is an error naming the
//! buffer, never a panic.

#[derive(Debug, thiserror::Error)]
pub enum ReadbackError {
    #[error("mapping {label} for reading failed: {message}")]
    Map { label: String, message: String },
    #[error("waiting for the GPU while reading {label} failed: {message}")]
    Poll { label: String, message: String },
}

/// Copies `size` bytes from the start of `source` (which needs COPY_SRC usage) to the CPU.
pub fn read_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: &wgpu::Buffer,
    size: u64,
    label: &str,
) -> Result<Vec<u8>, ReadbackError> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("framelab readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("framelab readback"),
    });
    encoder.copy_buffer_to_buffer(source, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    map_read(device, &staging, size, label)
}

/// Copies bytes `offset..offset + size` of `source` (which needs COPY_SRC usage, and
/// `offset + size` within it) to the CPU. The copy is widened to the 4-byte alignment buffer
/// copies need, and the bytes asked for are cut from it.
pub fn read_buffer_range(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: &wgpu::Buffer,
    offset: u64,
    size: u64,
    label: &str,
) -> Result<Vec<u8>, ReadbackError> {
    let start = offset & !3;
    let end = (offset + size).div_ceil(4) * 4;
    let end = end.min(source.size() & !3).max(start);
    if end == start {
        return Ok(Vec::new());
    }
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("framelab readback"),
        size: end - start,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("framelab readback"),
    });
    encoder.copy_buffer_to_buffer(source, start, &staging, 0, end - start);
    queue.submit([encoder.finish()]);
    let bytes = map_read(device, &staging, end - start, label)?;
    let from = (offset - start) as usize;
    let to = (from + size as usize).min(bytes.len());
    Ok(bytes[from.min(to)..to].to_vec())
}

/// Maps the first `size` bytes of `staging` (MAP_READ usage, written by work already
/// submitted), copies them out and unmaps it, so the buffer can be written again.
pub fn map_read(
    device: &wgpu::Device,
    staging: &wgpu::Buffer,
    size: u64,
    label: &str,
) -> Result<Vec<u8>, ReadbackError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    staging
        .slice(..size)
        .map_async(wgpu::MapMode::Read, move |result| {
            let _ = sender.send(result);
        });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| ReadbackError::Poll {
            label: label.to_owned(),
            message: e.to_string(),
        })?;
    let mapped = receiver.recv().map_err(|e| ReadbackError::Map {
        label: label.to_owned(),
        message: e.to_string(),
    })?;
    mapped.map_err(|e| ReadbackError::Map {
        label: label.to_owned(),
        message: e.to_string(),
    })?;
    let bytes = staging
        .slice(..size)
        .get_mapped_range()
        .map_err(|e| ReadbackError::Map {
            label: label.to_owned(),
            message: e.to_string(),
        })?
        .to_vec();
    staging.unmap();
    Ok(bytes)
}
