//! framelab-ui: the egui inspector. It shows what it is given (an inspection model built by the
//! root crate, and a replay session it can drive) and never reads captures itself, so that the
//! panels can be tested headless with egui_kittest on fixed models.

pub use framelab_replay as replay;
