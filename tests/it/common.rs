//! Helpers shared by the integration tests: run the `framelab` binary and read its output.

use std::path::PathBuf;
use std::process::Output;

/// A folder made (empty) for a test and removed when the test is done with it, passed or
/// not, so runs do not pile up side files.
pub struct Scratch(PathBuf);

impl Scratch {
    pub fn new(path: PathBuf) -> Scratch {
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).unwrap();
        Scratch(path)
    }

    /// `<name>-<process id>-<n>` in the system's temporary folder: a folder of its own on
    /// every call, so tests running side by side (or one run a case at a time) never remove
    /// each other's files.
    pub fn temp(name: &str) -> Scratch {
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Scratch::new(std::env::temp_dir().join(format!("{name}-{}-{n}", std::process::id())))
    }
}

impl std::ops::Deref for Scratch {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        &self.0
    }
}

impl AsRef<std::path::Path> for Scratch {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A GFXReconstruct capture of a real program under `tests/fixtures/gfxr/`.
pub fn gfxr_fixture(name: &str) -> PathBuf {
    repo().join("tests/fixtures/gfxr").join(name)
}

pub fn framelab(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_framelab"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("run framelab")
}

/// Writes the GFXReconstruct fixture `fixture` to `out` with one number set by `framelab
/// edit` (`set`, as `--set` takes it), which must succeed.
pub fn edited_fixture(fixture: &str, out: &std::path::Path, set: &str) {
    let run = framelab(&[
        "edit",
        gfxr_fixture(fixture).to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        set,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn json(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not JSON ({e}):\n{}\nstderr:\n{}",
            stdout(o),
            stderr(o)
        )
    })
}

/// An EXR file's first RGBA layer: its width and its pixels, row by row.
pub fn exr_image(path: &std::path::Path) -> (usize, Vec<[f32; 4]>) {
    let decoded = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            (
                resolution.width(),
                vec![[0.0f32; 4]; resolution.width() * resolution.height()],
            )
        },
        |(w, pixels): &mut (usize, Vec<[f32; 4]>), position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * *w + position.x()] = [r, g, b, a];
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    decoded.layer_data.channel_data.pixels
}

/// Runs `framelab ARGS` (from the repository) under the Khronos validation layer, logging its
/// errors and warnings to a file in `dir`, and asserts that the command succeeded and the
/// layer said nothing. The layer writes the file when it loads, so an empty file that exists
/// proves it ran and found nothing; a missing layer fails.
pub fn assert_clean_under_validation_layer(dir: &std::path::Path, args: &[&str]) {
    let log = layer_settings(dir, "log.txt", &[]);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_framelab"))
        .args(args)
        .current_dir(repo())
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
        .env("VK_LAYER_SETTINGS_PATH", dir)
        // This test binary is a debug build, whose wgpu instance emits WGSL source debug info in
        // SPIR-V (source language 10), which Debian 12's layer predates and calls invalid;
        // release builds, what users run, emit none. Ask for release behaviour.
        .env("WGPU_DEBUG", "0")
        .output()
        .unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    let messages = std::fs::read_to_string(&log).unwrap_or_else(|e| {
        panic!("{args:?}: the validation layer wrote no log ({e}): is vulkan-validationlayers installed?")
    });
    assert!(messages.is_empty(), "{args:?}:\n{messages}");
}

/// Replays one frame of `capture` into `out`, which must succeed: the export manifest and
/// what the replay said on stderr.
pub fn replay_export(
    capture: &std::path::Path,
    out: &std::path::Path,
) -> (serde_json::Value, String) {
    let run = framelab(&[
        "replay",
        capture.to_str().unwrap(),
        "--frames",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let manifest =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    (manifest, stderr(&run))
}

/// Replays one frame of a real capture into `out`, which must succeed and name the path its
/// shaders took (where it has any: a frame may only clear); the export manifest.
pub fn replay_one_frame(capture: &std::path::Path, out: &std::path::Path) -> serde_json::Value {
    let (manifest, notes) = replay_export(capture, out);
    let frame: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(capture).unwrap()).unwrap();
    let shaders = frame["vulkan"]["shader_modules"]
        .as_array()
        .is_some_and(|m| !m.is_empty());
    assert!(
        !shaders || notes.contains(" path"),
        "{}: the replay names no shader path:\n{notes}",
        capture.display()
    );
    manifest
}

/// Whether `path` is a symbolic link (not what it leads to).
pub fn is_symlink(path: &std::path::Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink())
}

/// Replays one frame of `capture` into `out` and returns the image the frame presented (the
/// manifest entry marked `presented`, which must be exactly one).
pub fn replay_presented(capture: &std::path::Path, out: &std::path::Path) -> image::RgbaImage {
    let m = replay_one_frame(capture, out);
    let presented: Vec<&serde_json::Value> = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["presented"] == serde_json::Value::Bool(true))
        .collect();
    assert_eq!(
        presented.len(),
        1,
        "{}: one presented image",
        capture.display()
    );
    image::open(out.join(presented[0]["file"].as_str().unwrap()))
        .unwrap()
        .to_rgba8()
}

/// Imports each of `captures` into `dir` with `import` and replays two frames of each under
/// the Khronos validation layer, which must say nothing.
pub fn replays_clean_under_validation_layer(
    dir: &std::path::Path,
    captures: &[&str],
    import: impl Fn(&str, &std::path::Path) -> PathBuf,
) {
    for name in captures {
        let capture = import(name, dir);
        assert_clean_under_validation_layer(
            dir,
            &[
                "replay",
                capture.to_str().unwrap(),
                "--frames",
                "2",
                "--quiet",
            ],
        );
    }
}

/// Writes `dir/vk_layer_settings.txt` so that the Khronos validation layer logs its errors and
/// warnings to `dir/<log>` (removed first), with `enables` (`VK_VALIDATION_FEATURE_ENABLE_*`)
/// on; returns the log's path. Point `VK_LAYER_SETTINGS_PATH` at `dir`.
pub fn layer_settings(dir: &std::path::Path, log: &str, enables: &[&str]) -> PathBuf {
    let log = dir.join(log);
    let mut text = format!(
        "khronos_validation.debug_action = VK_DBG_LAYER_ACTION_LOG_MSG\n\
         khronos_validation.log_filename = {}\n\
         khronos_validation.report_flags = error,warn\n",
        log.display()
    );
    if !enables.is_empty() {
        text += &format!("khronos_validation.enables = {}\n", enables.join(","));
    }
    std::fs::write(dir.join("vk_layer_settings.txt"), text).unwrap();
    let _ = std::fs::remove_file(&log);
    log
}

/// Copies the example's shaders into `dir` (created) and returns its capture as JSON, for a
/// test to change and write there as `frame.json`.
pub fn example_copy(dir: &std::path::Path) -> serde_json::Value {
    let example = repo().join("captures/example");
    std::fs::create_dir_all(dir.join("shaders")).unwrap();
    for entry in std::fs::read_dir(example.join("shaders")).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, dir.join("shaders").join(path.file_name().unwrap())).unwrap();
    }
    serde_json::from_str(&std::fs::read_to_string(example.join("frame.json")).unwrap()).unwrap()
}

/// Writes `dir/frame.json`: the example with its pass `name` changed by `change`, its shaders
/// beside it; returns the file.
pub fn example_changed(
    dir: &std::path::Path,
    name: &str,
    change: impl FnOnce(&mut serde_json::Value),
) -> PathBuf {
    let mut capture = example_copy(dir);
    let pass = capture["passes"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("the example has no pass {name}"));
    change(pass);
    let file = dir.join("frame.json");
    std::fs::write(&file, serde_json::to_string_pretty(&capture).unwrap()).unwrap();
    file
}

/// The example with its bloom threshold pass drawing its fullscreen triangle eight times.
pub fn example_with_bloom_drawn_eight_times(dir: &std::path::Path) -> PathBuf {
    example_changed(dir, "bloom_extract", |bloom| {
        let fullscreen = bloom["draws"][0].clone();
        bloom["draws"] = serde_json::Value::Array(vec![fullscreen; 8]);
    })
}

/// A virtual X server for a program's window, stopped when dropped.
pub struct Display {
    child: std::process::Child,
    pub name: String,
}

impl Drop for Display {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub fn start_display() -> Display {
    // Tests start displays at once: each call begins at a number of its own, so that two never
    // race for one number (the loser's Xvfb would exit, and it would take the winner's socket
    // for its own and stop the winner's server when done).
    static CALLS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let first = CALLS.fetch_add(11, std::sync::atomic::Ordering::SeqCst);
    // Every number of the range is tried: sockets of servers killed earlier stay behind.
    for n in 0..200 {
        let number = 60 + (std::process::id() + first + n) % 200;
        if std::path::Path::new(&format!("/tmp/.X11-unix/X{number}")).exists() {
            continue;
        }
        // Owned by the guard at once, so that it is stopped and waited for on every path.
        let display = Display {
            child: std::process::Command::new("Xvfb")
                .arg(format!(":{number}"))
                .args(["-screen", "0", "1024x768x24", "-nolisten", "tcp"])
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()
                .expect("Xvfb (apt-get install xvfb)"),
            name: format!(":{number}"),
        };
        let socket = format!("/tmp/.X11-unix/X{number}");
        for _ in 0..100 {
            if std::path::Path::new(&socket).exists() {
                return display;
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        panic!("Xvfb :{number} did not start");
    }
    panic!("no free X display number");
}
