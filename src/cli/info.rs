//! `framelab info`: a capture's resources, passes, heaps and totals as resolved for one scale.

use std::path::Path;
use std::process::ExitCode;

use super::print_stdout;

pub fn run(path: &Path, json: bool, scale: f64) -> anyhow::Result<ExitCode> {
    let Some(validated) = super::stages::validated(path, scale) else {
        return Ok(ExitCode::from(1));
    };
    let report = framelab_core::info::report(&validated.capture);
    if json {
        print_stdout(&(serde_json::to_string_pretty(&report)? + "\n"))?;
    } else {
        print_stdout(&framelab_core::info::render_text(&report))?;
    }
    Ok(ExitCode::SUCCESS)
}
