//! The `framelab` command: parses arguments once into a validated form, runs one command (one
//! file each), and maps the outcome to an exit code (0 ok, 1 bad input or failed work, 2 usage).
//! `anyhow` lives here only.

mod analysis;
pub(crate) mod capture;
mod diff;
mod import;
mod info;
mod inspect;
mod replay;
mod stages;
mod validate;
mod what_if;

use framelab_core::text::printable;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use framelab_core::capture::Diagnostic;

/// `--version`: the build, and the GPU stack and file formats it speaks.
const LONG_VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    "\nwgpu ",
    env!("FRAMELAB_WGPU_VERSION"),
    ", naga ",
    env!("FRAMELAB_NAGA_VERSION"),
    "\ncapture format 1, timing report format 1"
);

#[derive(Parser, Debug)]
#[command(
    name = "framelab",
    version,
    long_version = LONG_VERSION,
    about = "Frame-capture analysis and pass reconstruction",
    after_help = "Set NO_COLOR to turn colour off; it is off when output is not a terminal."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Check a capture against the format and D3D12/Vulkan rules; report every problem.
    ///
    /// Example: framelab validate captures/example/frame.json --json
    Validate {
        /// The capture (JSON).
        capture: PathBuf,
        /// Print diagnostics as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// List a capture's resources, passes, heaps and totals as resolved for one scale.
    ///
    /// Example: framelab info captures/example/frame.json --scale 0.5
    Info {
        /// The capture (JSON).
        capture: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
        /// Output-resolution multiplier; relative sizes follow it.
        #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
        scale: f64,
    },
    /// Build the pass DAG and print it as Graphviz DOT (default), JSON, or SVG.
    ///
    /// Example: framelab graph captures/example/frame.json --svg dag.svg
    Graph {
        /// The capture (JSON).
        capture: PathBuf,
        /// Write DOT to this file instead of stdout.
        #[arg(long)]
        dot: Option<PathBuf>,
        /// Print the graph as JSON.
        #[arg(long)]
        json: bool,
        /// Render SVG with Graphviz's `dot` into this file.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Order, culling, barriers per boundary, memory aliasing, lints, critical path.
    ///
    /// Example: framelab analyze frame.json --deny errors --deny FL021 (a CI step)
    Analyze {
        /// The capture (JSON).
        capture: PathBuf,
        /// Print the analysis as JSON.
        #[arg(long)]
        json: bool,
        /// Drop passes whose work never reaches an output before deriving barriers and memory.
        #[arg(long)]
        cull: bool,
        /// Output-resolution multiplier; relative sizes follow it.
        #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
        scale: f64,
        /// Exit 1 when a denied lint fires: `errors`, `warnings` (and errors), a lint code
        /// (`FL020`) or name (`barrier-missing`); repeatable.
        #[arg(long, value_parser = analysis::parse_deny)]
        deny: Vec<analysis::Deny>,
    },
    /// Replay the capture through wgpu: time every pass, export every texture.
    ///
    /// Example: framelab replay captures/example/frame.json --scale 0.5 --out out --timings t.json
    Replay {
        /// The capture (JSON).
        capture: PathBuf,
        /// Output-resolution multiplier; relative sizes follow it.
        #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
        scale: f64,
        /// Frames to run (history resources ping-pong, the camera moves and jitters).
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=10000))]
        frames: u32,
        /// Of those frames, how many come first to let clocks settle: kept in the timing
        /// report, marked, and left out of diffs.
        #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=9999))]
        warmup: u32,
        /// Use the adapter whose name contains this text.
        #[arg(long)]
        adapter: Option<String>,
        /// Drop passes whose results never reach an output.
        #[arg(long)]
        cull: bool,
        /// Export every texture (PNG/EXR) and a manifest into this folder.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Export the state right after this pass of the last frame.
        #[arg(long, requires = "out")]
        after: Option<String>,
        /// Export only this resource.
        #[arg(long, requires = "out")]
        resource: Option<String>,
        /// Write per-pass GPU and CPU times as JSON.
        #[arg(long)]
        timings: Option<PathBuf>,
        /// Write a Chrome trace-event file (one track per queue; opens in Perfetto).
        #[arg(long)]
        trace: Option<PathBuf>,
        /// Give every pass a start timestamp of its own instead of starting it at the previous
        /// pass's end: its time then leaves out the barriers before it, at twice the stamps.
        #[arg(long)]
        timestamp_pairs: bool,
        /// Count each pass's pipeline statistics (vertex, clipper, fragment and compute
        /// invocations) every frame: printed with the work each pass submits and the ratios
        /// read off them, and written to the timing report and the trace.
        #[arg(long)]
        counters: bool,
        /// No progress bar or summary.
        #[arg(long)]
        quiet: bool,
    },
    /// Compare two frames' per-pass GPU timings (two timing reports, or two captures replayed
    /// interleaved on one device) with statistics; exit 1 on a significant regression.
    ///
    /// Example: framelab diff before.json after.json --fail-on-regression 5 --markdown
    Diff(diff::DiffArgs),
    /// Change a frame and see what the change does: apply lint fixes, cull passes, drop
    /// recorded barriers or change formats; the variant is checked first (exit 1 on an error
    /// it introduces, before anything runs), then both replay interleaved on one device and
    /// their time, work, memory and every texture are compared.
    ///
    /// Example: framelab what-if frame.json --fix FL005 --frames 10 --out whatif/
    WhatIf(Box<what_if::WhatIfArgs>),
    /// Open the inspector: events, every texture as of any pass, resources, pass details with
    /// derived and recorded barriers, and a timeline scaled by GPU time.
    ///
    /// Example: framelab inspect frame.json --screenshot view.png --select tonemap --view ldr
    Inspect(Box<inspect::InspectArgs>),
    /// Take frame N of a running Vulkan program with GFXReconstruct's capture layer, stop the
    /// program once the frame is written, and import it (see `import`).
    ///
    /// Example: framelab capture --frame 3 -o cube.gfxr -- vkcube
    Capture(capture::CaptureArgs),
    /// Serve the Model Context Protocol over stdio, for assistants and scripts: open
    /// captures, list passes and resources, one pass's details, the analysis, a structural or
    /// timing diff, a texture, its texels or a buffer after any pass, per-pass timings, and
    /// take a running program's frame. Register it with a client as the command `framelab mcp`.
    ///
    /// Example: framelab mcp --root ~/captures
    Mcp {
        /// Read captures only inside this directory (and inside the client's roots); may be
        /// given more than once.
        #[arg(long)]
        root: Vec<PathBuf>,
    },
    /// Turn a GFXReconstruct or RenderDoc capture into a framelab capture: passes,
    /// resources, heaps and the barriers the application recorded. A binary capture
    /// (`.gfxr`, or RenderDoc's `.rdc` read through renderdoccmd; each recognised by its file
    /// header) also brings its SPIR-V shaders and memory contents, written as side files
    /// beside the output; a JSON Lines stream (gfxrecon-convert) holds neither, so its import
    /// is for validate, analyze, graph and diff --structure only.
    ///
    /// Example: framelab import app.gfxr -o app.json --frame 1
    Import {
        /// The capture: a binary `.gfxr`, a RenderDoc `.rdc`, or JSON Lines from
        /// gfxrecon-convert.
        stream: PathBuf,
        /// Where to write the capture (JSON); written only if it validates.
        #[arg(short, long)]
        out: PathBuf,
        /// Import only this frame (0-based; frames end at vkQueuePresentKHR).
        #[arg(long, value_parser = import::parse_frames, conflicts_with = "frames")]
        frame: Option<(u32, u32)>,
        /// Import only frames A-B (0-based, inclusive).
        #[arg(long, value_parser = import::parse_frames)]
        frames: Option<(u32, u32)>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Set numbers in a GFXReconstruct capture's calls (a barrier's masks or layouts) and
    /// write the edited capture, which replays like the original: a barrier removed or
    /// weakened in a real stream, to see what breaks. BLOCK is the call's block index as
    /// `gfxrecon-convert` numbers it; PATH names a parameter as the JSON Lines stream does.
    ///
    /// Example: framelab edit app.gfxr -o weak.gfxr --set '233:pImageMemoryBarriers[0].srcAccessMask=0'
    Edit {
        /// The binary capture (`.gfxr`).
        capture: PathBuf,
        /// Where to write the edited capture.
        #[arg(short, long)]
        out: PathBuf,
        /// BLOCK:PATH=VALUE, the value a number or a Vulkan enum name; repeatable.
        #[arg(long = "set", required = true)]
        set: Vec<framelab_core::import::gfxr::edit::FieldEdit>,
    },
    /// Print the JSON Schema of the capture format.
    ///
    /// Example: framelab schema > capture.schema.json
    Schema,
    /// Print what the replay does with every member of each class of Vulkan a real frame can
    /// use (commands, dynamic states, sampler fields, address modes, border colours,
    /// descriptor types): native, emulated, no effect or refused, and why, as Markdown.
    ///
    /// Example: framelab coverage > docs/coverage.md
    Coverage,
    /// List the GPU adapters wgpu can use here, best first.
    ///
    /// Example: framelab adapters
    Adapters,
    /// Print a shell completion script.
    ///
    /// Example: framelab completions bash > /etc/bash_completion.d/framelab
    Completions {
        /// bash, elvish, fish, powershell or zsh.
        shell: clap_complete::Shell,
    },
}

pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // clap exits 2 for usage errors and 0 for --help/--version.
        Err(e) => e.exit(),
    };
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            let _ = writeln!(
                std::io::stderr(),
                "{}: {}",
                error_label(),
                printable(&format!("{e:#}"))
            );
            ExitCode::from(1)
        }
    }
}

/// `error` in bold red on a terminal; plain when stderr is piped or `NO_COLOR` is set (as
/// anstream decides for clap's own messages).
pub(crate) fn error_label() -> String {
    let style = anstyle::Style::new()
        .bold()
        .fg_color(Some(anstyle::AnsiColor::Red.into()));
    if anstream::AutoStream::choice(&std::io::stderr()) == anstream::ColorChoice::Never {
        "error".to_owned()
    } else {
        format!("{style}error{style:#}")
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Validate { capture, json } => Ok(validate::run(&capture, json)),
        Command::Info {
            capture,
            json,
            scale,
        } => info::run(&capture, json, scale),
        Command::Graph {
            capture,
            dot,
            json,
            svg,
        } => analysis::graph(&capture, dot, json, svg),
        Command::Analyze {
            capture,
            json,
            cull,
            scale,
            deny,
        } => analysis::analyze(&capture, json, cull, scale, &deny),
        Command::Replay {
            capture,
            scale,
            frames,
            warmup,
            adapter,
            cull,
            out,
            after,
            resource,
            timings,
            trace,
            timestamp_pairs,
            counters,
            quiet,
        } => {
            let options = replay::ReplayOptions {
                scale,
                frames,
                warmup,
                adapter,
                cull,
                out,
                after,
                resource,
                timings,
                trace,
                timestamp_pairs,
                counters,
            };
            replay::run(&capture, &options, quiet)
        }
        Command::Diff(args) => Ok(diff::run(&args)),
        Command::WhatIf(args) => Ok(what_if::run(&args)),
        Command::Inspect(args) => inspect::run(&args),
        Command::Mcp { root } => crate::mcp::run(&root),
        Command::Capture(args) => capture::run(&args),
        Command::Import {
            stream,
            out,
            frame,
            frames,
            json,
        } => import::run(&stream, &out, frame.or(frames), json),
        Command::Edit { capture, out, set } => import::edit(&capture, &out, &set),
        Command::Schema => {
            print_stdout(&framelab_core::schema::schema_json())?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Coverage => {
            print_stdout(&coverage_page())?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Completions { shell } => {
            let mut text = Vec::new();
            clap_complete::generate(
                shell,
                &mut <Cli as clap::CommandFactory>::command(),
                "framelab",
                &mut text,
            );
            print_stdout(&String::from_utf8_lossy(&text))?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Adapters => {
            let adapters = framelab_replay::list_adapters();
            if adapters.is_empty() {
                anyhow::bail!(
                    "no GPU adapter found; install Mesa's software Vulkan (apt-get install mesa-vulkan-drivers libvulkan1)"
                );
            }
            let text: String = adapters.iter().map(|a| format!("{a}\n")).collect();
            print_stdout(&text)?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// A message names what is in the way without listing a whole folder.
pub(crate) use framelab_core::text::first_few;

/// Writes to stdout, treating a closed pipe (`| head`) as success rather than a panic; a
/// control character that came from an input is written as an escape (JSON output has none
/// left to escape).
pub(crate) fn print_stdout(text: &str) -> anyhow::Result<()> {
    print_stdout_styled(&printable(text))
}

/// Writes text whose escape sequences framelab put there itself (a coloured diff of inputs
/// checked for control characters when read).
pub(crate) fn print_stdout_styled(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

pub(crate) fn print_diagnostics(diagnostics: &[Diagnostic], file: &std::path::Path) {
    let mut err = std::io::stderr().lock();
    for d in diagnostics {
        let _ = writeln!(err, "{}", printable(&format!("{}: {d}", file.display())));
    }
}

pub(crate) fn parse_scale(text: &str) -> anyhow::Result<f64> {
    let v: f64 = text
        .parse()
        .map_err(|_| anyhow::anyhow!("\"{text}\" is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= 16.0 {
        Ok(v)
    } else {
        Err(anyhow::anyhow!("scale must be in (0, 16], not {v}"))
    }
}

pub(crate) fn parse_percent(text: &str) -> anyhow::Result<f64> {
    let v: f64 = text
        .parse()
        .map_err(|_| anyhow::anyhow!("\"{text}\" is not a number"))?;
    if v.is_finite() && (0.0..=1000.0).contains(&v) {
        Ok(v)
    } else {
        Err(anyhow::anyhow!(
            "a percentage must be in [0, 1000], not {v}"
        ))
    }
}

/// `1 pass`, `2 passes`.
pub(crate) fn count(n: impl TryInto<u64>, one: &str, many: &str) -> String {
    let n: u64 = n.try_into().unwrap_or(u64::MAX);
    format!("{n} {}", if n == 1 { one } else { many })
}

/// `docs/coverage.md`: the coverage table with its heading.
fn coverage_page() -> String {
    format!(
        "# Replay coverage of Vulkan, class by class\n\nGenerated by `framelab coverage` from the Vulkan registry the importer's decoding tables were made from (`tools/vkregistry`); a test fails when the registry names a member this table lacks. **native**: wgpu does what the capture says. **emulated**: done another way with the same result. **no effect**: changes nothing the replay reproduces. **sets**: a `vkCmdSet*` call, judged by its dynamic state's row. **refused**: the frame is refused at import (`not_replayable`, with the command and pass) and by `replay` (exit 1), never replayed into a wrong image.\n\n{}",
        framelab_core::coverage::markdown()
    )
}
