//! The fuzz harness for what a capture's files are rather than what they say: each case
//! copies a capture folder (the example with its WGSL shaders, the BC fixture with a contents
//! side file, a vkcube frame imported from GFXReconstruct with SPIR-V modules and memory
//! contents), turns one of its files (the capture itself or a side file) into something else
//! (a named pipe, a folder, a link to `/dev/zero` or to nothing, an empty or cut or garbage
//! file, a sparse file just under, at or past its limit, or of 64 GiB) and runs load,
//! validation, analysis and lowering on it as `framelab replay` would, on a thread with a
//! deadline. Whatever the file, the result is a value or an error naming it: no panic, no
//! block on a pipe, no read of many GiB. The campaign runs in a child process of this test
//! binary under a 4 GB address-space limit, so a regression that reads a sparse file whole
//! fails the test instead of exhausting the machine.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::pipeline::Validated;
use proptest::prelude::*;

use crate::common::{framelab, gfxr_fixture, repo};

const MIB: u64 = 1 << 20;

/// A capture folder to mutate: its directory and the capture file's name in it.
struct Template {
    dir: PathBuf,
    capture: &'static str,
}

/// The three folders, made once per run (the vkcube frame is imported by `framelab import`).
fn templates() -> &'static [Template] {
    static T: OnceLock<Vec<Template>> = OnceLock::new();
    T.get_or_init(|| {
        let root = std::env::temp_dir().join(format!("framelab-fuzz-files-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let vk = root.join("template-vkcube");
        std::fs::create_dir_all(&vk).unwrap();
        let out = vk.join("vkcube.json");
        let imported = framelab(&[
            "import",
            gfxr_fixture("vkcube_f3.gfxr").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(imported.status.success(), "{imported:?}");
        vec![
            Template {
                dir: repo().join("captures/example"),
                capture: "frame.json",
            },
            Template {
                dir: repo().join("tests/fixtures/bc"),
                capture: "bc.json",
            },
            Template {
                dir: vk,
                capture: "vkcube.json",
            },
        ]
    })
}

/// Every regular file under `dir`, sorted so that a pick is reproducible.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

fn copy_tree(from: &Path, to: &Path) {
    for f in files_under(from) {
        let dst = to.join(f.strip_prefix(from).unwrap());
        std::fs::create_dir_all(dst.parent().unwrap()).unwrap();
        std::fs::copy(&f, &dst).unwrap();
    }
}

/// What a file becomes.
#[derive(Clone, Debug)]
enum Kind {
    Fifo,
    Folder,
    LinkToDevZero,
    DanglingLink,
    Empty,
    /// The first `n` thousandths of the file.
    Cut(u32),
    Garbage(Vec<u8>),
    /// A sparse file of this many bytes (holes read as zeros).
    Sparse(u64),
}

fn kind() -> impl Strategy<Value = Kind> {
    // Just under, at and past each limit a file kind has (a capture 256 MiB, a shader 16 MiB,
    // a side file what the capture declares and at most 4 GiB), and far past all of them.
    let sizes = prop_oneof![
        Just(16 * MIB - 1),
        Just(16 * MIB),
        Just(16 * MIB + 1),
        Just(256 * MIB),
        Just(256 * MIB + 1),
        Just(4096 * MIB + 1),
        Just(64 << 30),
        Just(1 << 40),
    ];
    prop_oneof![
        1 => Just(Kind::Fifo),
        1 => Just(Kind::Folder),
        1 => Just(Kind::LinkToDevZero),
        1 => Just(Kind::DanglingLink),
        1 => Just(Kind::Empty),
        2 => (0u32..1000).prop_map(Kind::Cut),
        2 => proptest::collection::vec(any::<u8>(), 0..512).prop_map(Kind::Garbage),
        3 => sizes.prop_map(Kind::Sparse),
    ]
}

fn make(path: &Path, kind: &Kind) {
    let original = std::fs::read(path).unwrap();
    std::fs::remove_file(path).unwrap();
    match kind {
        Kind::Fifo => {
            let made = std::process::Command::new("mkfifo")
                .arg(path)
                .status()
                .unwrap();
            assert!(made.success());
        }
        Kind::Folder => std::fs::create_dir(path).unwrap(),
        Kind::LinkToDevZero => std::os::unix::fs::symlink("/dev/zero", path).unwrap(),
        Kind::DanglingLink => {
            std::os::unix::fs::symlink(path.with_extension("gone"), path).unwrap()
        }
        Kind::Empty => std::fs::write(path, b"").unwrap(),
        Kind::Cut(k) => {
            let n = original.len() * *k as usize / 1000;
            std::fs::write(path, &original[..n]).unwrap();
        }
        Kind::Garbage(bytes) => std::fs::write(path, bytes).unwrap(),
        Kind::Sparse(len) => std::fs::File::create(path).unwrap().set_len(*len).unwrap(),
    }
}

/// Load, validate, analyse and lower `capture` on a thread; fails on a panic, or when it
/// takes past the deadline (a read that blocks or never ends).
fn run_bounded(capture: PathBuf, what: String) {
    let (tx, rx) = std::sync::mpsc::channel();
    let worker = std::thread::spawn(move || {
        let options = Options {
            scale: 0.25,
            ..Options::default()
        };
        if let Ok(v) = Validated::load(&capture, &options)
            && let Ok(a) = v.analyse(AnalyzeOptions { cull: false })
        {
            let _ = a.lower(framelab_replay::wgpu::Features::empty(), "fuzz");
        }
        let _ = tx.send(());
    });
    match rx.recv_timeout(Duration::from_secs(30)) {
        Ok(()) => worker.join().unwrap(),
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
            if let Err(e) = worker.join() {
                std::panic::resume_unwind(e);
            }
        }
        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
            panic!("{what}: still running after 30 s (a blocked or unbounded read)")
        }
    }
}

/// Runs the campaign below in a child (this test binary, the one ignored test) under
/// `ulimit -v`, passing on FRAMELAB_FUZZ_CASES.
#[test]
fn file_kinds_and_sizes_under_an_address_space_limit() {
    let exe = std::env::current_exe().unwrap();
    let child = std::process::Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 4000000; exec "$0" "$@""#)
        .arg(exe)
        .args([
            "--exact",
            "fuzz_files::campaign",
            "--ignored",
            "--test-threads",
            "1",
        ])
        .env("RUST_BACKTRACE", "0")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // `sh` execs the test binary, so the campaign's folders are named after this pid.
    let pid = child.id();
    let out = child.wait_with_output().unwrap();
    let _ =
        std::fs::remove_dir_all(std::env::temp_dir().join(format!("framelab-fuzz-files-{pid}")));
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("1 passed"),
        "the campaign did not run:\n{text}"
    );
}

proptest! {
    // 300 cases in CI; FRAMELAB_FUZZ_CASES runs longer campaigns.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("FRAMELAB_FUZZ_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(300),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Run through `file_kinds_and_sizes_under_an_address_space_limit`.
    #[test]
    #[ignore = "run in a child under an address-space limit by the test above"]
    fn campaign(
        which in 0usize..3,
        pick in any::<usize>(),
        kind in kind(),
    ) {
        let t = &templates()[which];
        let case = std::env::temp_dir().join(format!(
            "framelab-fuzz-files-{}/case-{}",
            std::process::id(),
            std::thread::current().name().unwrap_or("t").replace(':', "_")
        ));
        let _ = std::fs::remove_dir_all(&case);
        copy_tree(&t.dir, &case);
        let files = files_under(&case);
        let target = &files[pick % files.len()];
        let what = format!("{} of {} made {kind:?}", target.strip_prefix(&case).unwrap().display(), t.capture);
        make(target, &kind);
        run_bounded(case.join(t.capture), what);
        let _ = std::fs::remove_dir_all(&case);
    }
}
