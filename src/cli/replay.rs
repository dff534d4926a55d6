//! `framelab replay`: validate, order (and optionally cull) a capture, open a GPU device,
//! lower the capture into a replay plan, run N frames, and write the timing report, a Chrome
//! trace and every texture as PNG/EXR. wgpu exposes one queue, so passes from the capture's
//! graphics, compute and copy queues run in DAG order on it; the reports keep each pass's
//! capture queue. Names given on the command line are resolved to ids before the device opens.

use framelab_core::text::printable;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use framelab_core::capture::Capture;
use framelab_core::capture::model::PassId;
use framelab_core::lower;
use framelab_core::timing::{self, TimingReport};
use framelab_core::wgpu_types::Features;
use serde::Serialize;

use super::print_stdout;
use super::stages;
use framelab_replay::Replaying;

#[derive(Debug, Clone)]
pub struct ReplayOptions {
    pub scale: f64,
    pub frames: u32,
    pub warmup: u32,
    pub adapter: Option<String>,
    pub cull: bool,
    pub out: Option<PathBuf>,
    /// Export the state right after this pass of the last frame.
    pub after: Option<String>,
    /// Export only this resource.
    pub resource: Option<String>,
    pub timings: Option<PathBuf>,
    pub trace: Option<PathBuf>,
    /// A start and an end timestamp for every pass (see `Session::set_timestamp_pairs`).
    pub timestamp_pairs: bool,
    /// Count every pass's pipeline statistics (see `Session::set_counting`).
    pub counters: bool,
}

/// What happened, for the command to print.
#[derive(Debug)]
pub enum Event<'a> {
    Adapter(&'a str),
    Note(&'a str),
    Frame { index: u32 },
    Exported { files: usize },
}

#[derive(Debug, Serialize)]
struct Manifest<'a> {
    capture: &'a str,
    frames: u32,
    after: Option<&'a str>,
    files: &'a [framelab_replay::export::ExportedFile],
    skipped: &'a [framelab_replay::export::Skipped],
}

/// `--after` and `--resource`, checked against the capture and the replayed order before a
/// device is opened (the frame cursor resolves them to the plan's once it is lowered).
fn check_targets(
    capture: &Capture,
    order: &[PassId],
    options: &ReplayOptions,
) -> anyhow::Result<()> {
    if let Some(name) = &options.after
        && !order.iter().any(|&p| &capture.pass(p).name == name)
    {
        bail!("--after: no pass \"{name}\" in the replayed order");
    }
    if let Some(name) = &options.resource
        && !capture
            .resources
            .iter()
            .any(|r| &r.name == name && r.is_texture())
    {
        bail!("--resource: no texture \"{name}\" is replayed");
    }
    Ok(())
}

pub fn replay(
    path: &Path,
    options: &ReplayOptions,
    mut on: impl FnMut(Event<'_>),
) -> anyhow::Result<TimingReport> {
    if options.warmup >= options.frames {
        bail!(
            "--warmup {} leaves no measured frame of --frames {}",
            options.warmup,
            options.frames
        );
    }
    let analysed = stages::for_replay(path, options.scale, options.cull)?;
    check_targets(&analysed.capture, &analysed.analysis.order, options)?;
    // Before the device and the replay: a refused --out should cost nothing.
    if let Some(out) = &options.out {
        check_out(out)?;
    }
    let ctx = framelab_replay::open_device(options.adapter.as_deref(), lower::wanted_features())?;
    on(Event::Adapter(&ctx.summary.to_string()));
    let lowered = stages::lower(analysed, &ctx)?;
    for n in &lowered.notes {
        on(Event::Note(n));
    }
    if !ctx.device.features().contains(Features::TIMESTAMP_QUERY) {
        on(Event::Note(
            "the adapter has no timestamp queries: GPU times are not measured",
        ));
    }
    // The capture's (DXGI) name of each plan texture's format, for the export manifest.
    let mut formats = vec![String::new(); lowered.plan.textures.len()];
    for (&r, &t) in &lowered.texture_of {
        if let (Some(slot), Some(f)) = (formats.get_mut(t), lowered.capture().resource(r).format) {
            *slot = f.name.to_owned();
        }
    }
    let mut replayer = Replaying::start(&ctx, lowered)?;
    let stop_after = match &options.after {
        Some(name) => Some(replayer.plan_pass(name).context("--after")?),
        None => None,
    };
    let export_texture = match &options.resource {
        Some(name) => Some(replayer.plan_texture(name).context("--resource")?),
        None => None,
    };
    for (shader, path) in replayer.session.shader_paths() {
        on(Event::Note(&format!(
            "shader {shader}: {} path",
            path.name()
        )));
    }
    replayer
        .session
        .set_timestamp_pairs(options.timestamp_pairs);
    if !replayer.session.set_counting(options.counters) {
        on(Event::Note(
            "the adapter has no pipeline statistics queries: counters are not measured",
        ));
    }
    let frames = options.frames.max(1);
    for f in 0..frames {
        on(Event::Frame { index: f });
        let stop = if f + 1 == frames { stop_after } else { None };
        replayer.frame(f, stop)?;
    }
    let report = replayer.report(options.warmup);
    let (session, times, capture) = (&replayer.session, &replayer.times, replayer.capture());
    if let Some(file) = &options.timings {
        framelab_core::output::write_atomically(file, report.to_json().as_bytes())?;
    }
    if let Some(file) = &options.trace {
        framelab_core::output::write_atomically(
            file,
            timing::trace::chrome_trace(&report, times).as_bytes(),
        )?;
    }
    if let Some(out) = &options.out {
        let files = export(
            session,
            out,
            &capture.name,
            frames,
            options.after.as_deref(),
            export_texture,
            &formats,
        )?;
        on(Event::Exported { files });
    }
    Ok(report)
}

pub fn run(path: &Path, options: &ReplayOptions, quiet: bool) -> anyhow::Result<ExitCode> {
    let outputs: Vec<&Path> = options
        .timings
        .iter()
        .chain(&options.trace)
        .map(|p| p.as_path())
        .collect();
    framelab_core::output::check_outputs(&outputs, &[path])?;
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
            let _ = writeln!(std::io::stderr(), "{}", printable(&text));
        } else {
            bar.println(printable(&text));
        }
    };
    let report = replay(path, options, |event| match event {
        Event::Adapter(a) => say(format!("adapter: {a}")),
        Event::Note(n) => say(format!("note: {n}")),
        Event::Frame { index, .. } => bar.set_position(u64::from(index)),
        Event::Exported { files } => say(format!("exported {files} images")),
    });
    bar.finish_and_clear();
    let report = report?;
    if !quiet {
        let rows: Vec<Vec<String>> = report
            .passes
            .iter()
            .map(|p| {
                let gpu = timing::stats::gpu_ms_median_min(p, report.warmup);
                let none = if p.gpu_untrusted.is_some() {
                    "untrusted"
                } else {
                    "-"
                };
                vec![
                    p.name.clone(),
                    p.queue.clone(),
                    gpu.map_or(none.to_owned(), |(median, _)| format!("{median:.3}")),
                    gpu.map_or(none.to_owned(), |(_, min)| format!("{min:.3}")),
                    format!("{:.3}", timing::stats::mean_cpu_ms(p, report.warmup)),
                    format!("{:.1}", p.bytes_moved() as f64 / 1e6),
                    gpu.and_then(|(median, _)| {
                        timing::gigabytes_per_second(p.bytes_moved(), median * 1e6)
                    })
                    .map_or("-".to_owned(), |g| format!("{g:.1}")),
                ]
            })
            .collect();
        let warm = if report.warmup > 0 {
            format!(" (summary after {} warm-up)", report.warmup)
        } else {
            String::new()
        };
        print_stdout(&format!(
            "{} on {} ({}), {} frame(s){warm} at scale {}\n{}",
            report.capture,
            report.adapter,
            report.backend,
            report.frames,
            report.scale,
            framelab_core::text::table(
                &[
                    "pass",
                    "queue",
                    "gpu ms (median)",
                    "gpu ms (min)",
                    "cpu ms (mean)",
                    "MB moved",
                    "GB/s",
                ],
                &rows
            )
        ))?;
        if options.counters && report.passes.iter().any(|p| p.counters.is_some()) {
            print_stdout(&counters_table(&report))?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Each pass's counters in the last frame, the work it submits and the ratios read off them;
/// a pass whose counts changed between frames is marked, as exact counts should not.
fn counters_table(report: &TimingReport) -> String {
    use timing::counters::{Ratios, short};
    let ratio = |r: Option<f64>| r.map_or("-".to_owned(), |r| format!("{r:.2}"));
    let mut varied = 0;
    let rows: Vec<Vec<String>> = report
        .passes
        .iter()
        .map(|p| {
            let work = p.work.clone().unwrap_or_default();
            let last = p.counters.as_ref().and_then(|c| c.last());
            let mut row = vec![p.name.clone(), (work.draws + work.dispatches).to_string()];
            match last {
                Some((c, steady)) => {
                    if !steady {
                        varied += 1;
                    }
                    let r = Ratios::of(&c, &work);
                    row.extend(c.iter().map(|&v| short(v)));
                    row.extend([
                        ratio(r.overdraw),
                        ratio(r.vertices_per_primitive),
                        ratio(r.fragments_per_primitive),
                        ratio(r.invocations_per_thread),
                        if steady { "" } else { "varies" }.to_owned(),
                    ]);
                }
                None => row.extend(std::iter::repeat_n("-".to_owned(), 9).chain([String::new()])),
            }
            row
        })
        .collect();
    let note = if varied > 0 {
        format!("\n{varied} pass(es) counted differently between frames")
    } else {
        String::new()
    };
    format!(
        "work counters (last frame)\n{}{note}",
        framelab_core::text::table(
            &[
                "pass",
                "draws+dispatches",
                "vertex inv",
                "clipper inv",
                "prims out",
                "fragment inv",
                "compute inv",
                "overdraw",
                "verts/prim",
                "frags/prim",
                "inv/thread",
                "",
            ],
            &rows
        )
    )
}

/// Refuses an `--out` that framelab must not replace: anything but a missing or empty folder,
/// or an earlier export holding only the files its manifest lists (an export replaces the
/// whole folder, so a file the user put there would be lost).
fn check_out(out: &Path) -> anyhow::Result<()> {
    if !out.exists() {
        return Ok(());
    }
    if !out.is_dir() {
        bail!("--out {} exists and is not a folder", out.display());
    }
    let entries: Vec<String> = std::fs::read_dir(out)
        .with_context(|| format!("reading {}", out.display()))?
        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect::<Result<_, _>>()
        .with_context(|| format!("reading {}", out.display()))?;
    if entries.is_empty() {
        return Ok(());
    }
    let manifest = out.join("manifest.json");
    let listed: Option<std::collections::BTreeSet<String>> =
        framelab_core::files::read_to_string(&manifest, framelab_core::files::MANIFEST)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .map(|m| {
                let mut names: std::collections::BTreeSet<String> = m["files"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .flat_map(|f| {
                        [
                            f["file"].as_str(),
                            f["preview"].as_str(),
                            f["alpha"].as_str(),
                        ]
                    })
                    .flatten()
                    .map(str::to_owned)
                    .collect();
                names.insert("manifest.json".to_owned());
                names
            });
    let Some(listed) = listed else {
        bail!(
            "{} exists and is not an earlier framelab export (no readable manifest.json); choose another --out",
            out.display()
        );
    };
    let foreign: Vec<&String> = entries.iter().filter(|e| !listed.contains(*e)).collect();
    if !foreign.is_empty() {
        bail!(
            "{} holds {} file(s) the earlier export did not write ({}); framelab replaces the whole folder, so choose another --out or move them",
            out.display(),
            foreign.len(),
            super::first_few(&foreign),
        );
    }
    Ok(())
}

/// Writes every texture (or one) into a staging folder, then replaces `out` with it.
fn export(
    session: &framelab_replay::Session,
    out: &Path,
    capture: &str,
    frames: u32,
    after: Option<&str>,
    only: Option<usize>,
    formats: &[String],
) -> anyhow::Result<usize> {
    use framelab_replay::export;
    let stems = export::unique_stems(&session.plan.textures);
    check_out(out)?;
    let staging = export::staging_dir(out);
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir_all(&staging).with_context(|| format!("creating {}", staging.display()))?;
    let result = (|| -> anyhow::Result<usize> {
        let items: Vec<export::ExportItem<'_>> = session
            .plan
            .textures
            .iter()
            .enumerate()
            .filter(|(i, _)| only.is_none_or(|o| o == *i))
            .map(|(i, spec)| export::ExportItem {
                texture: session.texture(i),
                spec,
                naming: export::Naming {
                    resource: &spec.name,
                    stem: &stems[i],
                    format: formats.get(i).map_or("", String::as_str),
                },
            })
            .collect();
        let (mut files, skipped) =
            export::export_all(&session.device, &session.queue, &items, &staging)?;
        // The frame's presented image, when the frame ran to its end.
        let presented = session.plan.passes.iter().rev().find_map(|p| match p.op {
            framelab_core::plan::PassOp::Present { texture } if after.is_none() => Some(texture),
            _ => None,
        });
        if let Some(t) = presented {
            let name = &session.plan.textures[t].name;
            for f in &mut files {
                f.presented = &f.resource == name && f.mip == 0 && f.layer == 0;
            }
        }
        let manifest = Manifest {
            capture,
            frames,
            after,
            files: &files,
            skipped: &skipped,
        };
        framelab_core::output::write_atomically(
            &staging.join("manifest.json"),
            (serde_json::to_string_pretty(&manifest)? + "\n").as_bytes(),
        )?;
        Ok(files.len())
    })();
    match result {
        Ok(n) => {
            if out.exists() {
                std::fs::remove_dir_all(out)
                    .with_context(|| format!("replacing {}", out.display()))?;
            }
            std::fs::rename(&staging, out)
                .with_context(|| format!("moving the export into {}", out.display()))?;
            Ok(n)
        }
        Err(e) => {
            let _ = std::fs::remove_dir_all(&staging);
            Err(e)
        }
    }
}
