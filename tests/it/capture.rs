//! `framelab capture` on a real program: vkcube under a virtual X server, frame 3 taken with
//! GFXReconstruct's layer, the program stopped, the capture imported; and the errors of a
//! program that never presents, one that is not there and one that exits first.

use std::process::Command;

use crate::common::{Scratch, json, repo, start_display, stderr};

fn capture(display: &str, dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_framelab"))
        .arg("capture")
        .args(args)
        .current_dir(dir)
        .env("DISPLAY", display)
        .output()
        .expect("run framelab")
}

#[test]
fn vkcube_frame_three_is_taken_stopped_and_imported() {
    let display = start_display();
    let dir = Scratch::temp("framelab-capture-test");
    let out = capture(
        &display.name,
        &dir,
        &[
            "--frame",
            "3",
            "-o",
            "cube.gfxr",
            "--timeout",
            "120",
            "--",
            "vkcube",
        ],
    );
    // Success means the program was stopped once its frame was written (vkcube runs until
    // it is closed); past --timeout the command fails.
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("cube.gfxr").exists());
    let info = Command::new(env!("CARGO_BIN_EXE_framelab"))
        .args(["info", "--json"])
        .arg(dir.join("cube.json"))
        .current_dir(repo())
        .output()
        .unwrap();
    let info = json(&info);
    // vkcube's frame: one render pass drawing the cube, then the present.
    let kinds: Vec<&str> = info["passes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"raster"), "{kinds:?}");
    assert!(kinds.contains(&"present"), "{kinds:?}");
    // Without -o the capture is dropped and the import named after the program.
    let out = capture(&display.name, &dir, &["--frame", "2", "--", "vkcube"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("vkcube_frame2.json").exists());

    let cases: [(&[&str], &str); 3] = [
        (
            &["--frame", "3", "--timeout", "2", "--", "sleep", "30"],
            "sleep did not reach frame 3 within 2 s",
        ),
        (
            &["--frame", "3", "--", "/nonexistent/program"],
            "cannot run /nonexistent/program",
        ),
        (
            &["--frame", "3", "--", "true"],
            "true exited (exit status: 0) before frame 3 was captured",
        ),
    ];
    for (args, message) in cases {
        let out = capture(&display.name, &dir, args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(stderr(&out).contains(message), "{args:?}: {}", stderr(&out));
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".framelab-capture"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
