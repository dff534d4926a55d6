//! `framelab capture`: takes frame N of a running Vulkan program with GFXReconstruct's capture
//! layer (Debian's `gfxreconstruct`), stops the program once the layer has written the frame
//! (its log says so on the program's stdout), and imports the capture as `framelab import`
//! does. The layer writes `<name>_frame_<N>.gfxr` beside the file it is given; that file is
//! kept at `-o` when one is named, otherwise it lives in a scratch folder that is removed.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};

/// The layer's manifest, where Debian's package installs it.
const LAYER_MANIFESTS: &[&str] = &[
    "/usr/share/vulkan/explicit_layer.d/VkLayer_gfxreconstruct.json",
    "/usr/local/share/vulkan/explicit_layer.d/VkLayer_gfxreconstruct.json",
    "/etc/vulkan/explicit_layer.d/VkLayer_gfxreconstruct.json",
];

/// What the layer logs once the trimmed frames are written and the file closed.
const FINISHED: &str = "Finished recording graphics API capture";

#[derive(Debug, Clone, clap::Args)]
pub struct CaptureArgs {
    /// The frame to take (1 is the program's first presented frame).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub frame: u32,
    /// Keep the GFXReconstruct capture here; the imported capture goes beside it (`.json`).
    /// Without it, the imported capture is `<program>_frame<N>.json` in this folder.
    #[arg(short, long)]
    pub out: Option<PathBuf>,
    /// Give up (and stop the program) after this many seconds.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u64).range(1..=3600))]
    pub timeout: u64,
    /// The program and its arguments, after `--`.
    #[arg(required = true, last = true)]
    pub program: Vec<String>,
}

/// Where the capture and the imported capture go.
struct Outputs {
    gfxr: PathBuf,
    json: PathBuf,
    scratch: Option<PathBuf>,
}

fn outputs(args: &CaptureArgs) -> anyhow::Result<Outputs> {
    if let Some(out) = &args.out {
        if out.extension().is_none_or(|x| x != "gfxr") {
            bail!("-o {}: name the capture to keep with .gfxr", out.display());
        }
        return Ok(Outputs {
            gfxr: out.clone(),
            json: out.with_extension("json"),
            scratch: None,
        });
    }
    let stem = Path::new(&args.program[0])
        .file_name()
        .map_or_else(|| "capture".into(), |n| n.to_string_lossy().into_owned());
    let scratch = std::env::temp_dir().join(format!("framelab-capture-{}", std::process::id()));
    Ok(Outputs {
        gfxr: scratch.join(format!("{stem}.gfxr")),
        json: PathBuf::from(format!("{stem}_frame{}.json", args.frame)),
        scratch: Some(scratch),
    })
}

pub fn run(args: &CaptureArgs) -> anyhow::Result<ExitCode> {
    if !LAYER_MANIFESTS.iter().any(|m| Path::new(m).exists()) {
        bail!("GFXReconstruct's capture layer is not installed (apt-get install gfxreconstruct)");
    }
    let out = outputs(args)?;
    let result = capture_and_import(args, &out);
    if let Some(scratch) = &out.scratch {
        let _ = std::fs::remove_dir_all(scratch);
    }
    result
}

fn capture_and_import(args: &CaptureArgs, out: &Outputs) -> anyhow::Result<ExitCode> {
    let written = take(&args.program, args.frame, args.timeout, &out.gfxr)?;
    if written != out.gfxr {
        std::fs::rename(&written, &out.gfxr)
            .with_context(|| format!("moving the capture to {}", out.gfxr.display()))?;
    }
    super::import::run(&out.gfxr, &out.json, None, false)
}

/// Whether the capture layer is installed, with the error that names its package.
pub fn layer_installed() -> anyhow::Result<()> {
    if !LAYER_MANIFESTS.iter().any(|m| Path::new(m).exists()) {
        bail!("GFXReconstruct's capture layer is not installed (apt-get install gfxreconstruct)");
    }
    Ok(())
}

/// Runs `program` (with its arguments) under the layer, in the folder of `gfxr`, until it has
/// written frame `frame`, then stops it; returns the file the layer wrote there. The
/// program's stdout is read here (the layer logs on it), its stderr is ours.
pub fn take(program: &[String], frame: u32, timeout: u64, gfxr: &Path) -> anyhow::Result<PathBuf> {
    layer_installed()?;
    let Some((name, arguments)) = program.split_first() else {
        bail!("no program to run");
    };
    let dir = match gfxr.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let base = dir.join(format!(".framelab-capture-{}.gfxr", std::process::id()));
    let program = name;
    let mut child = Command::new(program)
        .args(arguments)
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_LUNARG_gfxreconstruct")
        .env("GFXRECON_CAPTURE_FILE", &base)
        .env("GFXRECON_CAPTURE_FILE_TIMESTAMP", "false")
        .env("GFXRECON_CAPTURE_FRAMES", frame.to_string())
        .env("GFXRECON_LOG_LEVEL", "info")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .with_context(|| format!("cannot run {program}"))?;
    // The layer's log is on the program's stdout: watched on a thread, so the wait below
    // can time out.
    let (tx, finished) = mpsc::channel();
    if let Some(stdout) = child.stdout.take() {
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if line.contains(FINISHED) {
                    let _ = tx.send(());
                }
            }
        });
    }
    let deadline = Instant::now() + Duration::from_secs(timeout);
    let outcome = loop {
        if finished.try_recv().is_ok() {
            break Ok(());
        }
        if let Some(status) = child.try_wait().context("waiting for the program")? {
            // The layer may finish the frame as the program exits.
            if finished.recv_timeout(Duration::from_millis(200)).is_ok() {
                break Ok(());
            }
            break Err(anyhow::anyhow!(
                "{program} exited ({status}) before frame {frame} was captured"
            ));
        }
        if Instant::now() >= deadline {
            break Err(anyhow::anyhow!(
                "{program} did not reach frame {frame} within {timeout} s (--timeout); it was stopped"
            ));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let _ = child.kill();
    let _ = child.wait();
    let written = dir.join(format!(
        ".framelab-capture-{}_frame_{frame}.gfxr",
        std::process::id()
    ));
    if let Err(e) = outcome {
        let _ = std::fs::remove_file(&written);
        return Err(e);
    }
    if !written.exists() {
        bail!(
            "the capture layer reported frame {frame} written, but {} is not there",
            written.display()
        );
    }
    Ok(written)
}
