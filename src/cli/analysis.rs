//! `framelab graph` (the pass DAG as DOT, JSON or SVG) and `framelab analyze` (order, culling,
//! barriers, memory, lints, critical path).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use framelab_core::analysis::lints::{LintKind, LintSeverity};
use framelab_core::analysis::report;

use super::print_stdout;
use super::stages::analysed;

pub fn graph(
    path: &Path,
    dot: Option<PathBuf>,
    json: bool,
    svg: Option<PathBuf>,
) -> anyhow::Result<ExitCode> {
    let outputs: Vec<&Path> = dot.iter().chain(&svg).map(PathBuf::as_path).collect();
    framelab_core::output::check_outputs(&outputs, &[path])?;
    let Some(analysed) = analysed(path, false, 1.0) else {
        return Ok(ExitCode::from(1));
    };
    let a = &analysed.analysis;
    let text = report::dot(a);
    if json {
        print_stdout(&(serde_json::to_string_pretty(&report::graph_report(a))? + "\n"))?;
    }
    if let Some(file) = &dot {
        framelab_core::output::write_atomically(file, text.as_bytes())?;
    }
    if let Some(file) = &svg {
        let rendered = framelab_core::output::render_svg(&text)?;
        framelab_core::output::write_atomically(file, &rendered)?;
    }
    if !json && dot.is_none() && svg.is_none() {
        print_stdout(&text)?;
    }
    Ok(ExitCode::SUCCESS)
}
/// Which lints fail `analyze` (`--deny`), like clippy's `-D`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Deny {
    /// Every error-severity lint.
    Errors,
    /// Every warning- or error-severity lint.
    Warnings,
    /// One lint, by code.
    Code(&'static str),
}

impl Deny {
    fn denies(&self, lint: &report::LintReport) -> bool {
        match self {
            Deny::Errors => lint.severity == LintSeverity::Error,
            Deny::Warnings => lint.severity != LintSeverity::Info,
            Deny::Code(code) => lint.code == *code,
        }
    }
}

/// `errors`, `warnings`, a lint code (`FL020`) or a lint name (`barrier-missing`).
pub fn parse_deny(text: &str) -> anyhow::Result<Deny> {
    match text {
        "errors" => return Ok(Deny::Errors),
        "warnings" => return Ok(Deny::Warnings),
        _ => {}
    }
    LintKind::all()
        .iter()
        .find(|k| k.code().eq_ignore_ascii_case(text) || k.name() == text)
        .map(|k| Deny::Code(k.code()))
        .ok_or_else(|| {
            anyhow::anyhow!(
                "\"{text}\" is not `errors`, `warnings`, a lint code (FL001..) or a lint name"
            )
        })
}

pub fn analyze(
    path: &Path,
    json: bool,
    cull: bool,
    scale: f64,
    deny: &[Deny],
) -> anyhow::Result<ExitCode> {
    let Some(analysed) = analysed(path, cull, scale) else {
        return Ok(ExitCode::from(1));
    };
    let r = report::report(&analysed.capture, &analysed.analysis);
    if json {
        print_stdout(&(serde_json::to_string_pretty(&r)? + "\n"))?;
    } else {
        print_stdout(&report::render_text(&r))?;
    }
    let denied: Vec<&report::LintReport> = r
        .lints
        .iter()
        .filter(|l| deny.iter().any(|d| d.denies(l)))
        .collect();
    if denied.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    let mut err = std::io::stderr().lock();
    for l in &denied {
        let _ = writeln!(
            err,
            "error: denied lint {} {}: {}",
            l.code, l.name, l.message
        );
    }
    let _ = writeln!(
        err,
        "{}: {} denied lint(s) fired",
        path.display(),
        denied.len()
    );
    Ok(ExitCode::from(1))
}
