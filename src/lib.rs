//! framelab: frame-capture analysis and pass reconstruction.
//!
//! The library owns the capture format, its loading and validation, the DXGI format table, and
//! (in later stages) the pass graph, its analyses and the lowering to a replay plan. The binary
//! in `main.rs` is a thin layer mapping these to commands and exit codes.

pub mod analysis;
pub mod capture;
pub mod dxgi;
pub mod info;
pub mod output;
pub mod replay;
pub mod schema;
