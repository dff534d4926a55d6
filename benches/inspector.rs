//! Inspector benchmarks on the available adapter, over Night City at `--scale 0.5`:
//! - time to the first displayed render target (load, analyse, lower, start the worker, one
//!   timed frame, then frame 1 up to the current pass, read-back and display), measured once;
//! - time to switch the current pass (a replay up to the new pass, read-back, display), once;
//! - CPU time of one UI frame with the frame loaded and shown (criterion): layout, painting and
//!   tessellation of every visible panel, without the GPU.

// A benchmark that cannot set up (no adapter, no capture) has nothing to measure: it stops
// with the reason.
#![allow(clippy::expect_used)]

use std::time::{Duration, Instant};

use criterion::Criterion;
use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::pipeline::Analysed;
use framelab_ui::project::{self as inspect, Reports};
use framelab_ui::{Inspector, egui, headless};

const CAPTURE: &str = "captures/night_city/main_street_day.json";
const SETTLE: Duration = Duration::from_secs(1200);

fn main() {
    let start = Instant::now();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(CAPTURE);
    let options = Options {
        scale: 0.5,
        ..Options::default()
    };
    let analysed =
        Analysed::load(&path, &options, AnalyzeOptions::default()).expect("valid and acyclic");
    // Named as a user would, resolved to ids once.
    let c = &analysed.capture;
    let pass_id = |name: &str| c.passes.iter().find(|p| p.name == name).expect(name).id;
    let resource_id = |name: &str| c.resources.iter().find(|r| r.name == name).expect(name).id;
    let (base, lighting) = (pass_id("base_material"), pass_id("tiled_direct_lighting"));
    let albedo = resource_id("gbuffer_albedo");
    let ctx = framelab_replay::open_device(None, framelab_core::lower::wanted_features())
        .expect("an adapter");
    let (model, worker) =
        inspect::launch(analysed, &ctx, &Reports::default(), 1).expect("launches");
    let rs = headless::render_state(&ctx).expect("egui on the replay device");
    let mut app = Inspector::new(model, Some(worker), Some(rs.clone()));
    let model = app.model.clone();
    app.select_pass(model.pass_position(base).expect("base_material is shown"));
    app.open_resource(model.resource_position(albedo).expect("gbuffer_albedo"));
    let mut h = headless::harness(app, rs, egui::Vec2::new(1600.0, 900.0));
    headless::settle(&mut h, SETTLE).expect("first view");
    let first = start.elapsed();
    let switch_start = Instant::now();
    h.state_mut().select_pass(
        model
            .pass_position(lighting)
            .expect("tiled_direct_lighting is shown"),
    );
    headless::settle(&mut h, SETTLE).expect("switched");
    let switch = switch_start.elapsed();
    println!(
        "inspector on {} at scale 0.5, {}: first displayed target {:.2} s, pass switch {:.2} s",
        CAPTURE,
        ctx.summary.name,
        first.as_secs_f64(),
        switch.as_secs_f64()
    );
    // A frame as a window runs it: the UI laid out and painted, then tessellated (no
    // accessibility tree, which the test harness always builds).
    let ctx = egui::Context::default();
    let input = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::Vec2::new(1600.0, 900.0),
        )),
        ..Default::default()
    };
    let app = h.state_mut();
    let mut frame = || {
        let out = ctx.run_ui(input.clone(), |ui| app.ui(ui));
        ctx.tessellate(out.shapes, out.pixels_per_point)
    };
    for _ in 0..3 {
        frame();
    }
    let mut c = Criterion::default().configure_from_args();
    c.bench_function("inspector/ui_frame_night_city", |b| b.iter(&mut frame));
    c.final_summary();
}
