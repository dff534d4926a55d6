//! `framelab graph` (the pass DAG as DOT, JSON or SVG) and `framelab analyze` (order, culling,
//! barriers, memory, lints, critical path).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use framelab::analysis::report;

use super::{analysis, print_stdout};

pub fn graph(
    path: &Path,
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
pub fn analyze(path: &Path, json: bool, cull: bool, scale: f64) -> anyhow::Result<ExitCode> {
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
