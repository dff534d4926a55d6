//! The inspector's panels on a fixed model, driven by label with egui_kittest as a user would,
//! without a replay or a GPU: the panels see only the model and the selection, so what they
//! show and what a click changes can be checked here, apart from the capture and the device.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use framelab_ui::Inspector;
use framelab_ui::app::Pane;
use framelab_ui::egui;
use framelab_ui::egui::Key;
use framelab_ui::egui_kittest::Harness;
use framelab_ui::egui_kittest::kittest::Queryable;
use framelab_ui::model::{
    Barrier, BarrierSide, BarrierSource, BufferView, Edge, EdgeKind, Inspection, MemoryBlock, Pass,
    PassId, Resource, ResourceId,
};

fn pass(id: u32, name: &str, queue: usize, markers: &[&str]) -> Pass {
    Pass {
        id: PassId(id),
        name: name.to_owned(),
        queue,
        kind: if queue == 0 { "raster" } else { "compute" }.to_owned(),
        markers: markers.iter().map(|m| (*m).to_owned()).collect(),
        culled: false,
        work: vec![format!("{name} work line")],
        steps: 1,
        bindings: vec![("input".to_owned(), format!("{name}_input as texture_2d"))],
        attachments: Vec::new(),
        state: Vec::new(),
        params: Vec::new(),
        barriers: vec![Barrier {
            side: BarrierSide::Before,
            source: BarrierSource::Derived,
            kind: "transition".to_owned(),
            resource: "color".to_owned(),
            subresource: "all".to_owned(),
            states: "RENDER_TARGET -> PIXEL_SHADER_RESOURCE".to_owned(),
            vulkan: "COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL; ...".to_owned(),
        }],
        lints: Vec::new(),
        inputs: Vec::new(),
        outputs: Vec::new(),
    }
}

fn resource(id: u32, name: &str, buffer: bool) -> Resource {
    Resource {
        id: ResourceId(id),
        name: name.to_owned(),
        kind: if buffer { "buffer" } else { "texture_2d" }.to_owned(),
        format: if buffer { "" } else { "R8G8B8A8_UNORM" }.to_owned(),
        width: 64,
        height: if buffer { 1 } else { 32 },
        depth: 1,
        mips: 1,
        layers: 1,
        bytes: 8192,
        heap: "committed (DEFAULT)".to_owned(),
        offset: Some(0),
        first_pass: Some(0),
        last_pass: Some(2),
        aliases: Vec::new(),
        texture: None,
        buffer: buffer.then(|| BufferView {
            plan_index: 0,
            size: 8192,
            layouts: Vec::new(),
            indirect: Vec::new(),
        }),
    }
}

/// Three passes on two queues under one marker group, a texture and a buffer.
fn model() -> Inspection {
    Inspection {
        capture: "fixed".to_owned(),
        scale: 1.0,
        queues: vec!["gfx".to_owned(), "async".to_owned()],
        passes: vec![
            pass(0, "shadow", 0, &["Frame"]),
            pass(2, "simulate", 1, &["Frame"]),
            pass(1, "compose", 0, &["Frame", "Post"]),
        ],
        resources: vec![resource(0, "color", false), resource(1, "particles", true)],
        fences: vec![(1, 2)],
        edges: vec![Edge {
            from: 0,
            to: 2,
            kind: EdgeKind::Raw,
            resource: Some("color".to_owned()),
        }],
        memory: vec![MemoryBlock {
            resource: ResourceId(0),
            pool: "DEFAULT".to_owned(),
            offset: 0,
            bytes: 8192,
            first: 0,
            last: 2,
        }],
        timings: None,
        compare: None,
        presented: None,
        vulkan_terms: false,
    }
}

fn open() -> Harness<'static, Inspector> {
    open_model(model())
}

fn open_model(model: Inspection) -> Harness<'static, Inspector> {
    let app = Inspector::new(model, None);
    let mut h = Harness::builder()
        .with_size(egui::Vec2::new(1400.0, 900.0))
        .build_ui_state(|ui, app: &mut Inspector| app.ui(ui), app);
    h.run_steps(4);
    h
}

#[test]
fn a_fresh_inspector_shows_the_last_pass_and_says_it_does_not_replay() {
    let h = open();
    assert_eq!(h.state().selection.pass, 2);
    assert!(h.query_by_label_contains("no replay").is_some());
    // The pass panel: the name, its kind and queue, its derived barrier.
    assert!(h.query_by_label("raster on gfx, not timed").is_some());
    assert!(
        h.query_by_label_contains("RENDER_TARGET -> PIXEL_SHADER_RESOURCE")
            .is_some()
    );
}

#[test]
fn a_vulkan_programs_barriers_are_shown_in_vulkan_terms_alone() {
    let h = open();
    assert!(h.query_by_label("D3D12").is_some());
    let h = open_model(Inspection {
        vulkan_terms: true,
        ..model()
    });
    assert!(h.query_by_label("D3D12").is_none());
    assert!(h.query_by_label("Vulkan").is_some());
    assert!(
        h.query_by_label_contains("RENDER_TARGET -> PIXEL_SHADER_RESOURCE")
            .is_none()
    );
    assert!(
        h.query_by_label_contains("COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL")
            .is_some()
    );
}

#[test]
fn clicking_a_pass_in_the_event_list_selects_it_and_shows_its_work() {
    let mut h = open();
    let shown = |h: &Harness<'static, Inspector>, label: &str| h.query_all_by_label(label).count();
    let row = |h: &Harness<'static, Inspector>, label: &str| {
        h.get_all_by_label(label).next().unwrap().rect()
    };
    // The pass panel lists the current pass's work; the event list only an expanded pass's.
    assert_eq!(shown(&h, "shadow work line"), 0);
    assert_eq!(shown(&h, "compose work line"), 1);
    let compose_row = row(&h, "compose");
    h.get_all_by_label("shadow").next().unwrap().click();
    h.run_steps(3);
    assert_eq!(h.state().selection.pass, 0);
    assert_eq!(h.state().model.passes[0].id, PassId(0));
    assert_eq!(shown(&h, "shadow work line"), 1);
    assert_eq!(shown(&h, "compose work line"), 0);
    // Selecting a pass moves no row.
    assert_eq!(row(&h, "compose"), compose_row);
    // Expanded, the pass lists its work in the event list, and its draw can be selected.
    h.get_all_by_label(">").next().unwrap().click();
    h.run_steps(3);
    assert_eq!(shown(&h, "shadow work line"), 2);
    h.get_all_by_label("shadow work line")
        .next()
        .unwrap()
        .click();
    h.run_steps(2);
    assert_eq!(h.state().selection.step, Some(0));
    assert_eq!(h.state().selection.pass, 0);
}

#[test]
fn the_filter_hides_passes_by_name_and_marker() {
    let mut h = open();
    h.get_by_label("filter").click();
    h.run_steps(2);
    assert!(h.query_by_label("shadow").is_some());
    h.get_by_label("filter").type_text("post");
    h.run_steps(3);
    // `compose` is under the Post marker (and is the current pass, named by the pass panel
    // too); the others are hidden from the list.
    assert!(h.query_all_by_label("compose").count() >= 1);
    assert!(h.query_by_label("shadow").is_none());
    assert!(h.query_by_label("simulate").is_none());
}

#[test]
fn arrow_keys_step_through_the_visible_passes() {
    let mut h = open();
    h.get_all_by_label("shadow").next().unwrap().click();
    h.run_steps(2);
    h.key_press(Key::ArrowDown);
    h.run_steps(2);
    assert_eq!(h.state().selection.pass, 1);
    h.key_press(Key::ArrowDown);
    h.run_steps(2);
    assert_eq!(h.state().selection.pass, 2);
    h.key_press(Key::ArrowUp);
    h.run_steps(2);
    assert_eq!(h.state().selection.pass, 1);
}

#[test]
fn opening_a_buffer_from_the_resource_table_brings_the_buffer_viewer_forward() {
    let mut h = open();
    h.state_mut().show_pane(Pane::Resources);
    h.run_steps(3);
    assert!(h.query_by_label("8192 bytes").is_none());
    h.get_by_label("particles").click();
    h.run_steps(3);
    assert_eq!(h.state().selection.buffer, Some(1));
    // The buffer viewer is in front, showing the buffer's size (its bytes wait for a replay).
    assert!(h.query_by_label("8192 bytes").is_some());
    assert!(h.query_by_label_contains("Open a buffer").is_none());
}
