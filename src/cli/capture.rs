//! `framelab capture`: takes frame N of a running Vulkan program with GFXReconstruct's capture
//! layer (core's `import::program::take`: the program is stopped once the layer has written
//! the frame) and imports the capture as `framelab import` does. The layer writes `<name>_frame_<N>.gfxr` beside the file it is given; that file is
//! kept at `-o` when one is named, otherwise it lives in a scratch folder that is removed.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use framelab_core::import::program::{layer_installed, take};

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
    layer_installed()?;
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
