//! framelab-replay runs a lowered frame on the GPU through wgpu.
//!
//! This crate knows wgpu and images; it knows nothing of the capture's JSON, DXGI format names
//! or D3D12 heaps. It runs the `framelab_core::plan::Plan` that the core lowers from a
//! validated capture (`run`), reads textures back and decodes them (`decode`, `decompress`),
//! writes them as images (`export`), compares two sessions' textures (`compare`), measures a
//! frame and its variant side by side (`what_if`), and ends the core's staged journey with the
//! one stage that needs a device (`replaying`), held at any pass by one frame cursor (`cursor`)
//! on a thread of its own (`worker`).

pub mod compare;
pub mod cursor;
pub mod decode;
pub mod decompress;
pub mod device;
pub mod export;
pub mod readback;
pub mod replaying;
pub mod run;
pub mod what_if;
pub mod worker;

pub use cursor::NameError;
pub use device::{AdapterSummary, DeviceError, Faults, GpuContext, list_adapters, open_device};
pub use readback::{ReadbackError, read_buffer, read_buffer_range};
pub use replaying::{Open, Replaying};
pub use run::{PassTime, ReplayError, Session};
pub use wgpu;
pub use worker::Worker;
