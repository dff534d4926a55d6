//! The inspector on the available adapter, driven through egui_kittest by labels as a user
//! would: select passes in the event browser and on the timeline, open textures from the
//! resource table, change mip and channels, read texel values, and check what it reads back
//! against `framelab replay --after PASS --resource TEXTURE`.

use std::time::{Duration, Instant};

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::pipeline::Analysed;
use framelab_core::timing::TimingReport;
use framelab_ui::Inspector;
use framelab_ui::app::Pane;
use framelab_ui::egui;
use framelab_ui::egui_kittest::{
    self,
    kittest::{NodeT, Queryable},
};
use framelab_ui::headless;
use framelab_ui::project::{self as inspect, Reports};
use framelab_ui::worker::SaveAs;

use crate::common::{Scratch, exr_image, framelab, repo, stderr};
use crate::golden::ui_snapshot_options;

/// Tests name passes and resources as a user would; the model itself is keyed by id.
trait ByName {
    fn pass_named(&self, name: &str) -> Option<usize>;
    fn resource_named(&self, name: &str) -> Option<usize>;
}

impl ByName for framelab_ui::model::Inspection {
    fn pass_named(&self, name: &str) -> Option<usize> {
        self.passes.iter().position(|p| p.name == name)
    }
    fn resource_named(&self, name: &str) -> Option<usize> {
        self.resources.iter().position(|r| r.name == name)
    }
}

const SETTLE: Duration = Duration::from_secs(300);

/// The example at scale 0.25 in a 1400x900 harness, one frame timed, settled.
fn open(capture: &str) -> egui_kittest::Harness<'static, Inspector> {
    open_with(capture, &Reports::default())
}

fn report(path: &str) -> TimingReport {
    let text = std::fs::read_to_string(repo().join(path)).unwrap();
    TimingReport::from_json(path, &text).unwrap()
}

fn open_with(capture: &str, reports: &Reports<'_>) -> egui_kittest::Harness<'static, Inspector> {
    let mut harness = launched(capture, reports);
    headless::settle(&mut harness, SETTLE).unwrap();
    harness
}

/// The example at scale 0.25 in a 1400x900 harness, its worker just started.
fn launched(capture: &str, reports: &Reports<'_>) -> egui_kittest::Harness<'static, Inspector> {
    let path = repo().join(capture);
    let options = Options {
        scale: 0.25,
        ..Options::default()
    };
    let analysed = Analysed::load(&path, &options, AnalyzeOptions::default()).unwrap();
    let ctx = framelab_replay::open_device(None, framelab_core::lower::wanted_features())
        .expect("an adapter");
    let rs = headless::render_state(&ctx).unwrap();
    let options = inspect::LaunchOptions {
        frames: 1,
        ..Default::default()
    };
    let (model, worker) = inspect::launch(analysed, ctx, reports, options).unwrap();
    let app = Inspector::new(model, Some(worker));
    headless::harness(app, rs, egui::Vec2::new(1400.0, 900.0))
}

/// The example settled with example_a's timings compared against `b`.
fn compared_with(b: &TimingReport) -> egui_kittest::Harness<'static, Inspector> {
    let a = report("tests/fixtures/timing/example_a.json");
    open_with(
        "captures/example/frame.json",
        &Reports {
            timings: Some((&a, "example_a.json".into())),
            compare: Some((b, "example_b.json".into())),
        },
    )
}

fn settle(h: &mut egui_kittest::Harness<'static, Inspector>) {
    headless::settle(h, SETTLE).unwrap();
}

/// The channel values of the pixel readout (`(x, y) R v  G v ...`).
fn readout(h: &egui_kittest::Harness<'static, Inspector>, at: &str) -> Vec<f32> {
    label_with(h, at)
        .split_whitespace()
        .filter_map(|w| w.parse::<f32>().ok())
        .collect()
}

/// Filters the resource table to `name` and clicks its row, as a user opens a resource.
fn click_resource_row(h: &mut egui_kittest::Harness<'static, Inspector>, name: &str) {
    h.state_mut().selection.resource_filter = name.into();
    h.run_steps(2);
    h.get_all_by_label(name)
        .find(|n| n.accesskit_node().role() == egui::Role::Button)
        .unwrap_or_else(|| panic!("a {name} row in the resource table"))
        .click();
}

/// A primary click at `pos` (painted widgets have no accessible label to click by).
fn click_at(h: &mut egui_kittest::Harness<'static, Inspector>, pos: egui::Pos2) {
    h.hover_at(pos);
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    h.run_steps(2);
}

#[test]
fn selecting_passes_and_textures_shows_the_frame_as_of_that_pass() {
    let mut h = open("captures/example/frame.json");
    let model = h.state().model.clone();
    let scene = model.pass_named("scene").unwrap();

    // The event browser: click a pass, it becomes current.
    h.get_by_label("scene").click();
    settle(&mut h);
    assert_eq!(h.state().selection.pass, scene);

    // The resource table (a tab beside the timeline): open scene_color.
    h.get_by_label("Resources").click();
    click_resource_row(&mut h, "scene_color");
    settle(&mut h);
    let scene_color = model.resource_named("scene_color").unwrap();
    assert_eq!(h.state().selection.resource, Some(scene_color));

    // Right after `scene`, the top-left texel is the sky: the pass's clear colour
    // (0.02, 0.03, 0.05, 1) as RGBA16F stores it.
    h.state_mut().pick(0, 0);
    h.run_steps(2);
    let v = readout(&h, "(0, 0)");
    let expected = [0.02f32, 0.03, 0.05, 1.0];
    assert_eq!(v.len(), 4, "{v:?}");
    for (got, want) in v.iter().zip(expected) {
        assert!((got - want).abs() < 1e-3, "{v:?}");
    }

    // Channel toggles and mip: show only green of bloom's mip 1.
    let bloom = model.resource_named("bloom").unwrap();
    h.state_mut().open_resource(bloom);
    h.state_mut()
        .select_pass(model.pass_named("bloom_mips").unwrap());
    settle(&mut h);
    h.get_by_label("R").click();
    h.get_by_label("B").click();
    h.state_mut().selection.sub.mip = 1;
    settle(&mut h);
    let s = h.state();
    assert_eq!(s.selection.controls.channels, [false, true, false, false]);
    let shown = s.displayed.as_ref().unwrap();
    assert_eq!(shown.request.texture.as_ref().unwrap().sub.mip, 1);
    let decoded = shown.decoded.as_ref().unwrap();
    // Mip 1 of the half-size bloom at scale 0.25: 40x22.
    assert_eq!((decoded.width, decoded.height), (40, 22));

    // The timeline: click the tonemap bar.
    h.get_by_label("Timeline").click();
    h.run_steps(2);
    let tonemap = model.pass_named("tonemap").unwrap();
    let rect = h
        .state()
        .timeline_bars
        .iter()
        .find(|(p, _)| *p == tonemap)
        .map(|(_, r)| *r)
        .expect("a tonemap bar");
    click_at(&mut h, rect.center());
    assert_eq!(h.state().selection.pass, tonemap);
    // Where the adapter's timestamps do not measure compute passes (lavapipe), tonemap keeps
    // its place but shows no time, and the timeline says why; elsewhere it is measured.
    let ctx = framelab_replay::open_device(None, framelab_core::lower::wanted_features())
        .expect("an adapter");
    let why = framelab_core::timing::untrusted_timestamps(
        &ctx.summary.name,
        ctx.summary.device_type,
        framelab_core::capture::format::PassKind::Compute,
    );
    let timings = h.state().timings.clone().expect("live timings");
    let tonemap_time = timings.passes[tonemap].expect("tonemap ran");
    assert_eq!(tonemap_time.measured, why.is_none());
    assert_eq!(timings.note, why);
    assert_eq!(
        h.query_by_label_contains("grey: not measured").is_some(),
        why.is_some()
    );
    assert!(timings.passes[model.pass_named("scene").unwrap()].is_some_and(|t| t.measured));

    // The DAG: click the bloom_extract node.
    h.get_by_label("DAG").click();
    h.run_steps(2);
    let bloom_extract = model.pass_named("bloom_extract").unwrap();
    let node = h
        .state()
        .dag_nodes
        .iter()
        .find(|(p, _)| *p == bloom_extract)
        .map(|(_, r)| *r)
        .expect("a bloom_extract node");
    // The DAG centres on the current pass (tonemap), so bloom_extract, left of it, may be
    // partly outside the panel: click its right end.
    click_at(&mut h, egui::pos2(node.right() - 8.0, node.center().y));
    assert_eq!(h.state().selection.pass, bloom_extract);
    // It is centred now, its node right of the scene it reads from.
    let at = |h: &egui_kittest::Harness<'static, Inspector>, pass: usize| {
        h.state()
            .dag_nodes
            .iter()
            .find(|(p, _)| *p == pass)
            .unwrap()
            .1
    };
    let (node, scene_node) = (at(&h, bloom_extract), at(&h, scene));
    assert!(node.left() > scene_node.right(), "{node:?} {scene_node:?}");
    // The memory view lists the aliasing plan's pools.
    h.get_by_label("Memory").click();
    h.run_steps(2);
    assert!(h.query_by_label_contains("lower bound").is_some());
    h.state_mut().select_pass(tonemap);
    h.run_steps(1);

    // Arrow keys step through the events.
    h.key_press(egui::Key::ArrowUp);
    h.run_steps(1);
    assert_eq!(h.state().selection.pass, tonemap - 1);
}

#[test]
fn the_ui_keeps_drawing_and_taking_input_while_the_first_replay_runs() {
    // Night City: a frame long enough on lavapipe for the UI to be seen drawing through it.
    let mut h = launched(
        "captures/night_city/main_street_day.json",
        &Reports::default(),
    );
    // The first pass that draws into a texture: it opens that texture.
    let model = h.state().model.clone();
    let early = (0..model.passes.len())
        .find(|&p| {
            model.passes[p]
                .outputs
                .first()
                .is_some_and(|&r| model.resources[r].texture.is_some())
        })
        .unwrap();
    h.state_mut().select_pass(early);
    let visible = framelab_ui::panels::events::visible(&model, "");
    let next = visible[visible.iter().position(|&p| p == early).unwrap() + 1];
    let start = Instant::now();
    let (mut frames, mut longest) = (0u32, Duration::ZERO);
    let mut first_pass_shown_early = false;
    while h.state().replaying() {
        assert!(h.state().error.is_none(), "{:?}", h.state().error);
        let t = Instant::now();
        h.step();
        if frames % 8 == 0 {
            // The UI's own drawing, on its own device.
            h.render().unwrap();
        }
        longest = longest.max(t.elapsed());
        frames += 1;
        // That pass, once replayed, is shown before the frame's last pass has run.
        if let Some(d) = &h.state().displayed
            && d.request.pass == early
            && d.arrived_at.is_some_and(|(done, total)| done + 1 < total)
            && !first_pass_shown_early
        {
            first_pass_shown_early = true;
            h.key_press(egui::Key::ArrowDown);
        }
        std::thread::sleep(Duration::from_millis(5));
        assert!(start.elapsed() < SETTLE, "the first replay never finished");
    }
    let replay = start.elapsed();
    assert!(
        first_pass_shown_early,
        "{} was not shown before the frame finished",
        model.passes[early].name
    );
    // The key pressed while the replay ran was taken.
    assert_eq!(h.state().selection.pass, next);
    // A frozen UI draws a frame or two while the replay runs; this one kept drawing, none of
    // its frames near as long as the replay.
    assert!(frames >= 20, "{frames} UI frames in {replay:?}");
    assert!(
        longest * 5 < replay,
        "longest UI frame {longest:?} during a {replay:?} replay"
    );
    settle(&mut h);
    // Every texture of the frame opens at its last pass (2D and 3D, float, integer, depth).
    h.state_mut().select_pass(model.passes.len() - 1);
    for (r, res) in model.resources.iter().enumerate() {
        if res.texture.as_ref().is_some_and(|t| t.unviewable.is_none()) {
            h.state_mut().open_resource(r);
            settle(&mut h);
            let shown = h
                .state()
                .displayed
                .as_ref()
                .and_then(|d| d.request.texture.clone());
            assert_eq!(
                shown.map(|t| t.plan_index),
                res.texture.as_ref().map(|t| t.plan_index),
                "{}",
                res.name
            );
        }
    }
}

/// The whole window at the common 1280x720 and at a small 800x600: every panel keeps a usable
/// size (compared with blessed images).
#[test]
fn the_layout_holds_at_1280x720_and_800x600() {
    let mut results = egui_kittest::SnapshotResults::new();
    // A report's timings, so the images do not change with the machine's.
    let a = report("tests/fixtures/timing/example_a.json");
    let reports = Reports {
        timings: Some((&a, "example_a.json".into())),
        compare: None,
    };
    for (w, h, name) in [
        (1280.0, 720.0, "window_1280x720"),
        (800.0, 600.0, "window_800x600"),
    ] {
        let mut harness = launched("captures/example/frame.json", &reports);
        harness.set_size(egui::Vec2::new(w, h));
        let model = harness.state().model.clone();
        harness
            .state_mut()
            .select_pass(model.pass_named("scene").unwrap());
        settle(&mut harness);
        while harness.state().replaying() {
            harness.step();
            std::thread::sleep(Duration::from_millis(10));
        }
        settle(&mut harness);
        harness.run_steps(3);
        // Every pane shown is at least as large as the layout's minimum.
        let panes = harness.state().pane_rects.clone();
        assert_eq!(panes.len(), 4, "{panes:?}");
        for (pane, rect) in panes {
            assert!(
                rect.width() >= 100.0 && rect.height() >= 100.0,
                "{pane:?} at {w}x{h}: {rect:?}"
            );
        }
        results.add(harness.try_snapshot_options(name, &ui_snapshot_options()));
    }
}

#[test]
fn a_pass_with_barrier_lints_lists_its_barriers_and_lints() {
    let mut h = open("captures/example/frame.json");
    // The example's `scene` records a transition from the wrong state (FL024) and misses one
    // (FL020): both show in its details, beside its derived and recorded barriers.
    h.get_by_label("scene").click();
    settle(&mut h);
    assert!(h.query_by_label_contains("FL024").is_some());
    assert!(h.query_by_label_contains("FL020").is_some());
    assert!(h.query_all_by_label("recorded").count() > 0);
    assert!(h.query_all_by_label("derived").count() > 0);

    // Depth opens inverted and fitted to the values read back (perspective depth crowds
    // near 1: the far plane, where the pass cleared it).
    let depth = h.state().model.resource_named("depth").unwrap();
    h.state_mut().open_resource(depth);
    settle(&mut h);
    let c = h.state().selection.controls;
    assert!(c.invert && c.black > 0.9 && c.white == 1.0, "{c:?}");
}

/// What the inspector reads back for (pass, texture) is what `replay --after PASS --resource
/// TEXTURE` exports: both run one whole frame, then the next up to the pass.
#[test]
fn pixel_history_lists_the_pass_and_draws_that_wrote_a_texel() {
    let mut h = open("captures/example/frame.json");
    let model = h.state().model.clone();
    let scene = model.pass_named("scene").unwrap();
    h.state_mut().select_pass(scene);
    h.state_mut()
        .open_resource(model.resource_named("scene_color").unwrap());
    // A texel of the ground, in the lower half of the 160x90 target.
    h.state_mut().pick(80, 70);
    settle(&mut h);
    let after_scene = readout(&h, "(80, 70)");
    h.state_mut().request_history();
    settle(&mut h);
    let history = h
        .state()
        .history
        .as_ref()
        .unwrap()
        .as_ref()
        .unwrap()
        .clone();
    // scene_color is written by the scene pass alone: its draws, then the pass.
    let passes: Vec<usize> = history
        .rows
        .iter()
        .filter(|r| r.step.is_none())
        .map(|r| r.pass)
        .collect();
    assert_eq!(passes, [scene]);
    let steps = model.passes[scene].steps;
    let draws: Vec<_> = history.rows.iter().filter(|r| r.step.is_some()).collect();
    assert_eq!(draws.len(), steps);
    let whole = history.rows.iter().find(|r| r.step.is_none()).unwrap();
    assert!(whole.changed, "{history:?}");
    // The pass replayed up to its last draw leaves the texel as the whole pass does, and the
    // value is the one the texture viewer reads back there.
    assert_eq!(draws.last().unwrap().value, whole.value);
    let numbers = |text: &str| -> Vec<f32> {
        text.split_whitespace()
            .filter_map(|w| w.parse::<f32>().ok())
            .collect()
    };
    assert_eq!(numbers(&whole.value), after_scene);
    // The ground draw wrote the texel: the value changed from the frame's start there.
    assert!(draws[0].changed, "{history:?}");
    // The texture viewer as of each draw reads what the history says after it (the frame held
    // open at the pass, the pass replayed up to the draw from its starting contents).
    for (k, row) in draws.iter().enumerate().rev() {
        h.state_mut().select_step(scene, k);
        settle(&mut h);
        let shown = h.state().displayed.as_ref().unwrap();
        assert_eq!(
            shown.written,
            Some(framelab_ui::worker::Written::Step {
                pass: scene,
                step: k
            })
        );
        assert_eq!(readout(&h, "(80, 70) R"), numbers(&row.value), "draw {k}");
    }
    h.state_mut().show_pane(Pane::History);
    h.run_steps(3);
    assert!(h.query_by_label_contains("write(s) this frame").is_some());
}

/// The example copied into a temporary folder with its ground tinted red and its tonemap pass
/// renamed; the folder, holding it as `frame.json`.
fn changed_example() -> Scratch {
    let dir = Scratch::temp("framelab-against");
    let mut capture = crate::common::example_copy(&dir);
    for p in capture["passes"].as_array_mut().unwrap() {
        if p["name"] == "scene" {
            p["params"]["ground_tint"] = serde_json::json!([0.9, 0.1, 0.1, 1.0]);
        }
        if p["name"] == "tonemap" {
            p["name"] = serde_json::json!("tonemap_aces");
        }
    }
    std::fs::write(dir.join("frame.json"), capture.to_string()).unwrap();
    dir
}

#[test]
fn the_image_diff_pairs_passes_and_measures_flip() {
    let load = |path: &std::path::Path| {
        let options = Options {
            scale: 0.25,
            ..Options::default()
        };
        Analysed::load(path, &options, AnalyzeOptions::default()).unwrap()
    };
    let changed = changed_example();
    let (a, b) = (
        load(&repo().join("captures/example/frame.json")),
        load(&changed.join("frame.json")),
    );
    let pairs = framelab_core::structure::pass_pairs(&a.capture, &b.capture);
    let open =
        || framelab_replay::open_device(None, framelab_core::lower::wanted_features()).unwrap();
    let ctx = open();
    let rs = headless::render_state(&ctx).unwrap();
    let options = inspect::LaunchOptions {
        frames: 1,
        ..Default::default()
    };
    let (model, worker) = inspect::launch(a, ctx, &Reports::default(), options).unwrap();
    let (model_b, worker_b) = inspect::launch(b, open(), &Reports::default(), options).unwrap();
    let against = framelab_ui::against::Against::new(&model, model_b, &pairs);
    let app = Inspector::new(model, Some(worker)).with_against(against, worker_b);
    let mut h = headless::harness(app, rs, egui::Vec2::new(1400.0, 900.0));
    let model = h.state().model.clone();
    let flip_at = |h: &mut egui_kittest::Harness<'static, Inspector>, pass: &str, texture: &str| {
        h.state_mut().select_pass(model.pass_named(pass).unwrap());
        h.state_mut()
            .open_resource(model.resource_named(texture).unwrap());
        settle(h);
        let a = h.state().against.as_ref().unwrap();
        let f = a.flip.as_ref().expect("a FLIP");
        f.result.as_ref().map(|r| r.mean).unwrap()
    };
    // Before the tinted ground is drawn both frames are the same.
    assert_eq!(flip_at(&mut h, "noise_mips", "noise"), 0.0);
    // The scene differs where the ground is.
    let scene = flip_at(&mut h, "scene", "scene_color");
    assert!(scene > 0.05, "FLIP {scene}");
    // The renamed pass is paired all the same, as a rename.
    let tonemap = model.pass_named("tonemap").unwrap();
    let a = h.state().against.as_ref().unwrap();
    let (there, renamed) = a.pass_of[tonemap].unwrap();
    assert_eq!(a.model.passes[there].name, "tonemap_aces");
    assert!(renamed);
    h.state_mut().show_pane(Pane::ImageDiff);
    h.run_steps(3);
    assert!(h.query_by_label_contains("FLIP mean").is_some());
}

#[test]
fn read_back_values_match_the_export() {
    let mut h = open("captures/example/frame.json");
    let model = h.state().model.clone();
    h.state_mut()
        .select_pass(model.pass_named("bloom_extract").unwrap());
    h.state_mut()
        .open_resource(model.resource_named("bloom").unwrap());
    settle(&mut h);
    let decoded = h
        .state()
        .displayed
        .as_ref()
        .unwrap()
        .decoded
        .clone()
        .unwrap();

    let out = Scratch::temp("framelab-inspect");
    let run = framelab(&[
        "replay",
        "captures/example/frame.json",
        "--scale",
        "0.25",
        "--frames",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--after",
        "bloom_extract",
        "--resource",
        "bloom",
        "--quiet",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (w, pixels) = exr_image(&out.join("bloom_mip0.exr"));
    assert_eq!(
        (w, pixels.len()),
        (decoded.width as usize, decoded.values.len())
    );
    let lit = pixels.iter().filter(|p| p[0] > 0.0).count();
    assert!(lit > 0, "the bright pass wrote nothing");
    for (i, (e, d)) in pixels.iter().zip(&decoded.values).enumerate() {
        for c in 0..3 {
            assert!(
                (e[c] - d[c]).abs() <= 1e-6,
                "texel {i}: export {e:?}, inspector {d:?}"
            );
        }
    }
}

/// The text of the node whose label contains `text` (egui labels carry it as the value).
fn label_with(h: &egui_kittest::Harness<'static, Inspector>, text: &str) -> String {
    let node = h.get_by_label_contains(text);
    node.value()
        .or_else(|| node.accesskit_node().label())
        .unwrap_or_default()
}

#[test]
fn buffers_stencil_and_saving_a_view() {
    let mut h = open("captures/example/frame.json");
    let model = h.state().model.clone();

    // The buffer viewer: open draw_args from the resource table. After `simulate` it holds
    // the indirect draw arguments the compute pass wrote: the orb mesh's 192 indices (the
    // pass's `index_count` parameter) and one instance per live particle.
    h.get_by_label("Resources").click();
    click_resource_row(&mut h, "draw_args");
    h.state_mut()
        .select_pass(model.pass_named("simulate").unwrap());
    settle(&mut h);
    let draw_args = model.resource_named("draw_args").unwrap();
    assert_eq!(h.state().selection.buffer, Some(draw_args));
    assert!(h.query_by_label("base_vertex").is_some());
    assert!(h.query_by_label("instance_count").is_some());
    assert!(
        h.query_by_label("192").is_some(),
        "index_count after simulate"
    );
    // Right after `reset_args` cleared it, the arguments are zero.
    h.state_mut()
        .select_pass(model.pass_named("reset_args").unwrap());
    settle(&mut h);
    assert!(h.query_by_label("192").is_none());
    assert!(h.query_all_by_label("0").count() >= 5);
    // The particles read as rows of the shader's `Particle` struct.
    let particles = model.resource_named("particles").unwrap();
    h.state_mut().open_resource(particles);
    settle(&mut h);
    assert!(h.query_by_label("position_radius").is_some());
    // Scrolled with the wheel, the table reaches its last row (only rows on screen are laid
    // out, so its index label exists only once it is in view).
    let view = model.resources[particles].buffer.clone().unwrap();
    let rows = framelab_ui::panels::buffer::typed_rows(view.size, &view.layouts[0]);
    let last = (rows - 1).to_string();
    assert!(h.query_by_label(&last).is_none());
    // In a small window, where the panel is shorter than the table's own default height.
    h.set_size(egui::Vec2::new(800.0, 600.0));
    h.run_steps(3);
    let area = h
        .state()
        .pane_rects
        .iter()
        .find(|(p, _)| *p == Pane::Buffer)
        .unwrap()
        .1;
    h.hover_at(area.center());
    for _ in 0..40 {
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -400.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers::NONE,
        });
        h.run_steps(2);
    }
    assert!(h.query_by_label(&last).is_some(), "row {last} not reached");
    h.hover_at(egui::pos2(2.0, 2.0));
    h.set_size(egui::Vec2::new(1400.0, 900.0));
    h.run_steps(3);

    // The stencil aspect of the depth-stencil target, as `scene` cleared it (to 0).
    h.state_mut()
        .select_pass(model.pass_named("scene").unwrap());
    h.state_mut()
        .open_resource(model.resource_named("depth").unwrap());
    h.state_mut().show_aspect(true);
    h.state_mut().pick(3, 2);
    settle(&mut h);
    assert_eq!(label_with(&h, "(3, 2) S"), "(3, 2) S 0 (0b00000000)");

    // Save scene_color as of `scene`: EXR holds the values, PNG the view as shown.
    h.state_mut()
        .open_resource(model.resource_named("scene_color").unwrap());
    settle(&mut h);
    let dir = Scratch::temp("framelab-save");
    h.state_mut().save_path = dir.join("scene").display().to_string();
    h.get_by_label("EXR").click();
    settle(&mut h);
    assert!(
        matches!(h.state().saved, Some(Ok(_))),
        "{:?}",
        h.state().saved
    );
    let (w, pixels) = exr_image(&dir.join("scene.exr"));
    let decoded = h
        .state()
        .displayed
        .as_ref()
        .unwrap()
        .decoded
        .clone()
        .unwrap();
    assert_eq!(w, decoded.width as usize);
    for (c, want) in [0.02f32, 0.03, 0.05, 1.0].into_iter().enumerate() {
        assert!((pixels[0][c] - want).abs() < 1e-3, "{:?}", pixels[0]);
    }
    h.state_mut().save_view(SaveAs::Png);
    settle(&mut h);
    let png = image::open(dir.join("scene.png")).unwrap().to_rgba8();
    assert_eq!(png.dimensions(), (decoded.width, decoded.height));
    // The sky's clear colour, sRGB-encoded for display as the viewer shows it.
    let sky = png.get_pixel(0, 0);
    assert!(sky[2] > sky[0] && sky[0] > 20, "{sky:?}");
}

/// Every docked panel against its blessed image, with timings from a report compared
/// against a second one (`--timings A --compare B`), so the figures and verdict colours are
/// fixed: B has tonemap 60% slower and bloom_mips 40% faster.
#[test]
fn panels_match_their_snapshots_with_compared_timings() {
    let b = report("tests/fixtures/timing/example_b.json");
    let mut h = compared_with(&b);
    let model = h.state().model.clone();
    let compare = model.compare.as_ref().expect("a comparison");
    let verdict = |pass: &str| {
        compare.passes[model.pass_named(pass).unwrap()]
            .as_ref()
            .map(|r| r.verdict.clone())
    };
    assert_eq!(verdict("tonemap").as_deref(), Some("regression"));
    assert_eq!(verdict("bloom_mips").as_deref(), Some("improvement"));
    let tonemap = compare.passes[model.pass_named("tonemap").unwrap()]
        .as_ref()
        .unwrap();
    assert!((tonemap.change_pct - 60.0).abs() < 1.0, "{tonemap:?}");

    h.get_by_label("scene").click();
    h.state_mut()
        .open_resource(model.resource_named("scene_color").unwrap());
    h.state_mut().pick(0, 0);
    settle(&mut h);
    let options = ui_snapshot_options();
    let mut results = egui_kittest::SnapshotResults::new();
    for (pane, name) in [
        (Pane::Timeline, "timeline"),
        (Pane::Resources, "resources"),
        (Pane::Dag, "dag"),
        (Pane::Memory, "memory"),
    ] {
        h.state_mut().show_pane(pane);
        h.run_steps(3);
        results.add(h.try_snapshot_options(name, &options));
    }
    h.state_mut()
        .open_resource(model.resource_named("particles").unwrap());
    settle(&mut h);
    h.run_steps(3);
    results.add(h.try_snapshot_options("buffer", &options));
    results.unwrap();
}

/// The inspector's own options refuse what cannot be shown, by name, before a window opens.
#[test]
fn bad_inspector_options_are_named() {
    let out = framelab(&[
        "inspect",
        "captures/example/frame.json",
        "--scale",
        "0.25",
        "--select",
        "scene",
        "--draw",
        "9",
        "--screenshot",
        "unused.png",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("--draw 9: pass \"scene\" has 2 draws or dispatches"),
        "{}",
        stderr(&out)
    );
    let out = framelab(&[
        "inspect",
        "captures/example/frame.json",
        "--against",
        "no/such/capture.json",
        "--screenshot",
        "unused.png",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("no/such/capture.json"),
        "{}",
        stderr(&out)
    );
    let out = framelab(&["inspect", "captures/example/frame.json", "--history"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--pixel"), "{}", stderr(&out));
    assert!(!repo().join("unused.png").exists());
}

/// What-if edits given to `inspect` replay the variant beside the frame, its static verdict said
/// first; the variant and `--against` cannot both be the second frame.
#[test]
fn a_what_if_variant_opens_beside_its_frame() {
    let dir = Scratch::temp("framelab-inspect-what-if");
    let shot = dir.join("what_if.png");
    let out = framelab(&[
        "inspect",
        "captures/example/frame_sync.json",
        "--scale",
        "0.25",
        "--format",
        "bloom=R11G11B10_FLOAT",
        "--select",
        "bright_pass",
        "--view",
        "bloom",
        "--panel",
        "Image diff",
        "--screenshot",
        shot.to_str().unwrap(),
        "--size",
        "1000x700",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stderr(&out)
            .contains("what if: \"bloom\" R16G16B16A16_FLOAT -> R11G11B10_FLOAT; static: safe"),
        "{}",
        stderr(&out)
    );
    assert_eq!(image::open(&shot).unwrap().width(), 1000);
    // An unsafe variant opens all the same (to look at what it breaks), said so first.
    let unsafe_edit = framelab(&[
        "inspect",
        "captures/example/frame_sync.json",
        "--scale",
        "0.25",
        "--drop-barrier",
        "simulate:0",
        "--screenshot",
        shot.to_str().unwrap(),
        "--size",
        "640x480",
    ]);
    assert_eq!(
        unsafe_edit.status.code(),
        Some(0),
        "{}",
        stderr(&unsafe_edit)
    );
    assert!(
        stderr(&unsafe_edit).contains("static: UNSAFE: FL020"),
        "{}",
        stderr(&unsafe_edit)
    );
    let both = framelab(&[
        "inspect",
        "captures/example/frame_sync.json",
        "--cull",
        "present",
        "--against",
        "captures/example/frame.json",
        "--screenshot",
        "unused.png",
    ]);
    assert_eq!(both.status.code(), Some(1));
    assert!(
        stderr(&both).contains("--against and what-if edits"),
        "{}",
        stderr(&both)
    );
    assert!(!repo().join("unused.png").exists());
}

/// Reports taken at different scales are still compared, under a warning; a pass renamed
/// there is matched as a rename, one moved to another queue is shown but not compared.
#[test]
fn reports_at_different_scales_are_compared_under_a_warning() {
    let mut b = report("tests/fixtures/timing/example_b.json");
    b.scale *= 2.0;
    for p in &mut b.passes {
        if p.name == "tonemap" {
            p.name = "tonemap_aces".into();
            p.marker_path = "Frame/Post/tonemap_aces".into();
        }
        if p.name == "simulate" {
            p.queue = "gfx".into();
        }
    }
    let mut h = compared_with(&b);
    let model = h.state().model.clone();
    let compare = model.compare.as_ref().expect("compared all the same");
    let note = compare.note.clone().expect("a warning");
    assert!(note.contains("different scales"), "{note}");
    let row = |name: &str| compare.passes[model.pass_named(name).unwrap()].clone();
    let tonemap = row("tonemap").expect("the renamed pass matched");
    assert_eq!(tonemap.renamed.as_deref(), Some("tonemap_aces"));
    let simulate = row("simulate").expect("the moved pass shown");
    assert_eq!(simulate.moved.as_deref(), Some("gfx"));
    assert_eq!(simulate.verdict, "moved");
    assert!(row("scene").is_some_and(|r| r.renamed.is_none() && r.moved.is_none()));
    h.state_mut().show_pane(Pane::Timeline);
    h.run_steps(3);
    assert!(h.query_by_label_contains("different scales").is_some());
    assert!(
        h.query_by_label_contains("regression: slower there")
            .is_some()
    );
}

/// The pass panel says which reads see last frame: TAA's `history` is the previous frame's
/// `taa_output` (nothing has written it yet this frame), while the blur chain that follows
/// reads this frame's.
#[test]
fn history_reads_are_labelled_previous_frame() {
    let path = repo().join("captures/night_city/main_street_day.json");
    let analysed = Analysed::load(&path, &Options::default(), AnalyzeOptions::default()).unwrap();
    let model = inspect::model_without_replay(&analysed, &Reports::default()).unwrap();
    let binding = |pass: &str, variable: &str| {
        let p = model.passes.iter().find(|p| p.name == pass).unwrap();
        p.bindings
            .iter()
            .find(|(v, _)| v == variable)
            .unwrap()
            .1
            .clone()
    };
    assert!(binding("taa", "history").starts_with("taa_output (previous frame) as"));
    assert!(binding("taa", "composite").starts_with("composite as"));
    assert!(binding("taa_blur_downscale", "taa_output").starts_with("taa_output as"));
    assert!(binding("ssr_trace", "taa_downscaled").contains("(previous frame)"));
}

/// A report whose tonemap times the adapter could not be trusted for: tonemap keeps a place
/// on the timeline, unmeasured and after the pass before it, and the timeline says why.
#[test]
fn untrusted_report_times_stay_on_the_timeline_unmeasured() {
    let path = repo().join("captures/example/frame.json");
    let analysed = Analysed::load(&path, &Options::default(), AnalyzeOptions::default()).unwrap();
    let mut report = report("tests/fixtures/timing/example_a.json");
    let tonemap = report
        .passes
        .iter_mut()
        .find(|p| p.name == "tonemap")
        .unwrap();
    tonemap.gpu_untrusted = Some("not measured here".into());
    let reports = Reports {
        timings: Some((&report, "a.json".into())),
        compare: None,
    };
    let model = inspect::model_without_replay(&analysed, &reports).unwrap();
    let timings = model.timings.as_ref().unwrap();
    assert_eq!(timings.note.as_deref(), Some("not measured here"));
    let at = |name: &str| timings.passes[model.pass_named(name).unwrap()].unwrap();
    let (tonemap, bloom_mips) = (at("tonemap"), at("bloom_mips"));
    assert!(!tonemap.measured);
    assert!(bloom_mips.measured);
    assert!(tonemap.start_ns >= bloom_mips.start_ns + bloom_mips.gpu_ns);
}

/// A real program's frame (vkd3d-gears, imported from its binary capture) opens replayed: the
/// presented image first, and a pass's state and work name the Vulkan pipelines its draws run
/// with.
#[test]
fn an_imported_frame_opens_on_its_presented_image_with_its_pipelines() {
    let dir = Scratch::temp("framelab-inspector-imported");
    let capture = dir.join("gears.json");
    let out = crate::common::framelab(&[
        "import",
        crate::common::gfxr_fixture("vkd3d_gears_f2.gfxr")
            .to_str()
            .unwrap(),
        "-o",
        capture.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", crate::common::stderr(&out));
    let mut h = open(capture.to_str().unwrap());
    let presented = h.state().model.resource_named("swapchain_0");
    assert!(presented.is_some());
    assert_eq!(h.state().selection.resource, presented);
    h.get_by_label("render_pass 3").click();
    settle(&mut h);
    assert!(
        h.query_by_label("pipeline_86").is_some(),
        "state names the pipeline"
    );
    // In the events list and the pass's work.
    assert!(
        h.query_all_by_label_contains("1080 vertices x1 instances with pipeline_86")
            .count()
            >= 1,
        "work names each draw's pipeline"
    );
    drop(h);
}

/// The frames the inspector times are counted: the pass details show a pass's counters, and
/// the timeline can be coloured by any of them, with a legend saying which.
#[test]
fn the_timed_frame_is_counted_and_colours_the_timeline() {
    let mut h = open("captures/example/frame.json");
    let model = h.state().model.clone();
    let bloom = model.pass_named("bloom_extract").unwrap();
    let timings = h.state().timings.clone().expect("live timings");
    let counts = timings.passes[bloom]
        .and_then(|t| t.counters)
        .expect("bloom_extract counted");
    // A fullscreen triangle: 3 vertices, one primitive in.
    assert_eq!(counts[..2], [3, 1]);
    let area = timings.work[bloom].as_ref().unwrap().render_area;
    assert!(
        counts[3] >= area,
        "{} fragments over {area} pixels",
        counts[3]
    );
    // A copy pass has no counters.
    let upload = model.pass_named("upload_noise").unwrap();
    assert!(timings.passes[upload].is_none_or(|t| t.counters.is_none()));

    h.get_by_label("bloom_extract").click();
    settle(&mut h);
    assert!(h.query_by_label_contains("Counters (9)").is_some());
    let fragments = format!(
        "{} ({})",
        counts[3],
        framelab_core::timing::counters::short(counts[3])
    );
    assert!(h.query_by_label(&fragments).is_some(), "{fragments} shown");
    assert!(
        h.query_by_label_contains("overdraw (fragments per pixel)")
            .is_some()
    );

    h.get_by_label("Timeline").click();
    h.run_steps(2);
    assert!(h.query_by_label_contains("colour by").is_some());
    h.state_mut().color_timeline_by(3);
    h.run_steps(2);
    assert!(
        h.query_by_label_contains("fragment_invocations (grey: not counted)")
            .is_some()
    );
}
