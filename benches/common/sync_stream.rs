//! The long real command stream two benchmarks share: a synthetic frame of 1,440 compute
//! and copy passes replayed by `framelab replay` under GFXReconstruct's capture layer, made
//! once in Cargo's target folder; and the capturing itself, which the import scale benchmark
//! uses for its own frames.

use std::path::{Path, PathBuf};
use std::process::Command;

const PASSES: usize = 1440;
const BUFFERS: usize = 32;

/// The synthetic frame: two passes in three a compute pass reading and writing two buffers,
/// the third a copy between two; the buffers drawn by a fixed linear congruential sequence.
fn frame_json() -> String {
    let mut x: u64 = 12345;
    let mut below = |n: u64| {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (x >> 33) % n
    };
    let resources: Vec<String> = (0..BUFFERS)
        .map(|i| {
            format!(
                r#"{{"name":"buf{i}","kind":"buffer","buffer_kind":"structured","stride":16,"size":1024,"flags":["ALLOW_UNORDERED_ACCESS"]}}"#
            )
        })
        .collect();
    let passes: Vec<String> = (0..PASSES)
        .map(|p| {
            let a = below(BUFFERS as u64);
            let mut b = below(BUFFERS as u64);
            if b == a {
                b = (a + 1) % BUFFERS as u64;
            }
            if p % 3 == 2 {
                format!(
                    r#"{{"name":"copy{p}","queue":"gfx","kind":"copy","copies":[{{"src":{{"resource":"buf{a}","size":256}},"dst":{{"resource":"buf{b}","size":256}}}}]}}"#
                )
            } else {
                format!(
                    r#"{{"name":"pass{p}","queue":"gfx","kind":"compute","shader":{{"file":"compute.wgsl","compute":"cs_main"}},"bindings":{{"particles":{{"resource":"buf{a}","access":"storage_read_write"}},"draw_args":{{"resource":"buf{b}","access":"storage_read_write"}}}},"dispatches":[{{"groups":[1,1,1]}}]}}"#
                )
            }
        })
        .collect();
    format!(
        r#"{{"format_version":1,"name":"sync_bench","resolution":{{"width":64,"height":64}},"camera":{{"position":[0,2,-10],"target":[0,0,0],"fov_y_degrees":60}},"queues":[{{"name":"gfx","type":"graphics"}}],"resources":[{}],"passes":[{}]}}"#,
        resources.join(","),
        passes.join(",")
    )
}

/// The captured stream, made on first use.
pub fn stream() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sync-bench");
    capture_frame(&dir, "sync_bench", &frame_json)
}

/// `dir/name.gfxr`: the framelab frame `json` makes, replayed once by `framelab replay` under
/// GFXReconstruct's capture layer, made on first use (with the compute shader the frames use).
pub fn capture_frame(dir: &Path, name: &str, json: &dyn Fn() -> String) -> PathBuf {
    let capture = dir.join(format!("{name}.gfxr"));
    if capture.exists() {
        return capture;
    }
    std::fs::create_dir_all(dir).expect("target folder");
    let frame = format!("{name}.json");
    std::fs::write(dir.join(&frame), json()).expect("frame");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/compute.wgsl"),
        dir.join("compute.wgsl"),
    )
    .expect("shader");
    let partial = dir.join(format!("{name}.partial.gfxr"));
    let out = Command::new(env!("CARGO_BIN_EXE_framelab"))
        .args(["replay", &frame, "--frames", "1", "--quiet"])
        .current_dir(dir)
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_LUNARG_gfxreconstruct")
        .env("GFXRECON_CAPTURE_FILE", &partial)
        .env("GFXRECON_CAPTURE_FILE_TIMESTAMP", "false")
        .env("GFXRECON_PAGE_GUARD_ALIGN_BUFFER_SIZES", "true")
        .output()
        .expect("framelab replay");
    assert!(
        out.status.success() && partial.exists(),
        "capturing the frame failed (is gfxreconstruct installed?): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::rename(&partial, &capture).expect("rename");
    capture
}
