//! The command line's entry to the staged journey (`framelab_core::pipeline`): each command
//! asks for the stage it needs, and a stage's error becomes the message users read. Two
//! dialects exist, both kept as users know them: the analysis commands (`info`, `analyze`,
//! `graph`) print each diagnostic on its own line and exit 1; the commands that go on to a
//! device (`replay`, `diff`, `inspect`) report one error.

use framelab_core::text::printable;
use std::io::Write;
use std::path::Path;

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::{CaptureError, Options};
use framelab_core::pipeline::{Analysed, Loaded, Lowered, StageError, Validated};
use framelab_replay::GpuContext;

fn options(scale: f64) -> Options {
    Options {
        scale,
        ..Options::default()
    }
}

/// Why an edited frame could not be made, in the words `what-if` and `inspect` both use.
pub(super) fn variant_error(e: framelab_core::whatif::VariantError) -> anyhow::Error {
    use framelab_core::whatif::VariantError;
    match e {
        VariantError::Frame(e) => device_error(e),
        VariantError::Invalid(e) => {
            device_error(e).context("the edited frame is not a valid capture")
        }
        e => e.into(),
    }
}

/// A stage's error as the device commands report it.
pub(super) fn device_error(e: StageError) -> anyhow::Error {
    match e {
        StageError::Capture(CaptureError::Read { path, source }) => {
            anyhow::Error::new(source).context(format!("reading {}", path.display()))
        }
        // Only an invalid capture has more to say than its error's one line.
        StageError::Capture(e @ CaptureError::Invalid { .. }) => {
            let details: Vec<String> = e.diagnostics().iter().map(|d| d.to_string()).collect();
            anyhow::anyhow!("{e}\n{}", details.join("\n"))
        }
        e => e.into(),
    }
}

/// A stage's error as the analysis commands report it: diagnostics first, then the error.
fn print_stage_error(e: &StageError, path: &Path) {
    if let StageError::Capture(CaptureError::Invalid { diagnostics, .. }) = e {
        super::print_diagnostics(diagnostics, path);
    }
    let _ = writeln!(std::io::stderr(), "{}", printable(&e.to_string()));
}

/// A valid capture, or `None` once its problems are printed.
fn loaded(path: &Path, scale: f64) -> Option<Validated> {
    let v = Validated::load(path, &options(scale))
        .map_err(|e| print_stage_error(&e, path))
        .ok()?;
    note_scale(&v.capture, scale);
    Some(v)
}

/// A valid capture for an analysis command, or `None` once its problems are printed. A
/// capture whose passes cannot be ordered is refused here too, as `validate` refuses it.
pub fn validated(path: &Path, scale: f64) -> Option<Validated> {
    let v = loaded(path, scale)?;
    v.check_order()
        .map_err(|e| print_stage_error(&e, path))
        .ok()?;
    Some(v)
}

/// An imported frame has the application's sizes in texels, which no scale changes: said,
/// so that `--scale` is not taken to have made it smaller.
fn note_scale(capture: &framelab_core::capture::Capture, scale: f64) {
    if scale != 1.0 && capture.origin.is_some() {
        let _ = writeln!(
            std::io::stderr(),
            "note: {}: --scale {scale} changes no size here: an imported frame keeps the application's own (scale 1)",
            printable(&capture.source.display().to_string())
        );
    }
}

/// An analysed capture for an analysis command, or `None` once its problems are printed.
/// Analysis finds a cycle itself, so the order is not checked first.
pub fn analysed(path: &Path, cull: bool, scale: f64) -> Option<Analysed> {
    loaded(path, scale)?
        .analyse(AnalyzeOptions { cull })
        .map_err(|e| print_stage_error(&e, path))
        .ok()
}

/// An analysed capture for a device command, its bytes hashed for the timing report.
pub fn analysed_for_device(path: &Path, scale: f64, cull: bool) -> anyhow::Result<Analysed> {
    let v = Loaded::read_hashed(path)
        .and_then(|l| l.validate(&options(scale)))
        .map_err(device_error)?;
    note_scale(&v.capture, scale);
    v.analyse(AnalyzeOptions { cull }).map_err(device_error)
}

/// An analysed capture to replay: one that cannot be (an import) is refused before any device
/// opens.
pub fn for_replay(path: &Path, scale: f64, cull: bool) -> anyhow::Result<Analysed> {
    let a = Analysed::for_replay(path, &options(scale), AnalyzeOptions { cull })
        .map_err(device_error)?;
    note_scale(&a.capture, scale);
    Ok(a)
}

/// The capture's plan for this device.
pub fn lower(analysed: Analysed, ctx: &GpuContext) -> anyhow::Result<Lowered> {
    analysed
        .lower(ctx.device.features(), &ctx.summary.name)
        .map_err(device_error)
}
