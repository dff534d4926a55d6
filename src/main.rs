//! The `framelab` command: parses arguments once into a validated form, runs one command, and
//! maps the outcome to an exit code (0 ok, 1 bad input or failed work, 2 usage).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use framelab::analysis::report;
use framelab::capture::{self, CaptureError, Diagnostic, Options, Severity};

/// Analyses allocate and free several MiB per run. The system allocator hands that memory back
/// to the kernel between runs and faults it in again; mimalloc keeps it, which on a 2-core
/// machine halves the analysis of a 10k-pass frame (README, Performance). The `system-alloc`
/// feature keeps the system allocator.
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser, Debug)]
#[command(
    name = "framelab",
    version,
    about = "Frame-capture analysis and pass reconstruction"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Check a capture against the format and D3D12/Vulkan rules; report every problem.
    Validate {
        capture: PathBuf,
        /// Print diagnostics as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// List a capture's resources, passes, heaps and totals as resolved for one scale.
    Info {
        capture: PathBuf,
        #[arg(long)]
        json: bool,
        /// Output-resolution multiplier; relative sizes follow it.
        #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
        scale: f64,
    },
    /// Build the pass DAG and print it as Graphviz DOT (default), JSON, or SVG.
    Graph {
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
    Analyze {
        capture: PathBuf,
        #[arg(long)]
        json: bool,
        /// Drop passes whose work never reaches an output before deriving barriers and memory.
        #[arg(long)]
        cull: bool,
        #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
        scale: f64,
    },
    /// Replay the capture through wgpu: time every pass, export every texture.
    Replay {
        capture: PathBuf,
        #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
        scale: f64,
        /// Frames to run (history resources ping-pong, the camera moves and jitters).
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=10000))]
        frames: u32,
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
        /// No progress bar or summary.
        #[arg(long)]
        quiet: bool,
    },
    /// Print the JSON Schema of the capture format.
    Schema,
    /// List the GPU adapters wgpu can use here, best first.
    Adapters,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // clap exits 2 for usage errors and 0 for --help/--version.
        Err(e) => e.exit(),
    };
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Validate { capture, json } => Ok(validate(&capture, json)),
        Command::Info {
            capture,
            json,
            scale,
        } => info(&capture, json, scale),
        Command::Graph {
            capture,
            dot,
            json,
            svg,
        } => graph(&capture, dot, json, svg),
        Command::Analyze {
            capture,
            json,
            cull,
            scale,
        } => analyze(&capture, json, cull, scale),
        Command::Replay {
            capture,
            scale,
            frames,
            adapter,
            cull,
            out,
            after,
            resource,
            timings,
            trace,
            quiet,
        } => {
            let options = framelab::replay::ReplayOptions {
                scale,
                frames,
                adapter,
                cull,
                out,
                after,
                resource,
                timings,
                trace,
            };
            replay(&capture, &options, quiet)
        }
        Command::Schema => {
            print_stdout(&framelab::schema::schema_json())?;
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

/// Writes to stdout, treating a closed pipe (`| head`) as success rather than a panic.
fn print_stdout(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

fn print_diagnostics(diagnostics: &[Diagnostic], file: &std::path::Path) {
    let mut err = std::io::stderr().lock();
    for d in diagnostics {
        let _ = writeln!(err, "{}: {d}", file.display());
    }
}

fn validate(path: &std::path::Path, json: bool) -> ExitCode {
    let result = capture::load_and_validate(path, &Options::default());
    let (valid, diagnostics, summary) = match &result {
        Ok(v) => (true, v.warnings.clone(), None),
        Err(e) => (false, e.diagnostics(), Some(e.to_string())),
    };
    if json {
        let report = serde_json::json!({
            "capture": path.display().to_string(),
            "valid": valid,
            "errors": diagnostics.iter().filter(|d| d.severity == Severity::Error).count(),
            "warnings": diagnostics.iter().filter(|d| d.severity == Severity::Warning).count(),
            "diagnostics": diagnostics,
        });
        let text = serde_json::to_string_pretty(&report).unwrap_or_default();
        let _ = print_stdout(&(text + "\n"));
    } else {
        match &result {
            Err(CaptureError::Invalid { .. }) | Ok(_) => print_diagnostics(&diagnostics, path),
            Err(_) => {}
        }
        if let Some(summary) = summary {
            let _ = writeln!(std::io::stderr(), "{summary}");
        } else {
            let c = result.as_ref().map(|v| &v.capture);
            if let Ok(c) = c {
                let _ = print_stdout(&format!(
                    "{}: valid ({} resources, {} passes, {} queues, {} warnings)\n",
                    path.display(),
                    c.resources.len(),
                    c.passes.len(),
                    c.queues.len(),
                    diagnostics.len()
                ));
            }
        }
    }
    if valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// Loads a capture for a command that needs a valid one; reports problems and returns `None`.
fn load(path: &std::path::Path, scale: f64) -> Option<framelab::capture::Capture> {
    let options = Options {
        scale,
        ..Options::default()
    };
    match capture::load_and_validate(path, &options) {
        Ok(v) => Some(v.capture),
        Err(e) => {
            if let CaptureError::Invalid { diagnostics, .. } = &e {
                print_diagnostics(diagnostics, path);
            }
            let _ = writeln!(std::io::stderr(), "{e}");
            None
        }
    }
}

type Analysed = (framelab::capture::Capture, report::Analysis);

fn analysis(path: &std::path::Path, cull: bool, scale: f64) -> Option<Analysed> {
    let capture = load(path, scale)?;
    match report::analyze(&capture, report::AnalyzeOptions { cull }) {
        Ok(a) => Some((capture, a)),
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "{}: {e}", path.display());
            None
        }
    }
}

fn graph(
    path: &std::path::Path,
    dot: Option<PathBuf>,
    json: bool,
    svg: Option<PathBuf>,
) -> anyhow::Result<ExitCode> {
    let Some((_, a)) = analysis(path, false, 1.0) else {
        return Ok(ExitCode::from(1));
    };
    let text = report::dot(&a);
    if json {
        print_stdout(&(serde_json::to_string_pretty(&report::graph_report(&a))? + "\n"))?;
    }
    if let Some(file) = &dot {
        framelab::output::write_atomically(file, text.as_bytes())?;
    }
    if let Some(file) = &svg {
        let rendered = framelab::output::render_svg(&text)?;
        framelab::output::write_atomically(file, &rendered)?;
    }
    if !json && dot.is_none() && svg.is_none() {
        print_stdout(&text)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn analyze(path: &std::path::Path, json: bool, cull: bool, scale: f64) -> anyhow::Result<ExitCode> {
    let Some((capture, a)) = analysis(path, cull, scale) else {
        return Ok(ExitCode::from(1));
    };
    let r = report::report(&capture, &a);
    if json {
        print_stdout(&(serde_json::to_string_pretty(&r)? + "\n"))?;
    } else {
        print_stdout(&report::render_text(&r))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn replay(
    path: &std::path::Path,
    options: &framelab::replay::ReplayOptions,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    use framelab::replay::Event;
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(u64::from(options.frames))
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg:>10} [{bar:30}] {pos}/{len} frames")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message("replaying");
    // indicatif draws nothing (and prints nothing) when stderr is not a terminal.
    let say = |text: String| {
        if quiet {
        } else if bar.is_hidden() {
            let _ = writeln!(std::io::stderr(), "{text}");
        } else {
            bar.println(text);
        }
    };
    let report = framelab::replay::replay(path, options, |event| match event {
        Event::Adapter(a) => say(format!("adapter: {a}")),
        Event::Note(n) => say(format!("note: {n}")),
        Event::Frame { index, .. } => bar.set_position(u64::from(index)),
        Event::Exported { files } => say(format!("exported {files} images")),
    });
    bar.finish_and_clear();
    let report = report?;
    if !quiet {
        let mut rows = Vec::new();
        for p in &report.passes {
            let gpu: Vec<u64> = p.gpu_ns.iter().flatten().copied().collect();
            let gpu = if gpu.is_empty() {
                "-".to_owned()
            } else {
                format!(
                    "{:.3}",
                    gpu.iter().sum::<u64>() as f64 / gpu.len() as f64 / 1e6
                )
            };
            let cpu = p.cpu_ns.iter().sum::<u64>() as f64 / p.cpu_ns.len().max(1) as f64 / 1e6;
            rows.push(vec![
                p.name.clone(),
                p.queue.clone(),
                gpu,
                format!("{cpu:.3}"),
            ]);
        }
        print_stdout(&format!(
            "{} on {} ({}), {} frame(s) at scale {}\n{}",
            report.capture,
            report.adapter,
            report.backend,
            report.frames,
            report.scale,
            framelab::info::table(&["pass", "queue", "gpu ms (mean)", "cpu ms (mean)"], &rows)
        ))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn info(path: &std::path::Path, json: bool, scale: f64) -> anyhow::Result<ExitCode> {
    let Some(capture) = load(path, scale) else {
        return Ok(ExitCode::from(1));
    };
    let report = framelab::info::report(&capture);
    if json {
        print_stdout(&(serde_json::to_string_pretty(&report)? + "\n"))?;
    } else {
        print_stdout(&framelab::info::render_text(&report))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn parse_scale(text: &str) -> Result<f64, String> {
    let v: f64 = text
        .parse()
        .map_err(|_| format!("\"{text}\" is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= 16.0 {
        Ok(v)
    } else {
        Err(format!("scale must be in (0, 16], not {v}"))
    }
}
