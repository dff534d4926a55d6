//! The capture: its file format (`format`), loading (`load`), validation into the typed model
//! (`validate`, `model`), diagnostics, and the procedural generators a capture may name.

pub mod diag;
pub mod dxgi;
pub mod format;
pub mod formats;
pub mod generators;
pub mod ids;
pub mod load;
pub mod model;
pub mod shaders;
pub mod support;
pub mod validate;
pub mod vk_model;
pub mod vulkan;

pub use diag::{Diagnostic, Severity};
pub use load::CaptureError;
pub use model::Capture;
pub use validate::{Limits, Options, Validated};
