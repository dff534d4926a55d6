//! Inspector benchmarks on the available adapter, over Night City at `--scale 0.5`, through
//! the same calls a click makes (`select_pass`, `open_resource`, then frames until the worker's
//! image is shown):
//! - the window: time from start to the first UI frame drawn (load, analyse, lower, the
//!   worker started; its session is created on its own thread);
//! - the first pass shown while the first replay runs, and the whole frame browsable;
//! - switching to every pass in turn once the frame has replayed (median and worst);
//! - re-opening a texture viewed before (median);
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

type Harness = framelab_ui::egui_kittest::Harness<'static, Inspector>;

/// Steps frames (at least one: the first sends the request) until `done` holds, and returns
/// how long that took.
fn until(h: &mut Harness, done: impl Fn(&Inspector) -> bool) -> Duration {
    let start = Instant::now();
    loop {
        h.step();
        if done(h.state()) {
            return start.elapsed();
        }
        assert!(h.state().error.is_none(), "{:?}", h.state().error);
        assert!(start.elapsed() < SETTLE, "timed out");
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// Whether the texture the selection asks for is the one shown.
fn shown(app: &Inspector) -> bool {
    app.is_idle()
        && app.displayed.as_ref().is_some_and(|d| {
            d.request.pass == app.selection.pass
                && d.request.texture.as_ref().map(|t| t.plan_index)
                    == app
                        .selection
                        .resource
                        .and_then(|r| app.model.resources[r].texture.as_ref())
                        .map(|t| t.plan_index)
        })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

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
    let base = pass_id("base_material");
    let (albedo, normal) = (resource_id("gbuffer_albedo"), resource_id("gbuffer_normal"));
    let ctx = framelab_replay::open_device(None, framelab_core::lower::wanted_features())
        .expect("an adapter");
    let adapter = ctx.summary.name.clone();
    let rs = headless::render_state(&ctx).expect("egui on its own device");
    let options = inspect::LaunchOptions {
        frames: 1,
        ..Default::default()
    };
    let (model, worker) =
        inspect::launch(analysed, ctx, &Reports::default(), options).expect("launches");
    let mut app = Inspector::new(model, Some(worker));
    let model = app.model.clone();
    let base = model.pass_position(base).expect("base_material is shown");
    let (albedo, normal) = (
        model.resource_position(albedo).expect("gbuffer_albedo"),
        model.resource_position(normal).expect("gbuffer_normal"),
    );
    app.select_pass(base);
    app.open_resource(albedo);
    let mut h = headless::harness(app, rs, egui::Vec2::new(1600.0, 900.0));
    h.step();
    let window = start.elapsed();
    until(&mut h, shown);
    let first = start.elapsed();
    let replayed_through = h.state().replayed.map_or(0, |(d, _)| d + 1);
    until(&mut h, |a| !a.replaying());
    let whole = start.elapsed();
    let mut switches = Vec::new();
    for p in 0..model.passes.len() {
        h.state_mut().select_pass(p);
        switches.push(until(&mut h, shown).as_secs_f64());
    }
    let mut reopen = Vec::new();
    h.state_mut().select_pass(base);
    until(&mut h, shown);
    for _ in 0..5 {
        for r in [normal, albedo] {
            h.state_mut().open_resource(r);
            reopen.push(until(&mut h, shown).as_secs_f64());
        }
    }
    // A draw of base_material (a replay up to the pass, then the pass up to the draw), and the
    // history of a texel of the albedo target (every draw of the pass replayed in turn).
    h.state_mut().select_pass(base);
    until(&mut h, shown);
    h.state_mut().select_step(base, 1);
    let step = until(&mut h, |a| {
        shown(a)
            && a.displayed
                .as_ref()
                .is_some_and(|d| d.request.step == Some(1))
    });
    // The next draw of the same pass: only the pass runs again, from its starting contents.
    h.state_mut().select_step(base, 2);
    let next_step = until(&mut h, |a| {
        shown(a)
            && a.displayed
                .as_ref()
                .is_some_and(|d| d.request.step == Some(2))
    });
    h.state_mut().select_pass(base);
    h.state_mut().open_resource(albedo);
    until(&mut h, shown);
    h.state_mut().pick(480, 400);
    h.state_mut().request_history();
    let history = until(&mut h, |a| a.history.is_some() && a.is_idle());
    let worst = switches.iter().copied().fold(0.0, f64::max);
    let mut slowest: Vec<(f64, usize)> = switches.iter().copied().zip(0..).collect();
    slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
    let slowest: Vec<String> = slowest
        .iter()
        .take(5)
        .map(|&(t, p)| format!("{} {t:.3} s", model.passes[p].name))
        .collect();
    println!(
        "inspector on {CAPTURE} at scale 0.5, {adapter}: window {:.2} s; base_material's albedo \
         shown {:.2} s (the first replay {replayed_through} passes in); whole frame browsable \
         {:.2} s; pass switch over {} passes: median {:.3} s, worst {:.3} s; re-opening a \
         texture: median {:.3} s; {}; slowest switches: {}; a draw of base_material shown \
         {:.2} s, its next draw {:.2} s; a texel's history {:.2} s",
        window.as_secs_f64(),
        first.as_secs_f64(),
        whole.as_secs_f64(),
        switches.len(),
        median(switches),
        worst,
        median(reopen),
        h.state().status,
        slowest.join(", "),
        step.as_secs_f64(),
        next_step.as_secs_f64(),
        history.as_secs_f64(),
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
