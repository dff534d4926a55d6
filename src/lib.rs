//! framelab: frame-capture analysis and pass reconstruction.
//!
//! The library owns the capture format with its loading and validation (`capture`), the pass
//! graph and what is derived from it (`analysis`), the lowering of a capture to a replay plan
//! (`lower`, the only place that maps DXGI to wgpu), timing reports (`timing`), and the reports
//! the commands print (`info`, `text`). The binary (`src/cli/`) maps these to commands and exit
//! codes; `anyhow` lives only there.

pub mod analysis;
pub mod capture;
pub mod import;
pub mod info;
pub mod inspect;
pub mod lower;
pub mod matching;
pub mod output;
pub mod scenes;
pub mod schema;
pub mod structure;
pub mod text;
pub mod timing;
