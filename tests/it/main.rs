//! The one integration-test binary of the `framelab` crate: each module tests one area end to
//! end (the command line, the analyses, replay on the available adapter), sharing the helpers in
//! `common` and the golden-image comparison in `golden`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
mod golden;

mod analysis_cli;
mod analysis_stages;
mod barrier_properties;
mod capture;
mod cli;
mod counters;
mod diff_cli;
mod docs;
mod driver_rejects;
mod dxgi_ddsfile;
mod fuzz;
mod fuzz_files;
mod gfxr_binary;
mod gfxr_fuzz;
mod gfxr_limits;
mod gfxr_replay;
mod house;
mod import;
mod inspector;
mod invalid_corpus;
mod mcp;
mod memory_quality;
mod rdc_fuzz;
mod rdc_import;
mod replay_gpu;
mod scenes;
mod sync_layer;
mod synthetic_scale;
mod vk_classes;
mod vk_section;
mod vk_shaders;
mod what_if;
