//! The `framelab` command: parses arguments once into a validated form, runs one command, and
//! maps the outcome to an exit code (0 ok, 1 bad input or failed work, 2 usage).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use framelab::capture::{self, CaptureError, Diagnostic, Options, Severity};

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

fn info(path: &std::path::Path, json: bool, scale: f64) -> anyhow::Result<ExitCode> {
    let options = Options {
        scale,
        ..Options::default()
    };
    let validated = match capture::load_and_validate(path, &options) {
        Ok(v) => v,
        Err(e) => {
            if let CaptureError::Invalid { diagnostics, .. } = &e {
                print_diagnostics(diagnostics, path);
            }
            let _ = writeln!(std::io::stderr(), "{e}");
            return Ok(ExitCode::from(1));
        }
    };
    let report = framelab::info::report(&validated.capture);
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
