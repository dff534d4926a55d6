//! `framelab inspect`: opens the inspector over a capture replayed on the chosen device, in a
//! window, or off-screen to write a screenshot (`--screenshot`, with the pass and resource to
//! select), for documentation and tests.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use std::io::Write;

use anyhow::{Context, bail};
use framelab_core::capture::Options;
use framelab_core::lower;
use framelab_core::pipeline::{Analysed, Loaded};
use framelab_core::text::printable;
use framelab_core::timing::TimingReport;
use framelab_core::whatif::{Edit, variant};
use framelab_ui::Inspector;
use framelab_ui::app::Pane;
use framelab_ui::headless;
use framelab_ui::project::{self, Reports};

use super::parse_scale;
use super::stages;

#[derive(Debug, Clone, clap::Args)]
pub struct InspectArgs {
    /// The capture (JSON).
    pub capture: PathBuf,
    /// Output-resolution multiplier.
    #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
    pub scale: f64,
    /// A timing report (`replay --timings`) for the timeline, instead of the inspector's own
    /// timed frames.
    #[arg(long)]
    pub timings: Option<PathBuf>,
    /// A second timing report: each pass shows its time there and the diff's verdict.
    #[arg(long, requires = "timings")]
    pub compare: Option<PathBuf>,
    /// A second capture (or this one again) replayed beside this one at the same scale: the
    /// Image diff panel shows the viewed texture after the current pass in both, paired as the
    /// structural diff pairs passes, and FLIP's error map between them.
    #[arg(long)]
    pub against: Option<PathBuf>,
    /// What-if edits (as `framelab what-if` takes them): the frame they make is replayed
    /// beside this one, as `--against` does with a second capture, after its static verdict is
    /// printed.
    #[command(flatten)]
    pub edits: super::what_if::EditArgs,
    /// Use the adapter whose name contains this text.
    #[arg(long)]
    pub adapter: Option<String>,
    /// Render the window off-screen into this PNG and exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// The pass to make current (default: the last).
    #[arg(long)]
    pub select: Option<String>,
    /// The resource to open: a texture in the texture viewer, a buffer in the buffer viewer.
    #[arg(long)]
    pub view: Option<String>,
    /// The panel to bring to the front of its tab group: Timeline, Resources, Buffer, DAG or
    /// Memory.
    #[arg(long, value_parser = parse_pane)]
    pub panel: Option<Pane>,
    /// Show the stencil aspect of the `--view` depth-stencil texture.
    #[arg(long, requires = "view")]
    pub stencil: bool,
    /// The texel to read out, X,Y (as a click on the texture would pick it).
    #[arg(long, value_parser = parse_pixel)]
    pub pixel: Option<(u32, u32)>,
    /// Show the frame as of this draw or dispatch of the `--select` pass (its index among
    /// them, from 0), as selecting it in the event list does.
    #[arg(long, requires = "select")]
    pub draw: Option<usize>,
    /// Ask for the history of the `--pixel` texel of the `--view` texture (the History panel).
    #[arg(long, requires_all = ["pixel", "view"])]
    pub history: bool,
    /// Colour the timeline by a work counter (vertex_invocations, clipper_invocations,
    /// clipper_primitives_out, fragment_invocations, compute_invocations) or overdraw.
    #[arg(long, value_parser = parse_measure)]
    pub color_by: Option<usize>,
    /// Window size in points, WxH (screenshots).
    #[arg(long, default_value = "1600x900", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Whole frames timed: the first before the browsed frame replays, the rest after it.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub frames: u32,
    /// Memory for the copies of what each pass writes, in MiB: a pass whose copies fit is shown
    /// without a replay; one evicted costs a replay up to it.
    #[arg(long, default_value_t = project::DEFAULT_BUDGET >> 20,
          value_parser = clap::value_parser!(u64).range(1..=1 << 20))]
    pub cache_mb: u64,
}

fn parse_size(text: &str) -> anyhow::Result<(u32, u32)> {
    let (w, h) = text
        .split_once('x')
        .ok_or_else(|| anyhow::anyhow!("\"{text}\" is not WxH"))?;
    let parse = |s: &str| s.parse::<u32>().ok().filter(|v| (64..=8192).contains(v));
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(anyhow::anyhow!(
            "\"{text}\": width and height must be 64..8192"
        )),
    }
}

fn parse_pane(text: &str) -> anyhow::Result<Pane> {
    Pane::ALL
        .into_iter()
        .find(|p| p.title().eq_ignore_ascii_case(text))
        .ok_or_else(|| {
            let names: Vec<&str> = Pane::ALL.iter().map(|p| p.title()).collect();
            anyhow::anyhow!("\"{text}\" is not a panel ({})", names.join(", "))
        })
}

fn parse_pixel(text: &str) -> anyhow::Result<(u32, u32)> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| anyhow::anyhow!("\"{text}\" is not X,Y"))?;
    match (x.trim().parse(), y.trim().parse()) {
        (Ok(x), Ok(y)) => Ok((x, y)),
        _ => Err(anyhow::anyhow!("\"{text}\": X and Y must be whole numbers")),
    }
}

/// A second frame with the pass pairs between the first and it.
type Second = (Analysed, Vec<(usize, usize, bool)>);

fn report(path: &Path) -> anyhow::Result<TimingReport> {
    let text = framelab_core::files::read_to_string(path, framelab_core::files::TIMING_REPORT)?;
    Ok(TimingReport::from_json(&path.display().to_string(), &text)?)
}

/// The frame and the variant the edits make of it, its static verdict printed; the variant
/// named by its edits, so the image diff says which side it is.
fn what_if(args: &InspectArgs, edits: &[Edit]) -> anyhow::Result<(Analysed, Analysed)> {
    if args.against.is_some() {
        bail!("--against and what-if edits each give the second frame: give one of them");
    }
    let loaded = Loaded::read_hashed(&args.capture).map_err(stages::device_error)?;
    let options = Options {
        scale: args.scale,
        ..Options::default()
    };
    let mut pair = variant(loaded, None, edits, &options).map_err(stages::variant_error)?;
    let verdict = framelab_core::whatif::verdict(&pair);
    let mut said = pair.changes.join("; ");
    if verdict.safe() {
        said.push_str("; static: safe");
    } else {
        let errors: Vec<String> = verdict
            .errors()
            .map(|l| format!("{} {}", l.code, l.message))
            .collect();
        said.push_str(&format!("; static: UNSAFE: {}", errors.join("; ")));
    }
    if let Some(note) = &verdict.note {
        said.push_str(&format!(" ({note})"));
    }
    let _ = writeln!(std::io::stderr(), "what if: {}", printable(&said));
    let spelt: Vec<String> = edits.iter().map(Edit::spelling).collect();
    pair.variant.capture.name = format!(
        "{} (what if {})",
        pair.variant.capture.name,
        spelt.join(" ")
    );
    Ok((pair.frame, pair.variant))
}

/// The frame, and the second one to replay beside it with the pass pairs: the variant of the
/// what-if edits, or the `--against` capture.
fn frames(args: &InspectArgs) -> anyhow::Result<(Analysed, Option<Second>)> {
    let edits = args.edits.edits();
    let (analysed, variant) = if edits.is_empty() {
        (
            stages::analysed_for_device(&args.capture, args.scale, false)?,
            None,
        )
    } else {
        let (a, b) = what_if(args, &edits)?;
        (a, Some(b))
    };
    let against = match (&args.against, variant) {
        (_, Some(b)) => {
            if b.capture.not_replayable().is_some() {
                bail!(
                    "{} is not replayed, so its variant has no images to compare",
                    args.capture.display()
                );
            }
            let pairs = framelab_core::whatif::pass_pairs(&analysed.capture, &b.capture);
            Some((b, pairs))
        }
        (Some(path), None) => {
            let b = stages::analysed_for_device(path, args.scale, false)?;
            if b.capture.not_replayable().is_some() {
                bail!(
                    "--against: {} is not replayed, so it has no images to compare",
                    path.display()
                );
            }
            let pairs = framelab_core::structure::pass_pairs(&analysed.capture, &b.capture);
            Some((b, pairs))
        }
        (None, None) => None,
    };
    Ok((analysed, against))
}

/// The pass and resource the command line names, as positions in the inspector's model, and
/// every choice that cannot be shown refused by name.
fn chosen(
    args: &InspectArgs,
    model: &framelab_ui::model::Inspection,
    not_replayed: bool,
    select_id: Option<(&String, Option<framelab_core::capture::model::PassId>)>,
    view_id: Option<(&String, Option<framelab_core::capture::model::ResourceId>)>,
) -> anyhow::Result<(Option<usize>, Option<usize>)> {
    let select = match select_id {
        Some((name, id)) => Some(id.and_then(|id| model.pass_position(id)).with_context(|| {
            let names: Vec<&str> = model.passes.iter().map(|p| p.name.as_str()).collect();
            format!(
                "--select: no pass \"{name}\" (passes: {})",
                names.join(", ")
            )
        })?),
        None => None,
    };
    let view = match view_id {
        Some((name, id)) => Some(
            id.and_then(|id| model.resource_position(id))
                .with_context(|| format!("--view: no resource \"{name}\" in {}", model.capture))?,
        ),
        None => None,
    };
    if let Some(v) = view
        && model.resources[v].texture.is_none()
        && model.resources[v].buffer.is_none()
    {
        bail!(
            "--view: \"{}\" is neither a texture nor a buffer the replay creates{}",
            model.resources[v].name,
            if not_replayed {
                " (an imported capture is not replayed)"
            } else {
                ""
            }
        );
    }
    if let Some(v) = view
        && args.stencil
        && !model.resources[v]
            .texture
            .as_ref()
            .is_some_and(|t| t.stencil || t.sampling == framelab_ui::model::Sampling::Stencil)
    {
        bail!(
            "--stencil: \"{}\" has no stencil aspect the viewer can read",
            model.resources[v].name
        );
    }
    if let (Some(p), Some(d)) = (select, args.draw) {
        let steps = model.passes[p].steps;
        if d >= steps {
            bail!(
                "--draw {d}: pass \"{}\" has {steps} draws or dispatches",
                model.passes[p].name
            );
        }
    }
    Ok((select, view))
}

pub fn run(args: &InspectArgs) -> anyhow::Result<ExitCode> {
    let (analysed, against) = frames(args)?;
    let timings = args.timings.as_deref().map(report).transpose()?;
    let compare = args.compare.as_deref().map(report).transpose()?;
    let reports = Reports {
        timings: timings
            .as_ref()
            .zip(args.timings.as_ref())
            .map(|(t, p)| (t, p.display().to_string())),
        compare: compare
            .as_ref()
            .zip(args.compare.as_ref())
            .map(|(t, p)| (t, p.display().to_string())),
    };
    // Names from the command line become capture ids once, before the device opens.
    let c = &analysed.capture;
    let select_id = args.select.as_ref().map(|name| {
        let id = c.passes.iter().find(|p| &p.name == name).map(|p| p.id);
        (name, id)
    });
    let view_id = args.view.as_ref().map(|name| {
        let id = c.resources.iter().find(|r| &r.name == name).map(|r| r.id);
        (name, id)
    });
    let ctx = framelab_replay::open_device(args.adapter.as_deref(), lower::wanted_features())?;
    // Off-screen, egui draws with a device of its own on the same adapter; a window draws
    // with OpenGL.
    let render_state = match &args.screenshot {
        Some(_) => Some(headless::render_state(&ctx)?),
        None => None,
    };
    if against.is_some() && analysed.capture.not_replayable().is_some() {
        bail!(
            "--against: {} is not replayed, so it has no images to compare",
            args.capture.display()
        );
    }
    let options = project::LaunchOptions {
        frames: args.frames,
        budget: args.cache_mb << 20,
    };
    // The second capture on a device of its own, so neither replay waits on the other's queue.
    let against = match against {
        Some((b, pairs)) => {
            let ctx_b =
                framelab_replay::open_device(args.adapter.as_deref(), lower::wanted_features())?;
            let (model_b, worker_b) = project::launch(b, ctx_b, &Reports::default(), options)?;
            Some((model_b, pairs, worker_b))
        }
        None => None,
    };
    // An imported capture is inspected without a replay: passes, barriers, DAG and memory.
    let (model, worker) = if analysed.capture.not_replayable().is_some() {
        let model = project::model_without_replay(&analysed, &reports)?;
        (model, None)
    } else {
        let (model, worker) = project::launch(analysed, ctx, &reports, options)?;
        (model, Some(worker))
    };
    let (select, view) = chosen(args, &model, worker.is_none(), select_id, view_id)?;
    let stencil = args.stencil;
    let pixel = args.pixel;
    let (draw, history) = (args.draw, args.history);
    let panel = args.panel;
    let color_by = args.color_by;
    let against = against.map(|(model_b, pairs, worker_b)| {
        (
            framelab_ui::against::Against::new(&model, model_b, &pairs),
            worker_b,
        )
    });
    let prepare = move |app: &mut Inspector| {
        if let Some(p) = select {
            app.select_pass(p);
        }
        if let Some(r) = view {
            app.open_resource(r);
            if stencil {
                app.show_aspect(true);
            }
        }
        if let (Some(p), Some(d)) = (select, draw) {
            app.expanded_pass(p);
            app.select_step(p, d);
        }
        if let Some((x, y)) = pixel {
            app.pick(x, y);
        }
        if history {
            app.request_history();
        }
        if let Some(p) = panel {
            app.show_pane(p);
        }
        if let Some(m) = color_by {
            app.color_timeline_by(m);
        }
    };
    match (&args.screenshot, render_state) {
        (Some(path), Some(rs)) => {
            let mut app = Inspector::new(model, worker);
            if let Some((a, w)) = against {
                app = app.with_against(a, w);
            }
            prepare(&mut app);
            let size = framelab_ui::egui::Vec2::new(args.size.0 as f32, args.size.1 as f32);
            let image = headless::capture(app, rs, size, Duration::from_secs(600))?;
            headless::save_png(&image, path)?;
            Ok(ExitCode::SUCCESS)
        }
        _ => {
            let title = format!("framelab inspect {}", args.capture.display());
            headless::window(&title, move || {
                let mut app = Inspector::new(model, worker);
                if let Some((a, w)) = against {
                    app = app.with_against(a, w);
                }
                prepare(&mut app);
                app
            })?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn parse_measure(s: &str) -> anyhow::Result<usize> {
    let measures = framelab_ui::panels::work::MEASURES;
    measures
        .iter()
        .position(|m| *m == s)
        .ok_or_else(|| anyhow::anyhow!("not a measure; one of {}", measures.join(", ")))
}
