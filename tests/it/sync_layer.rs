//! framelab's synchronization hazards on real frames against the Khronos validation layer's
//! synchronization validation, run on the application's own command stream: each
//! GFXReconstruct fixture is replayed by `gfxrecon-replay` under the layer (on a virtual X
//! server: the replay opens the application's window), and the layer's `SYNC-HAZARD-*`
//! messages are compared with the hazards `framelab import` found, as (command, hazard kind,
//! access, earlier access, earlier command). RenderDoc captures are compared with the layer
//! on GFXReconstruct's capture of the same program.
//!
//! Where the two differ it is written down here with the specification's rule: the layer
//! orders render pass attachment accesses by rasterization order across render pass
//! instances; the specification guarantees rasterization order within a subpass only.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::common::{Display, Scratch, framelab, gfxr_fixture, repo, start_display, stderr};

/// (command, hazard kind, access, earlier access, earlier command), in the layer's words.
type Finding = (String, String, String, String, String);

/// Xlib for 320x240 captures: with XCB, gfxrecon-replay waits forever for a window of its own
/// default size (no resize event comes).
fn wsi(capture: &Path) -> &'static [&'static str] {
    let name = capture.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    match name {
        "qtquick_f30"
        | "qt6quick_f30"
        | "mpv_testsrc2_f30"
        | "gtk4_f30"
        | "gstreamer_f30"
        | "qt6_msaa_f30"
        | "qt6_quick3d_f30"
        | "vkbasalt_all_f30"
        | "vkbasalt_reshade_f30"
        | "vkbasalt_rgb10a2_f30"
        | "vkbasalt_mrt_f30"
        | "vkbasalt_depth_qt3d_f30"
        | "qt6_video_p010le_f60"
        | "mpv_gpunext_f30"
        | "vlc_zink_f40"
        | "libreoffice_skia_f60"
        | "qt5_hellovulkanwindow_f30"
        | "mame_menu_f60" => &["--wsi", "xlib"],
        _ => &[],
    }
}

/// The layer's synchronization findings on `capture` replayed by gfxrecon-replay.
fn layer_findings(capture: &Path, display: &Display, dir: &Path) -> BTreeSet<Finding> {
    let log = replay_under_layer(
        capture,
        display,
        dir,
        "sync_log.txt",
        &[
            "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT",
            // Hazards between command buffers and submissions, checked when they are
            // submitted: off by default in this layer.
            "VALIDATION_CHECK_ENABLE_SYNCHRONIZATION_VALIDATION_QUEUE_SUBMIT",
        ],
    );
    let text = std::fs::read_to_string(&log).unwrap_or_else(|e| {
        panic!("the validation layer wrote no log ({e}): is vulkan-validationlayers installed?")
    });
    text.lines()
        .filter(|l| l.contains("SYNC-HAZARD-") || layout_message(l).is_some())
        .map(|l| {
            layout_message(l)
                .or_else(|| parse_layer(l))
                .unwrap_or_else(|| panic!("{}: unreadable layer message: {l}", capture.display()))
        })
        .collect()
}

/// `... | vkCmdBeginRenderPass: Hazard READ_AFTER_WRITE in ... Access info (usage: X,
/// prior_usage: Y, write_barriers: ..., command: Z, ...)` at record time; at submit time
/// `vkQueueSubmit: Hazard K for entry N, VkCommandBuffer ..., Recorded access info
/// (recorded_usage: X, command: C, ...). Access info (prior_usage: Y, ..., command: Z, ...)`,
/// where the command is the recorded one (C).
fn parse_layer(line: &str) -> Option<Finding> {
    let after = line.rsplit_once("| ")?.1;
    let (command, rest) = after.split_once(": Hazard ")?;
    let kind = rest.split_whitespace().next()?;
    let field = |text: &str, key: &str| -> Option<String> {
        let at = text.find(&format!("{key}: "))? + key.len() + 2;
        Some(text[at..].split([',', ')']).next()?.trim().to_owned())
    };
    if let Some((recorded, access)) = rest
        .split_once("Recorded access info (")
        .and_then(|(_, r)| r.split_once(". Access info ("))
    {
        // An acquire's read, or a present, names the call instead of a command.
        let prior_command = field(access, "command").or_else(|| {
            access
                .split_whitespace()
                .find(|w| w.starts_with("vkAcquireNextImage") || w.starts_with("vkQueuePresent"))
                .map(str::to_owned)
        })?;
        return Some((
            field(recorded, "command")?,
            kind.to_owned(),
            field(recorded, "recorded_usage")?,
            field(access, "prior_usage")?,
            prior_command,
        ));
    }
    if let Some(load) = rest
        .split_once(" vs. layout transition in subpass ")
        .map(|(_, l)| l)
    {
        return Some(load_after_transition(command.trim(), kind, load));
    }
    Some((
        command.trim().to_owned(),
        kind.to_owned(),
        field(rest, "usage")?,
        field(rest, "prior_usage")?,
        field(rest, "command")?,
    ))
}

/// `vkCmdBeginRenderPass: Hazard K vs. layout transition in subpass N for attachment A aspect
/// depth during load with loadOp OP`: an attachment's load operation against the layout
/// transition the same begin performs, which the layer words without access info. The load's
/// access follows the attachment's aspect and load op (a clear or don't-care writes, a load
/// reads).
fn load_after_transition(command: &str, kind: &str, load: &str) -> Finding {
    let depth = load.contains("aspect depth") || load.contains("aspect stencil");
    let reads = load.contains("VK_ATTACHMENT_LOAD_OP_LOAD");
    let usage = match (depth, reads) {
        (true, true) => "SYNC_EARLY_FRAGMENT_TESTS_DEPTH_STENCIL_ATTACHMENT_READ",
        (true, false) => "SYNC_EARLY_FRAGMENT_TESTS_DEPTH_STENCIL_ATTACHMENT_WRITE",
        (false, true) => "SYNC_COLOR_ATTACHMENT_OUTPUT_COLOR_ATTACHMENT_READ",
        (false, false) => "SYNC_COLOR_ATTACHMENT_OUTPUT_COLOR_ATTACHMENT_WRITE",
    };
    (
        command.to_owned(),
        kind.to_owned(),
        usage.to_owned(),
        "SYNC_IMAGE_LAYOUT_TRANSITION".to_owned(),
        command.to_owned(),
    )
}

/// The layer's image layout errors, as (command, `LAYOUT_MISMATCH`, expected layout,
/// current layout, ""): a barrier's old layout that is not the image's, a render pass begun
/// with an attachment in another layout than its initialLayout, and a descriptor whose image
/// is in another layout than the descriptor says; each at the command where the command
/// buffer itself put the image in that layout, and otherwise at the submission, where the
/// layer holds what the command buffer expects against the layout the image is in
/// (`vkQueueSubmit(): ... expects VkImage ... to be in layout X--instead, current layout is Y`).
fn layout_message(line: &str) -> Option<Finding> {
    let text = line.rsplit_once("| ")?.1;
    let command =
        if text.contains(" expects VkImage ") && text.contains("--instead, current layout is") {
            text.split(':').next()?.trim_end_matches("()")
        } else if line.contains("VUID-VkImageMemoryBarrier-oldLayout-01197") {
            "vkCmdPipelineBarrier"
        } else if line.contains("cannot start a render pass using attachment") {
            "vkCmdBeginRenderPass"
        } else if line.contains("VUID-VkDescriptorImageInfo-imageLayout-00344") {
            // `vkCmdDraw: Cannot use VkImage ... with specific layout X that doesn't match the
            // previous known layout Y.`
            text.split(':').next()?
        } else {
            return None;
        };
    let mut layouts = text
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter_map(|w| w.strip_prefix("VK_IMAGE_LAYOUT_"));
    Some((
        command.to_owned(),
        "LAYOUT_MISMATCH".to_owned(),
        layouts.next()?.to_owned(),
        layouts.next()?.to_owned(),
        String::new(),
    ))
}

/// framelab's access description in the layer's words: `SYNC_<stage>_<access>`, a layout
/// transition `SYNC_IMAGE_LAYOUT_TRANSITION`.
fn usage(access: &str) -> String {
    if access.starts_with("layout transition") {
        return "SYNC_IMAGE_LAYOUT_TRANSITION".to_owned();
    }
    if access.starts_with("presentation engine read (acquire)") {
        return "SYNC_PRESENT_ENGINE_SYNCVAL_PRESENT_ACQUIRE_READ_SYNCVAL".to_owned();
    }
    if access.starts_with("presentation engine read (present)")
        || access.starts_with("presentation engine read (its last present")
    {
        return "SYNC_PRESENT_ENGINE_SYNCVAL_PRESENT_PRESENTED_SYNCVAL".to_owned();
    }
    let scope = access.split_whitespace().next().unwrap_or("");
    let (stage, access) = scope.split_once('/').unwrap_or((scope, ""));
    format!("SYNC_{stage}_{access}")
}

fn call(command: &str) -> String {
    command.split(" #").next().unwrap_or(command).to_owned()
}

/// framelab's findings on an imported capture, and those of them where both accesses are
/// attachment load and store operations of different render pass instances.
fn framelab_findings(capture: &Path) -> (BTreeSet<Finding>, BTreeSet<Finding>) {
    let c: Value = serde_json::from_str(&std::fs::read_to_string(capture).unwrap()).unwrap();
    let hazards = c["source"]["sync_hazards"]
        .as_array()
        .unwrap_or_else(|| panic!("{}: the import checked no stream", capture.display()));
    let (mut all, mut across) = (BTreeSet::new(), BTreeSet::new());
    for h in hazards {
        let s = |k: &str| h[k].as_str().unwrap().to_owned();
        let last = |k: &str| s(k).rsplit(' ').next().unwrap_or("").to_owned();
        if s("kind") == "LAYOUT_MISMATCH" {
            if dynamic_rendering_at_submit(&s("command"), &s("access")) {
                continue;
            }
            // `descriptor in SHADER_READ_ONLY_OPTIMAL` (at `vkCmdDraw #12` when judged at
            // the submission): the layout is the first word in capitals.
            let expected = s("access")
                .split_whitespace()
                .find(|w| w.len() > 1 && w.chars().all(|c| c.is_ascii_uppercase() || c == '_'))
                .unwrap_or("")
                .to_owned();
            all.insert((
                call(&s("command")),
                s("kind"),
                expected,
                last("prior"),
                String::new(),
            ));
            continue;
        }
        // A write after present names the acquire that did not order it; the layer names
        // the present it raced (in a trimmed capture, gfxrecon-replay's own, restoring the
        // swapchain).
        let prior_command = if s("kind") == "WRITE_AFTER_PRESENT" {
            "vkQueuePresentKHR".to_owned()
        } else {
            call(&s("prior_command"))
        };
        let f = (
            call(&s("command")),
            s("kind"),
            usage(&s("access")),
            usage(&s("prior")),
            prior_command,
        );
        if s("access").contains("load op") && s("prior").contains("store op") {
            across.insert(f.clone());
        }
        all.insert(f);
    }
    (all, across)
}

/// A dynamic rendering attachment in another layout than its `imageLayout`, where a command
/// buffer other than the one rendering put it there. The specification asks the image to be
/// in the layout `imageLayout` names during rendering (`vkCmdBeginRendering` transitions
/// nothing), as a render pass's `initialLayout`; Debian 12's layer (1.3.239) holds render
/// passes' initial layouts against the image's at submission but not dynamic rendering's
/// (0 A.D. through zink: a depth image never transitioned since its creation, rendered to
/// as `DEPTH_STENCIL_READ_ONLY_OPTIMAL`). framelab reports it; the comparison leaves it out.
fn dynamic_rendering_at_submit(command: &str, access: &str) -> bool {
    command.starts_with("vkQueueSubmit")
        && access.starts_with("attachment in")
        && access.contains(" at vkCmdBeginRendering")
}

fn temp(name: &str) -> Scratch {
    Scratch::temp(&format!("framelab-sync-{name}"))
}

fn import(input: &Path, out: &Path) {
    let run = framelab(&[
        "import",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
}

/// GFXReconstruct captures, with the hazards framelab finds that the layer does not because
/// of its ordering rule where the specification has none (expected count): rasterization
/// order across render passes.
const GFXR: [(&str, usize); 42] = [
    ("vkcube_f3", 0),
    ("vkcube_staging", 0),
    ("template_compute", 0),
    ("vkcube_f184", 0),
    ("vkcubepp_f3", 0),
    ("vkd3d_triangle_f1", 1),
    ("vkd3d_gears_f2", 2),
    ("mpv_testsrc_f5", 0),
    ("mpv_hq_f5", 0),
    ("framelab_inspect_f3", 0),
    ("write_after_read", 0),
    ("qtquick_f30", 0),
    ("qt6quick_f30", 0),
    ("mpv_testsrc2_f30", 0),
    ("gtk4_f30", 0),
    ("gstreamer_f30", 0),
    ("vkbasalt_f100", 0),
    ("mangohud_f30", 0),
    ("zink_es2gears_f30", 0),
    ("warzone_menu_f120", 0),
    ("qt6_msaa_f30", 0),
    ("qt6_quick3d_f30", 0),
    ("vkbasalt_all_f30", 0),
    ("chromium_angle_f60", 0),
    ("vkmark_effect2d_f30", 0),
    ("sdl_testvulkan_f30", 0),
    ("vkbasalt_reshade_f30", 1),
    ("glmark2_zink_ideas_f30", 0),
    ("vkbasalt_rgb10a2_f30", 1),
    ("mpv_gpunext_f30", 0),
    ("vlc_zink_f40", 0),
    ("zeroad_zink_menu_f60", 0),
    ("ffmpeg_chain", 0),
    ("ffmpeg_overlay", 0),
    ("vkbasalt_mrt_f30", 0),
    ("vkbasalt_depth_qt3d_f30", 0),
    ("ffmpeg_rgba_scale_yuv", 0),
    ("qt6_video_p010le_f60", 0),
    ("glmark2_zink_shadow_f30", 0),
    ("libreoffice_skia_f60", 0),
    ("qt5_hellovulkanwindow_f30", 0),
    ("mame_menu_f60", 0),
];

/// Captures whose submissions wait on timeline semaphores (FFmpeg's filters: each submission
/// waits for the last one's values at `TOP_OF_PIPE`, which in a second scope stands for all
/// commands, so everything it records, layout transitions included, follows the signalled
/// work). The layer of Debian 12 (1.3.239) does not follow timeline waits between submissions
/// and reports each layout transition after the earlier submission's writes as a
/// WRITE_AFTER_WRITE; framelab, by the specification's rule, does not.
const TIMELINE_WAITS: [&str; 3] = ["ffmpeg_chain", "ffmpeg_overlay", "ffmpeg_rgba_scale_yuv"];

/// The layer's findings on a capture of [`TIMELINE_WAITS`] less the layout transitions after
/// writes that a timeline wait orders, which must be all it reports beyond framelab, and some.
fn beyond_timeline_waits(
    name: &str,
    layer: &BTreeSet<Finding>,
    ours: &BTreeSet<Finding>,
    failures: &mut Vec<String>,
) -> BTreeSet<Finding> {
    let (ordered, rest): (BTreeSet<Finding>, BTreeSet<Finding>) =
        layer.iter().cloned().partition(|f| {
            !ours.contains(f)
                && f.0 == "vkCmdPipelineBarrier"
                && f.1 == "WRITE_AFTER_WRITE"
                && f.2 == "SYNC_IMAGE_LAYOUT_TRANSITION"
        });
    if ordered.is_empty() {
        failures.push(format!(
            "{name}: the layer no longer reports layout transitions after timeline waits"
        ));
    }
    rest
}

/// RenderDoc captures and the GFXReconstruct capture of the same program the layer ran on.
const RDC: [(&str, &str); 4] = [
    ("vkcube_frame183", "vkcube_f184"),
    ("vkd3d_gears_f3445", "vkd3d_gears_f2"),
    ("mpv_testsrc_f73", "mpv_testsrc_f5"),
    ("framelab_inspect_f117", "framelab_inspect_f3"),
];

#[test]
fn hazards_on_real_frames_are_the_validation_layers() {
    let dir = temp("layer");
    let display = start_display();
    let mut layer_of = std::collections::BTreeMap::new();
    let mut agreed = Vec::new();
    let mut failures = Vec::new();
    for (name, across_expected) in GFXR {
        let capture = gfxr_fixture(&format!("{name}.gfxr"));
        let layer = layer_findings(&capture, &display, &dir);
        let out = dir.join(format!("{name}.json"));
        import(&capture, &out);
        // Every valid-usage error framelab finds in the calls, the layer reports too (it
        // also reports gfxrecon-replay's own render passes of a trimmed capture's restore).
        let skipped = not_replayed(&dir);
        let vuids: BTreeSet<_> = framelab_vuids(&out)
            .into_iter()
            .filter(|v| !(v.1 == EXTENSION_NOT_ENABLED && skipped.contains(&v.0)))
            .collect();
        let layer_vuids = vuids_in_log(&dir.join("sync_log.txt"));
        if !vuids.is_subset(&layer_vuids) {
            failures.push(format!(
                "{name}: valid-usage errors the layer does not report: {:?}",
                vuids.difference(&layer_vuids).collect::<Vec<_>>()
            ));
        }
        // And every one the layer reports of the classes checked, but for attachment
        // descriptions, which gfxrecon-replay's own render passes break.
        let missed: Vec<_> = layer_vuids
            .iter()
            .filter(|v| !v.1.starts_with("VUID-VkAttachmentDescription") && !vuids.contains(v))
            .filter(|v| !replays_own_stencil_shader(v, &out))
            .collect();
        if !missed.is_empty() {
            failures.push(format!(
                "{name}: valid-usage errors framelab does not report: {missed:?}"
            ));
        }
        let (ours, across) = framelab_findings(&out);
        // The specification (synchronization chapter, rasterization order) orders attachment
        // accesses in rasterization order within a subpass; a render pass's load operations
        // happen-before the first subpass's commands and its store operations after the
        // last's, and nothing orders one render pass instance's store with the next one's
        // load on the same attachment but a dependency. The layer orders them by raster
        // order anyway (its ordering rule for attachment accesses spans render passes).
        if across.len() != across_expected {
            failures.push(format!(
                "{name}: hazards the layer orders where the specification does not: {across:?}"
            ));
        }
        let without: BTreeSet<Finding> = ours.difference(&across).cloned().collect();
        let layer = if TIMELINE_WAITS.contains(&name) {
            beyond_timeline_waits(name, &layer, &without, &mut failures)
        } else {
            layer
        };
        if without != layer {
            failures.push(format!(
                "{name}: framelab only {:?}\n    the layer only {:?}",
                without.difference(&layer).collect::<Vec<_>>(),
                layer.difference(&without).collect::<Vec<_>>()
            ));
        }
        agreed.push(format!("{name}: {} hazard(s)", layer.len()));
        layer_of.insert(name, layer);
    }
    for (name, same_program) in RDC {
        let out = dir.join(format!("{name}.json"));
        import(&repo().join(format!("tests/fixtures/rdc/{name}.rdc")), &out);
        let (ours, across) = framelab_findings(&out);
        let without: BTreeSet<Finding> = ours.difference(&across).cloned().collect();
        // RenderDoc does not record vkAcquireNextImageKHR, so its capture cannot show a
        // hazard against the presentation engine's read that an acquire orders.
        let layer: BTreeSet<Finding> = layer_of[same_program]
            .iter()
            .filter(|f| !f.3.contains("PRESENT_ACQUIRE_READ"))
            .cloned()
            .collect();
        assert_eq!(
            &without, &layer,
            "{name}: framelab on RenderDoc's capture (left) and the layer on {same_program} (right) differ"
        );
    }
    eprintln!("agreed: {}", agreed.join(", "));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The mpv frames do have a hazard, which both report: loadOp LOAD reads the attachment
    // after a layout transition whose barrier made it visible to writes only.
    assert!(!layer_of["mpv_testsrc_f5"].is_empty());
}

#[test]
fn layer_messages_are_read() {
    let line = "SYNC-HAZARD-READ-AFTER-WRITE(ERROR / SPEC): msgNum: -455515022 - Validation Error: [ SYNC-HAZARD-READ-AFTER-WRITE ] Object 0: handle = 0x320000000032, type = VK_OBJECT_TYPE_RENDER_PASS; | MessageID = 0xe4d96472 | vkCmdBeginRenderPass: Hazard READ_AFTER_WRITE in subpass 0 for attachment 0 aspect color during load with loadOp VK_ATTACHMENT_LOAD_OP_LOAD. Access info (usage: SYNC_COLOR_ATTACHMENT_OUTPUT_COLOR_ATTACHMENT_READ, prior_usage: SYNC_IMAGE_LAYOUT_TRANSITION, write_barriers: SYNC_COLOR_ATTACHMENT_OUTPUT_COLOR_ATTACHMENT_WRITE, command: vkCmdPipelineBarrier, seq_no: 2, reset_no: 5).";
    assert_eq!(
        parse_layer(line),
        Some((
            "vkCmdBeginRenderPass".to_owned(),
            "READ_AFTER_WRITE".to_owned(),
            "SYNC_COLOR_ATTACHMENT_OUTPUT_COLOR_ATTACHMENT_READ".to_owned(),
            "SYNC_IMAGE_LAYOUT_TRANSITION".to_owned(),
            "vkCmdPipelineBarrier".to_owned(),
        ))
    );
    let submitted = "SYNC-HAZARD-READ-AFTER-WRITE(ERROR / SPEC): msgNum: 1 - Validation Error: [ SYNC-HAZARD-READ-AFTER-WRITE ] | MessageID = 0xe4d96472 | vkQueueSubmit: Hazard READ_AFTER_WRITE for entry 6, VkCommandBuffer 0x55957c57bdf0[], Recorded access info (recorded_usage: SYNC_COMPUTE_SHADER_SHADER_STORAGE_READ, command: vkCmdDispatch, seq_no: 1, reset_no: 1). Access info (prior_usage: SYNC_IMAGE_LAYOUT_TRANSITION, write_barriers: 0, queue: VkQueue 0x55957bfc2b98[], submit: 0, batch: 0, batch_tag: 18, command: vkCmdPipelineBarrier, seq_no: 1, command_buffer: VkCommandBuffer 0x55957c579050[], reset_no: 1).";
    assert_eq!(
        parse_layer(submitted),
        Some((
            "vkCmdDispatch".to_owned(),
            "READ_AFTER_WRITE".to_owned(),
            "SYNC_COMPUTE_SHADER_SHADER_STORAGE_READ".to_owned(),
            "SYNC_IMAGE_LAYOUT_TRANSITION".to_owned(),
            "vkCmdPipelineBarrier".to_owned(),
        ))
    );
    // Qt Quick's depth attachment: a load against the begin's own layout transition.
    let transition = "SYNC-HAZARD-WRITE-AFTER-WRITE(ERROR / SPEC): msgNum: 1544472022 - Validation Error: [ SYNC-HAZARD-WRITE-AFTER-WRITE ] Object 0: handle = 0x460000000046, type = VK_OBJECT_TYPE_RENDER_PASS; | MessageID = 0x5c0ec5d6 | vkCmdBeginRenderPass: Hazard WRITE_AFTER_WRITE vs. layout transition in subpass 0 for attachment 1 aspect depth during load with loadOp VK_ATTACHMENT_LOAD_OP_CLEAR.";
    assert_eq!(
        parse_layer(transition),
        Some((
            "vkCmdBeginRenderPass".to_owned(),
            "WRITE_AFTER_WRITE".to_owned(),
            "SYNC_EARLY_FRAGMENT_TESTS_DEPTH_STENCIL_ATTACHMENT_WRITE".to_owned(),
            "SYNC_IMAGE_LAYOUT_TRANSITION".to_owned(),
            "vkCmdBeginRenderPass".to_owned(),
        ))
    );
    assert_eq!(
        usage("COLOR_ATTACHMENT_OUTPUT/COLOR_ATTACHMENT_READ (load op LOAD)"),
        "SYNC_COLOR_ATTACHMENT_OUTPUT_COLOR_ATTACHMENT_READ"
    );
}

/// A barrier removed or weakened in a real stream (`framelab edit`), and what it breaks: the
/// finding framelab must add at the command (by its index in the stream), and the one the
/// layer adds there when it is another.
struct Planted {
    file: &'static str,
    source: &'static str,
    edits: &'static [&'static str],
    command: &'static str,
    kind: &'static str,
    layer_kind: Option<&'static str>,
}

const PLANTED: [Planted; 6] = [
    // Read after write: the copy's write is not made visible to the compute shader's read.
    Planted {
        file: "raw_mpv_testsrc_f5",
        source: "mpv_testsrc_f5",
        edits: &["201:pBufferMemoryBarriers[0].dstAccessMask=0"],
        command: "vkCmdDispatch #205",
        kind: "READ_AFTER_WRITE",
        layer_kind: None,
    },
    // Write after read: the barrier between two dispatches no longer waits for the compute
    // stage, so the second dispatch's write of `a` is unordered with the first's read. The
    // layer (1.3.239, checking across command buffers at submission) reports the same write
    // against the earlier layout transition of `a` instead: it carries no read of another
    // command buffer into the submission's state. Both are unordered with the write by the
    // specification's rule (an execution dependency must order each earlier access before
    // a write); framelab names the read, the access the write must wait for last.
    Planted {
        file: "war_write_after_read",
        source: "write_after_read",
        edits: &[
            "197:srcStageMask=4096",
            "197:pImageMemoryBarriers[0].srcAccessMask=0",
        ],
        command: "vkCmdDispatch #180",
        kind: "WRITE_AFTER_READ",
        layer_kind: Some("WRITE_AFTER_WRITE"),
    },
    // Write after write: the transition to PRESENT_SRC no longer makes the render pass's
    // store available.
    Planted {
        file: "waw_vkd3d_gears_f2",
        source: "vkd3d_gears_f2",
        edits: &["176:pImageMemoryBarriers[0].srcAccessMask=0"],
        command: "vkCmdPipelineBarrier #176",
        kind: "WRITE_AFTER_WRITE",
        layer_kind: None,
    },
    // A wrong old layout: the swapchain image is in PRESENT_SRC_KHR, the barrier says GENERAL.
    Planted {
        file: "old_layout_vkd3d_gears_f2",
        source: "vkd3d_gears_f2",
        edits: &["154:pImageMemoryBarriers[0].oldLayout=VK_IMAGE_LAYOUT_GENERAL"],
        command: "vkCmdPipelineBarrier #154",
        kind: "LAYOUT_MISMATCH",
        layer_kind: None,
    },
    // A missing layout transition: the barrier keeps PRESENT_SRC_KHR, and the render pass
    // expects COLOR_ATTACHMENT_OPTIMAL.
    Planted {
        file: "no_transition_vkd3d_gears_f2",
        source: "vkd3d_gears_f2",
        edits: &["154:pImageMemoryBarriers[0].newLayout=VK_IMAGE_LAYOUT_PRESENT_SRC_KHR"],
        command: "vkCmdBeginRenderPass #156",
        kind: "LAYOUT_MISMATCH",
        layer_kind: None,
    },
    // A missing layout transition before sampling: mpv's storage image stays in GENERAL,
    // and the draw's descriptor says SHADER_READ_ONLY_OPTIMAL.
    Planted {
        file: "descriptor_layout_mpv_testsrc_f5",
        source: "mpv_testsrc_f5",
        edits: &["228:pImageMemoryBarriers[0].newLayout=VK_IMAGE_LAYOUT_GENERAL"],
        command: "vkCmdDraw #237",
        kind: "LAYOUT_MISMATCH",
        layer_kind: None,
    },
];

/// framelab's findings as imported, with the command's index kept.
fn commands_found(capture: &Path) -> BTreeSet<(String, String)> {
    let c: Value = serde_json::from_str(&std::fs::read_to_string(capture).unwrap()).unwrap();
    c["source"]["sync_hazards"]
        .as_array()
        .unwrap()
        .iter()
        .map(|h| {
            (
                h["command"].as_str().unwrap().to_owned(),
                h["kind"].as_str().unwrap().to_owned(),
            )
        })
        .collect()
}

#[test]
fn planted_hazards_are_flagged_by_framelab_and_the_layer_at_the_same_command() {
    let dir = temp("planted");
    let display = start_display();
    for p in PLANTED {
        let planted = repo().join(format!("tests/fixtures/gfxr/planted/{}.gfxr", p.file));
        let source = gfxr_fixture(&format!("{}.gfxr", p.source));
        // The fixture is the source with exactly these edits.
        let remade = dir.join(format!("{}.gfxr", p.file));
        let mut args = vec![
            "edit".to_owned(),
            source.display().to_string(),
            "-o".to_owned(),
            remade.display().to_string(),
        ];
        for e in p.edits {
            args.extend(["--set".to_owned(), (*e).to_owned()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let run = framelab(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        assert!(
            std::fs::read(&remade).unwrap() == std::fs::read(&planted).unwrap(),
            "{}: the fixture is not {} with its edits",
            p.file,
            p.source
        );

        let (before, after) = (dir.join("before.json"), dir.join("after.json"));
        import(&source, &before);
        import(&planted, &after);
        let added: Vec<(String, String)> = commands_found(&after)
            .difference(&commands_found(&before))
            .cloned()
            .collect();
        assert_eq!(
            added,
            [(p.command.to_owned(), p.kind.to_owned())],
            "{}: framelab's new findings",
            p.file
        );
        let ours: BTreeSet<Finding> = framelab_findings(&after)
            .0
            .difference(&framelab_findings(&before).0)
            .cloned()
            .collect();
        let layer: BTreeSet<Finding> = layer_findings(&planted, &display, &dir)
            .difference(&layer_findings(&source, &display, &dir))
            .cloned()
            .collect();
        match p.layer_kind {
            None => assert_eq!(
                ours, layer,
                "{}: framelab (left) and the layer (right)",
                p.file
            ),
            Some(kind) => {
                let found: Vec<(&str, &str)> =
                    layer.iter().map(|f| (f.0.as_str(), f.1.as_str())).collect();
                assert_eq!(found, [(call(p.command).as_str(), kind)], "{}", p.file);
            }
        }
    }
}

/// The layer's messages of the valid-usage classes framelab checks from the calls:
/// (call, VUID, the attachment named).
fn layer_vuids(
    capture: &Path,
    display: &Display,
    dir: &Path,
) -> BTreeSet<(String, String, String)> {
    vuids_in_log(&replay_under_layer(
        capture,
        display,
        dir,
        "vuid_log.txt",
        &[],
    ))
}

/// A command of an extension neither the instance nor the device enabled: the specification's
/// rule has no VUID, so framelab takes the layer's id.
const EXTENSION_NOT_ENABLED: &str = "UNASSIGNED-GeneralParameterError-ExtensionNotEnabled";

/// gfxrecon-replay restores a trimmed capture's depth/stencil contents with a fragment shader
/// of its own that writes `FragStencilRefEXT` as a float, which the layer rejects at its
/// `vkCreateShaderModule`: a message about that built-in is the replay's own where no module
/// of the capture (as framelab imported them) declares it.
fn replays_own_stencil_shader(v: &(String, String, String), capture: &Path) -> bool {
    const FRAG_STENCIL_REF: u32 = 5014;
    if v.1 != INVALID_SPIRV || !v.2.contains("FragStencilRefEXT") {
        return false;
    }
    let stem = capture.file_stem().unwrap().to_string_lossy();
    let shaders = capture.with_file_name(format!("{stem}.shaders"));
    let declares = std::fs::read_dir(&shaders).into_iter().flatten().any(|e| {
        let bytes = std::fs::read(e.unwrap().path()).unwrap();
        let words: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        // OpDecorate %x BuiltIn FragStencilRefEXT: 4 words, opcode 71, decoration 11.
        words
            .windows(4)
            .any(|w| w[0] == (4 << 16 | 71) && w[2] == 11 && w[3] == FRAG_STENCIL_REF)
    });
    !declares
}

/// Shader code that SPIRV-Tools' validator rejects (`VkShaderModuleCreateInfo::pCode` must be
/// valid SPIR-V): the layer's id in its version here; its message quotes the validator's.
const INVALID_SPIRV: &str = "UNASSIGNED-CoreValidation-Shader-InconsistentSpirv";

/// The VUIDs of the classes framelab checks from the calls (`import/valid_usage.rs`,
/// `import/valid_usage_buffers.rs`, `import/valid_usage_sets.rs`): load operations from
/// `UNDEFINED`, descriptors, layout transitions, attachments and transfers against image
/// usage, each use of a buffer against its usage, the sets a draw's pipeline uses bound, and
/// what it filters linearly against what the device can.
fn checked_class(vuid: &str) -> bool {
    vuid.starts_with("VUID-VkAttachmentDescription")
        || vuid == "VUID-VkClearDepthStencilValue-depth-02506"
        || vuid == EXTENSION_NOT_ENABLED
        || vuid == INVALID_SPIRV
        // A draw or dispatch whose pipeline uses a set not bound through a compatible layout.
        || vuid.ends_with("-None-02697")
        // A dynamic state set that the draw's pipeline does not declare dynamic.
        || vuid.ends_with("-None-02859")
        || vuid == "VUID-VkImageCreateInfo-usage-00963"
        || vuid == "VUID-VkDeviceCreateInfo-pNext-00373"
        // A statically used descriptor that is not valid: null without the feature, or its
        // image in another layout.
        || vuid.ends_with("-None-02699")
        // A count the registry requires non-zero.
        || vuid.ends_with("-arraylength")
        || vuid.ends_with("-newLayout-01198")
        || vuid.ends_with("-bufferRowLength-00195")
        || vuid.ends_with("-bufferImageHeight-00196")
        || vuid.ends_with("-pRegions-00171")
        || vuid.ends_with("-pRegions-00183")
        // A linear sampler over a view the device cannot filter linearly.
        || vuid.ends_with("-magFilter-04553")
        || [
            "VUID-vkCmdBindVertexBuffers-pBuffers-00627",
            "VUID-vkCmdBindVertexBuffers2-pBuffers-03359",
            "VUID-vkCmdBindIndexBuffer-buffer-00433",
            "VUID-vkCmdDrawIndirect-buffer-02709",
            "VUID-vkCmdDrawIndexedIndirect-buffer-02709",
            "VUID-vkCmdDispatchIndirect-buffer-02709",
            "VUID-vkCmdDrawIndirectCount-buffer-02709",
            "VUID-vkCmdDrawIndirectCount-countBuffer-02715",
            "VUID-vkCmdDrawIndexedIndirectCount-buffer-02709",
            "VUID-vkCmdDrawIndexedIndirectCount-countBuffer-02715",
            "VUID-vkCmdCopyBuffer-srcBuffer-00118",
            "VUID-vkCmdCopyBuffer-dstBuffer-00120",
            "VUID-vkCmdCopyBufferToImage-srcBuffer-00174",
            "VUID-vkCmdCopyImageToBuffer-dstBuffer-00191",
            "VUID-vkCmdFillBuffer-dstBuffer-00029",
            "VUID-vkCmdUpdateBuffer-dstBuffer-00034",
            "VUID-VkBufferViewCreateInfo-buffer-00932",
        ]
        .contains(&vuid)
        || vuid.starts_with("VUID-VkWriteDescriptorSet-descriptorType-0033")
        || vuid.starts_with("VUID-vkCmdBeginRenderPass-initialLayout-0089")
        || [
            "VUID-vkCmdBeginRenderPass-initialLayout-01758",
            "VUID-vkCmdBeginRenderPass2-initialLayout-03094",
            "VUID-vkCmdBeginRenderPass2-initialLayout-03096",
            "VUID-vkCmdBeginRenderPass2-initialLayout-03097",
            "VUID-vkCmdBeginRenderPass2-initialLayout-03098",
            "VUID-vkCmdBeginRenderPass2-initialLayout-03099",
            "VUID-vkCmdBeginRenderPass2-initialLayout-03100",
        ]
        .contains(&vuid)
        || [
            "VUID-VkFramebufferCreateInfo-pAttachments-00877",
            "VUID-VkFramebufferCreateInfo-pAttachments-00879",
            "VUID-VkFramebufferCreateInfo-pAttachments-02633",
        ]
        .contains(&vuid)
        || [
            "VUID-vkCmdCopyImage-srcImage-00126",
            "VUID-vkCmdCopyImage-dstImage-00131",
            "VUID-vkCmdBlitImage-srcImage-00219",
            "VUID-vkCmdBlitImage-dstImage-00224",
            "VUID-vkCmdCopyBufferToImage-dstImage-00177",
            "VUID-vkCmdCopyImageToBuffer-srcImage-00186",
            "VUID-vkCmdClearColorImage-image-00002",
        ]
        .contains(&vuid)
        || [
            "01208", "01209", "01210", "01211", "01212", "01213", "01658", "01659",
        ]
        .iter()
        .any(|n| {
            vuid == format!("VUID-VkImageMemoryBarrier-oldLayout-{n}")
                || vuid == format!("VUID-VkImageMemoryBarrier2-oldLayout-{n}")
        })
}

/// The valid-usage messages of the classes framelab checks in a layer's log, as (call, VUID,
/// the member named: `pAttachments[0]`, `pDescriptorWrites[0]`,
/// `pImageMemoryBarriers[0].newLayout`).
fn vuids_in_log(log: &Path) -> BTreeSet<(String, String, String)> {
    let text = std::fs::read_to_string(log).expect("the validation layer wrote no log");
    text.lines()
        .map(undefined_array_length)
        .filter(|l| {
            l.starts_with("VUID-")
                || l.starts_with(EXTENSION_NOT_ENABLED)
                || l.starts_with(INVALID_SPIRV)
        })
        .filter_map(|l| {
            let vuid = l.split('(').next().unwrap_or("").to_owned();
            if !checked_class(&vuid) {
                return None;
            }
            // The layer names a render pass's attachment as `attachment N`.
            let said = l.rsplit_once("| ").map_or("", |(_, s)| s);
            if let Some(rest) = vuid.strip_prefix("VUID-vkCmdBeginRenderPass") {
                let call = format!(
                    "vkCmdBeginRenderPass{}",
                    rest.split('-').next().unwrap_or("")
                );
                let n = said
                    .split_once("for attachment ")
                    .map_or("", |(_, rest)| rest.split(' ').next().unwrap_or(""));
                return Some((call, vuid, format!("pAttachments[{n}]")));
            }
            // `Attempted to call vkCmdBeginDebugUtilsLabelEXT() but its required extension
            // VK_EXT_debug_utils has not been enabled`.
            if vuid == EXTENSION_NOT_ENABLED {
                let call = said
                    .split_once("call ")
                    .and_then(|(_, rest)| rest.split('(').next())
                    .unwrap_or("")
                    .to_owned();
                return Some((call, vuid, String::new()));
            }
            // A count the registry requires non-zero: the command and the count, in the id.
            if let Some(rest) = vuid.strip_suffix("-arraylength") {
                let mut parts = rest.trim_start_matches("VUID-").split('-');
                let call = parts.next().unwrap_or("").to_owned();
                let member = parts.next().unwrap_or("").to_owned();
                return Some((call, vuid, member));
            }
            // The layer words the device's create info without its call.
            if vuid == "VUID-VkDeviceCreateInfo-pNext-00373" {
                return Some(("vkCreateDevice".to_owned(), vuid, String::new()));
            }
            // The layer does not name the module's call; both quote the validator.
            if vuid == INVALID_SPIRV {
                return Some(("vkCreateShaderModule".to_owned(), vuid, said.to_owned()));
            }
            // A command's own rule names the command and the argument; its message may not.
            if let Some(rest) = vuid.strip_prefix("VUID-vkCmd") {
                let mut parts = rest.split('-');
                let call = format!("vkCmd{}", parts.next().unwrap_or(""));
                let member = parts.next().unwrap_or("").to_owned();
                return Some((call, vuid, member));
            }
            let said = l.rsplit_once("| ").map_or("", |(_, s)| s);
            // The layer names a framebuffer's attachment as `Attachment (N)`.
            if vuid.starts_with("VUID-VkFramebufferCreateInfo") {
                let n = said
                    .split_once("Attachment (")
                    .and_then(|(_, rest)| rest.split_once(')'))
                    .map_or("", |(n, _)| n);
                return Some((
                    "vkCreateFramebuffer".to_owned(),
                    vuid,
                    format!("pAttachments[{n}]"),
                ));
            }
            let mut call = said.split(['(', ':', ' ']).next().unwrap_or("").to_owned();
            // A push through a template is named without `Cmd`, its writes as
            // `VkWriteDescriptorSet[N]`.
            if call == "vkPushDescriptorSetWithTemplateKHR" {
                call = "vkCmdPushDescriptorSetWithTemplateKHR".to_owned();
            }
            // A copy's region is `pRegion[N]` in the layer's words.
            let said = said
                .replace("VkWriteDescriptorSet[", "pDescriptorWrites[")
                .replace("pRegion[", "pRegions[");
            let member = said
                .split_whitespace()
                .map(|w| {
                    w.trim_start_matches("pCreateInfo->")
                        .trim_start_matches('.')
                })
                .find(|w| w.starts_with('p') && w.contains('['))
                .unwrap_or("")
                .to_owned();
            Some((call, vuid, member))
        })
        .collect()
}

/// The layer's `arraylength` rules its version lacks an id for come as `VUID_Undefined`
/// (`vkCmdSetColorBlendEnableEXT: parameter attachmentCount must be greater than 0.`): the
/// line with the specification's id, `VUID-<command>-<count>-arraylength`, in its place.
fn undefined_array_length(line: &str) -> std::borrow::Cow<'_, str> {
    let said = line.rsplit_once("| ").map_or("", |(_, s)| s);
    let parsed = line
        .starts_with("VUID_Undefined")
        .then(|| said.split_once(": parameter "))
        .flatten()
        .and_then(|(call, rest)| Some((call, rest.strip_suffix(" must be greater than 0.")?)));
    match parsed {
        Some((call, count)) => format!("VUID-{call}-{count}-arraylength(ERROR) | {said}").into(),
        None => line.into(),
    }
}

/// framelab's valid-usage findings on an imported capture, in the layer's terms.
fn framelab_vuids(capture: &Path) -> BTreeSet<(String, String, String)> {
    let c: Value = serde_json::from_str(&std::fs::read_to_string(capture).unwrap()).unwrap();
    c["source"]["valid_usage"]
        .as_array()
        .expect("the import checked the calls")
        .iter()
        .map(|f| {
            let s = |k: &str| f[k].as_str().unwrap().to_owned();
            // The layer does not say which clear value is out of range.
            let attachment = if s("vuid") == INVALID_SPIRV {
                s("detail")
            } else if s("vuid").starts_with("VUID-VkImageCreateInfo") {
                // The layer names the usage without a member path.
                String::new()
            } else if let Some(rest) = s("vuid")
                .strip_prefix("VUID-")
                .filter(|v| v.starts_with("vkCmd") || v.ends_with("-arraylength"))
                .filter(|v| !v.starts_with("vkCmdBeginRenderPass"))
            {
                // A command's own rule: the layer is read by the member its id names
                // (`None` for a draw's state).
                rest.split('-').nth(1).unwrap_or("").to_owned()
            } else if s("vuid").starts_with("VUID-VkClearDepthStencilValue")
                || s("vuid").starts_with("VUID-VkDeviceCreateInfo")
                || s("vuid") == EXTENSION_NOT_ENABLED
            {
                String::new()
            } else {
                s("detail")
                    .split_whitespace()
                    .next()
                    .unwrap_or("")
                    .trim_end_matches(':')
                    .to_owned()
            };
            (call(&s("command")), s("vuid"), attachment)
        })
        .collect()
}

/// Valid-usage findings as (call, VUID, the member named).
type Vuids = BTreeSet<(String, String, String)>;

/// A real stream (`fixture`) with one number set by `framelab edit` (`set`): framelab's
/// valid-usage findings on its import, and the layer's messages of the classes framelab checks
/// on it that the original stream does not give. framelab finds nothing on the original.
fn planted_vuids(name: &str, fixture: &str, set: &str) -> (Vuids, Vuids) {
    let dir = temp(name);
    let display = start_display();
    let source = gfxr_fixture(fixture);
    let planted = dir.join("planted.gfxr");
    let run = framelab(&[
        "edit",
        source.to_str().unwrap(),
        "-o",
        planted.to_str().unwrap(),
        "--set",
        set,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let (before, after) = (dir.join("before.json"), dir.join("after.json"));
    import(&source, &before);
    import(&planted, &after);
    assert!(framelab_vuids(&before).is_empty());
    let layer = layer_vuids(&planted, &display, &dir)
        .difference(&layer_vuids(&source, &display, &dir))
        .cloned()
        .collect();
    (framelab_vuids(&after), layer)
}

/// A render pass made to load its colour attachment from `UNDEFINED` (vkcube's, its `loadOp`
/// set to LOAD with `framelab edit`, a fresh stream made by the test): framelab and the layer
/// both report VUID-VkAttachmentDescription-format-06699 at vkCreateRenderPass, for that
/// attachment, and nothing else new; on vkcube as it was framelab reports nothing. (On
/// trimmed captures the layer also reports gfxrecon-replay's own render passes, which it makes
/// to restore depth contents; the difference leaves them out.)
#[test]
fn planted_valid_usage_errors_are_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-vuid",
        "vkcube_f3.gfxr",
        "64:pCreateInfo.pAttachments[0].loadOp=0",
    );
    let expected = (
        "vkCreateRenderPass".to_owned(),
        "VUID-VkAttachmentDescription-format-06699".to_owned(),
        "pAttachments[0]".to_owned(),
    );
    assert_eq!(ours, BTreeSet::from([expected]));
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube's texture (the whole capture, which records its setup) created without `VK_IMAGE_USAGE_SAMPLED_BIT` (its usage set to
/// `COLOR_ATTACHMENT` with `framelab edit`): framelab and the layer both report the combined
/// image sampler descriptors written of it (`VUID-VkWriteDescriptorSet-descriptorType-00337`,
/// one per swapchain image's set) and its transition from `PREINITIALIZED` to
/// `SHADER_READ_ONLY_OPTIMAL` (`VUID-VkImageMemoryBarrier-oldLayout-01211`), at the same calls
/// and members. (On a trimmed capture the transition is gfxrecon-replay's own, restoring the
/// image's layout, and the stream holds no barrier.)
#[test]
fn image_usage_against_its_use_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-usage",
        "vkcube_whole.gfxr",
        "50:pCreateInfo.usage=16",
    );
    let vuids: BTreeSet<&str> = ours.iter().map(|(_, v, _)| v.as_str()).collect();
    assert_eq!(
        vuids,
        BTreeSet::from([
            "VUID-VkImageMemoryBarrier-oldLayout-01211",
            "VUID-VkWriteDescriptorSet-descriptorType-00337"
        ])
    );
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube's depth image made transient and sampled too (usage `TRANSIENT_ATTACHMENT |
/// DEPTH_STENCIL_ATTACHMENT | SAMPLED` with `framelab edit`, as vkBasalt makes Qt's): framelab
/// and the layer both report its creation (`VUID-VkImageCreateInfo-usage-00963`).
#[test]
fn a_transient_image_with_other_uses_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-transient",
        "vkcube_whole.gfxr",
        "44:pCreateInfo.usage=100",
    );
    let expected = (
        "vkCreateImage".to_owned(),
        "VUID-VkImageCreateInfo-usage-00963".to_owned(),
        String::new(),
    );
    assert_eq!(ours, BTreeSet::from([expected]));
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube `--use_staging`'s texture created without `VK_IMAGE_USAGE_TRANSFER_DST_BIT` (usage
/// `SAMPLED` only): framelab and the layer both report the copy into it
/// (`VUID-vkCmdCopyBufferToImage-dstImage-00177`) and both transitions through
/// `TRANSFER_DST_OPTIMAL` (`VUID-VkImageMemoryBarrier-oldLayout-01213`, its new layout at the
/// first barrier, its old one at the second).
#[test]
fn a_copy_into_an_image_without_transfer_usage_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-transfer",
        "vkcube_staging.gfxr",
        "57:pCreateInfo.usage=4",
    );
    let barrier = |member: &str| {
        (
            "vkCmdPipelineBarrier".to_owned(),
            "VUID-VkImageMemoryBarrier-oldLayout-01213".to_owned(),
            format!("pImageMemoryBarriers[0].{member}"),
        )
    };
    let expected = BTreeSet::from([
        barrier("newLayout"),
        barrier("oldLayout"),
        (
            "vkCmdCopyBufferToImage".to_owned(),
            "VUID-vkCmdCopyBufferToImage-dstImage-00177".to_owned(),
            "dstImage".to_owned(),
        ),
    ]);
    assert_eq!(ours, expected);
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube's depth image created without `VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT` (usage
/// `SAMPLED`, the whole capture, which makes its framebuffers): framelab and the layer both
/// report each framebuffer made of it (`VUID-VkFramebufferCreateInfo-pAttachments-02633`,
/// attachment 1), and each render pass begun on them, which puts that attachment in
/// `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` (`VUID-vkCmdBeginRenderPass-initialLayout-00896`).
#[test]
fn an_attachment_without_attachment_usage_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-framebuffer",
        "vkcube_whole.gfxr",
        "44:pCreateInfo.usage=4",
    );
    let expected = BTreeSet::from([
        (
            "vkCreateFramebuffer".to_owned(),
            "VUID-VkFramebufferCreateInfo-pAttachments-02633".to_owned(),
            "pAttachments[1]".to_owned(),
        ),
        (
            "vkCmdBeginRenderPass".to_owned(),
            "VUID-vkCmdBeginRenderPass-initialLayout-00896".to_owned(),
            "pAttachments[1]".to_owned(),
        ),
    ]);
    assert_eq!(ours, expected);
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube's first uniform buffer (the whole capture, which writes its descriptors) created
/// without `VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT` (usage `TRANSFER_SRC`): framelab and the layer
/// both report the uniform-buffer descriptor written of it
/// (`VUID-VkWriteDescriptorSet-descriptorType-00330`) at the same call, and nothing else new.
#[test]
fn a_uniform_buffer_without_uniform_usage_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-uniform",
        "vkcube_whole.gfxr",
        "61:pCreateInfo.usage=1",
    );
    let expected = BTreeSet::from([(
        "vkUpdateDescriptorSets".to_owned(),
        "VUID-VkWriteDescriptorSet-descriptorType-00330".to_owned(),
        "pDescriptorWrites[0]".to_owned(),
    )]);
    assert_eq!(ours, expected);
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube `--use_staging`'s staging buffer created without `VK_BUFFER_USAGE_TRANSFER_SRC_BIT`
/// (usage `UNIFORM_BUFFER`): framelab and the layer both report the copy out of it into the
/// texture (`VUID-vkCmdCopyBufferToImage-srcBuffer-00174`).
#[test]
fn a_copy_from_a_buffer_without_transfer_usage_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-staging",
        "vkcube_staging.gfxr",
        "50:pCreateInfo.usage=16",
    );
    let expected = BTreeSet::from([(
        "vkCmdCopyBufferToImage".to_owned(),
        "VUID-vkCmdCopyBufferToImage-srcBuffer-00174".to_owned(),
        "srcBuffer".to_owned(),
    )]);
    assert_eq!(ours, expected);
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// Replays `capture` with `gfxrecon-replay` under the Khronos validation layer with `enables`,
/// which must succeed; the layer's log.
fn replay_under_layer(
    capture: &Path,
    display: &Display,
    dir: &Path,
    log: &str,
    enables: &[&str],
) -> std::path::PathBuf {
    let log = crate::common::layer_settings(dir, log, enables);
    let out = Command::new("timeout")
        .args(["300", "gfxrecon-replay"])
        .args(wsi(capture))
        .arg("--use-captured-swapchain-indices")
        .arg(capture)
        .env("DISPLAY", &display.name)
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
        .env("VK_LAYER_SETTINGS_PATH", dir)
        .output()
        .expect("gfxrecon-replay (apt-get install gfxreconstruct)");
    assert!(
        out.status.success(),
        "{}: gfxrecon-replay failed: {}",
        capture.display(),
        String::from_utf8_lossy(&out.stdout)
    );
    std::fs::write(dir.join("replay_output.txt"), &out.stdout).unwrap();
    log
}

/// The functions gfxrecon-replay did not call in its last run in `dir` (`Unsupported
/// function vkSetDebugUtilsObjectNameEXT was called, resulting in no-op behavior`: an
/// extension the stream never enabled), which the layer therefore never sees.
fn not_replayed(dir: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(dir.join("replay_output.txt")).unwrap_or_default();
    text.lines()
        .filter_map(|l| l.split_once("Unsupported function ")?.1.split(' ').next())
        .map(str::to_owned)
        .collect()
}

/// vkcube's depth clear value set to 2 (its bits written into the clear value's words with
/// `framelab edit`): framelab and the layer both report
/// `VUID-VkClearDepthStencilValue-depth-02506` at the vkCmdBeginRenderPass that clears with
/// it, and the replay clears to 1, said in the import's notes.
#[test]
fn a_depth_clear_value_out_of_range_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-clear",
        "vkcube_f3.gfxr",
        "91:pRenderPassBegin.pClearValues[1].color.uint32[0]=1073741824",
    );
    let expected = BTreeSet::from([(
        "vkCmdBeginRenderPass".to_owned(),
        "VUID-VkClearDepthStencilValue-depth-02506".to_owned(),
        String::new(),
    )]);
    assert_eq!(ours, expected);
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// The update-template program's uniform buffer created with storage usage only (`framelab
/// edit`): framelab and the layer both report the template's uniform buffer entry
/// (`VUID-VkWriteDescriptorSet-descriptorType-00330`, the third entry taken as the write
/// `pDescriptorWrites[2]`) at the set updated through the template and at the push through
/// the push template.
#[test]
fn descriptors_written_through_templates_are_checked_like_writes() {
    let (ours, layer) = planted_vuids(
        "planted-template",
        "template_compute.gfxr",
        "28:pCreateInfo.usage=32",
    );
    let at = |call: &str| {
        (
            call.to_owned(),
            "VUID-VkWriteDescriptorSet-descriptorType-00330".to_owned(),
            "pDescriptorWrites[2]".to_owned(),
        )
    };
    let expected = BTreeSet::from([
        at("vkUpdateDescriptorSetWithTemplate"),
        at("vkCmdPushDescriptorSetWithTemplateKHR"),
    ]);
    assert_eq!(ours, expected);
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube's fragment shader (`vkCreateShaderModule` at block 72) with its `OpSource` language
/// set to 99, a value no SPIR-V grammar has (word 28 of its code, with `framelab edit`):
/// framelab (SPIRV-Tools' validator, with the device's options) and the layer both reject the
/// module with the validator's message, and nothing else new. The module still replays: the
/// language is debug information drivers ignore.
#[test]
fn invalid_spirv_is_flagged_by_framelab_and_the_layer() {
    let (ours, layer) = planted_vuids(
        "planted-spirv",
        "vkcube_f3.gfxr",
        "72:pCreateInfo.pCode[28]=99",
    );
    let expected = BTreeSet::from([(
        "vkCreateShaderModule".to_owned(),
        INVALID_SPIRV.to_owned(),
        "SPIR-V module not valid: Invalid source language operand: 99".to_owned(),
    )]);
    assert_eq!(ours, expected);
    assert_eq!(ours, layer, "framelab (left) and the layer (right)");
}

/// vkcube `--use_staging` edited one number at a time with `framelab edit`: the copy of the
/// logo given a `bufferImageHeight` below its height (`VUID-VkBufferImageCopy-bufferImageHeight-00196`)
/// or a `bufferOffset` that runs its last row past the staging buffer
/// (`VUID-vkCmdCopyBufferToImage-pRegions-00171`), the barrier after it transitioning to
/// `UNDEFINED` (`VUID-VkImageMemoryBarrier-newLayout-01198`), and a viewport set with a count
/// of zero (`VUID-vkCmdSetViewport-viewportCount-arraylength`): framelab and the layer report
/// each at the same call and member, and nothing else of the classes framelab checks.
#[test]
fn copy_regions_barrier_layouts_and_counts_are_flagged_by_framelab_and_the_layer() {
    let one = |call: &str, vuid: &str, member: &str| {
        BTreeSet::from([(call.to_owned(), vuid.to_owned(), member.to_owned())])
    };
    let plants = [
        (
            "planted-image-height",
            "62:pRegions[0].bufferImageHeight=255",
            one(
                "vkCmdCopyBufferToImage",
                "VUID-VkBufferImageCopy-bufferImageHeight-00196",
                "pRegions[0]",
            ),
        ),
        (
            "planted-buffer-end",
            "62:pRegions[0].bufferOffset=4",
            one(
                "vkCmdCopyBufferToImage",
                "VUID-vkCmdCopyBufferToImage-pRegions-00171",
                "pRegions",
            ),
        ),
        (
            "planted-to-undefined",
            "63:pImageMemoryBarriers[0].newLayout=0",
            one(
                "vkCmdPipelineBarrier",
                "VUID-VkImageMemoryBarrier-newLayout-01198",
                "pImageMemoryBarriers[0].newLayout",
            ),
        ),
        (
            "planted-no-viewports",
            "107:viewportCount=0",
            one(
                "vkCmdSetViewport",
                "VUID-vkCmdSetViewport-viewportCount-arraylength",
                "viewportCount",
            ),
        ),
    ];
    for (name, set, expected) in plants {
        let (ours, layer) = planted_vuids(name, "vkcube_staging.gfxr", set);
        assert_eq!(ours, expected, "{set}: framelab");
        assert_eq!(ours, layer, "{set}: framelab (left) and the layer (right)");
    }
}
