//! framelab-core: everything framelab knows about a frame without a GPU.
//!
//! It owns the capture format with its loading and validation (`capture`), the WGSL front end
//! that reflects shader interfaces (`shader`, `uniforms`, `layout`), the reflection and rewriting
//! of captured Vulkan SPIR-V so wgpu can run it (`spirv`), the pass graph and what is derived
//! from it (`analysis`), the importers of real captures (`import`), the lowering of a capture to
//! a replay plan (`lower`, `plan`: the only place DXGI meets wgpu's format vocabulary), timing
//! reports and their statistics (`timing`), the structural diff (`structure`), and the reports
//! the commands print (`info`, `text`). `pipeline` is the one staged journey every command
//! walks: load, validate, analyse, lower. No wgpu device, no egui, no command line: the replay
//! and inspector crates build on this one.

pub mod analysis;
pub mod atomic;
pub mod buffer_views;
pub mod capture;
pub mod coverage;
pub mod files;
pub mod import;
pub mod info;
pub mod layout;
pub mod lower;
pub mod matching;
pub mod output;
pub mod pipeline;
pub mod plan;
pub mod schema;
pub mod shader;
pub mod spirv;
pub mod structure;
pub mod text;
pub mod timing;
pub mod uniforms;
pub mod whatif;

pub use wgpu_types;
