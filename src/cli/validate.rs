//! `framelab validate`: every problem of a capture at once, as text on stderr or JSON on stdout.

use framelab_core::text::printable;
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use framelab_core::capture::{CaptureError, Diagnostic, Options, Severity};
use framelab_core::pipeline::{StageError, Validated};

use super::{print_diagnostics, print_stdout};

pub fn run(path: &Path, json: bool) -> ExitCode {
    let result = Validated::load(path, &Options::default());
    let (valid, diagnostics, summary) = match &result {
        // A capture whose passes cannot be ordered is invalid here too, not only to `analyze`.
        Ok(v) => match v.check_order() {
            Ok(()) => (true, v.warnings.clone(), None),
            Err(StageError::Cycle { cycle, .. }) => {
                let mut all = v.warnings.clone();
                all.push(Diagnostic {
                    severity: Severity::Error,
                    code: "cycle",
                    path: "$.passes".to_owned(),
                    message: cycle.to_string(),
                    suggestion: None,
                });
                let errors = format!("{}: 1 error(s) in capture", path.display());
                (false, all, Some(errors))
            }
            Err(e) => (false, e.diagnostics(), Some(e.to_string())),
        },
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
            Err(StageError::Capture(CaptureError::Invalid { .. })) | Ok(_) => {
                print_diagnostics(&diagnostics, path)
            }
            Err(_) => {}
        }
        if let Some(summary) = summary {
            let _ = writeln!(std::io::stderr(), "{}", printable(&summary));
        } else {
            let c = result.as_ref().map(|v| &v.capture);
            if let Ok(c) = c {
                let _ = print_stdout(&format!(
                    "{}: valid ({}, {}, {}, {})\n",
                    path.display(),
                    super::count(c.resources.len(), "resource", "resources"),
                    super::count(c.passes.len(), "pass", "passes"),
                    super::count(c.queues.len(), "queue", "queues"),
                    super::count(diagnostics.len(), "warning", "warnings")
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
