//! framelab-ui: the egui inspector. `project` projects the pipeline's stages into a plain
//! inspection model by id, and the panels show only that model and the replay the worker
//! drives on its own thread; they never read captures themselves, so they can be tested
//! headless with egui_kittest on fixed models.

pub mod against;
pub mod app;
pub mod headless;
pub mod model;
pub mod panels;
pub mod project;
pub mod state;
pub mod visualise;
pub mod worker;

pub use app::Inspector;
pub use eframe::egui_wgpu;
pub use egui;
pub use egui_kittest;
pub use framelab_replay as replay;
