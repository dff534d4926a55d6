//! framelab-ui: the egui inspector. It shows what it is given (an inspection model built by the
//! root crate, and a replay session it drives on a worker thread) and never reads captures
//! itself, so that the panels can be tested headless with egui_kittest on fixed models.

pub mod app;
pub mod headless;
pub mod model;
pub mod panels;
pub mod project;
pub mod visualise;
pub mod worker;

pub use app::Inspector;
pub use eframe::egui_wgpu;
pub use egui;
pub use egui_kittest;
pub use framelab_replay as replay;
