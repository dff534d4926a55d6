//! framelab-replay runs a compiled frame on the GPU through wgpu.
//!
//! This crate knows wgpu, WGSL and images; it knows nothing of the capture's JSON, DXGI format
//! names or D3D12 heaps. The root crate lowers a validated capture into the wgpu-level types
//! here, so that the GPU side can be tested and reused without the capture model.

pub mod atomic;
pub mod decode;
pub mod decompress;
pub mod device;
pub mod export;
pub mod layout;
pub mod plan;
pub mod readback;
pub mod run;
pub mod shader;
pub mod uniforms;

pub use device::{AdapterSummary, DeviceError, Faults, GpuContext, list_adapters, open_device};
pub use readback::{ReadbackError, read_buffer};
pub use run::{PassTime, ReplayError, Session};
pub use shader::{ShaderError, ValidatedShader, validate_wgsl};
pub use wgpu;
