//! The frame cursor on the example frame at a small scale: a held frame runs on from where it
//! stands (submitting only the passes between) and reaches the contents a fresh hold reaches;
//! an earlier pass, a pass run part way or a frame that does not follow the last whole one
//! starts again; names resolve to the plan's or are refused by kind. And the worker thread's
//! handle: jobs reach it, a stopped one refuses them, dropping it waits for it.

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::pipeline::Analysed;
use framelab_replay::decode;
use framelab_replay::{NameError, Open, ReplayError, Replaying, Worker};

fn example() -> Replaying {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../captures/example/frame.json");
    let options = Options {
        scale: 0.125,
        ..Options::default()
    };
    let analysed = Analysed::for_replay(&path, &options, AnalyzeOptions { cull: false }).unwrap();
    let ctx = framelab_replay::open_device(None, framelab_core::lower::wanted_features())
        .unwrap_or_else(|e| panic!("no usable GPU adapter: {e}"));
    let lowered = analysed
        .lower(ctx.device.features(), &ctx.summary.name)
        .unwrap();
    Replaying::start(&ctx, lowered).unwrap()
}

/// Holds `frame` at `done` passes, returning the passes submitted on the way.
fn hold(r: &mut Replaying, frame: u32, done: usize) -> Vec<usize> {
    let mut submitted = Vec::new();
    r.hold(frame, done, |i| {
        submitted.push(i);
        Ok::<(), ReplayError>(())
    })
    .unwrap();
    submitted
}

/// Mip 0, layer 0 of every readable plan texture as it stands in the open frame (the bits of
/// its values, so that NaN equals NaN).
fn textures(r: &Replaying) -> Vec<Vec<u32>> {
    let s = &r.session;
    let mut read = Vec::new();
    for (t, spec) in s.plan.textures.iter().enumerate() {
        let Ok(format) = decode::readable_format(spec) else {
            continue;
        };
        let texture = s.texture_in_frame(t);
        for image in
            decode::read_subresource(&s.device, &s.queue, texture, spec, format, 0, 0).unwrap()
        {
            read.push(image.values.iter().flatten().map(|v| v.to_bits()).collect());
        }
    }
    read
}

#[test]
fn a_held_frame_runs_on_to_what_a_fresh_hold_reaches() {
    let mut a = example();
    let passes = a.session.plan.passes.len();
    assert!(passes >= 6, "the example has {passes} passes");
    let (first, then) = (2, passes - 2);
    assert_eq!(hold(&mut a, 0, first), (0..first).collect::<Vec<_>>());
    // Runs on: only the passes between are submitted.
    assert_eq!(hold(&mut a, 0, then), (first..then).collect::<Vec<_>>());
    assert_eq!(
        a.open(),
        Some(Open {
            frame: 0,
            done: then,
            partial: None
        })
    );
    let mut b = example();
    assert_eq!(hold(&mut b, 0, then).len(), then);
    let (ta, tb) = (textures(&a), textures(&b));
    assert!(ta.len() >= 4, "{} textures read", ta.len());
    assert!(ta == tb, "the textures differ from a fresh hold's");
}

#[test]
fn an_earlier_pass_or_a_pass_run_part_way_starts_the_frame_again() {
    let mut r = example();
    hold(&mut r, 0, 4);
    assert_eq!(
        hold(&mut r, 0, 1),
        vec![0],
        "an earlier pass begins the frame"
    );
    r.step(0, 3, 0).unwrap();
    assert_eq!(r.open().unwrap().partial, Some(3));
    // Pass 3 is part way: running on would run it over what it already wrote.
    assert_eq!(hold(&mut r, 0, 5), (0..5).collect::<Vec<_>>());
    r.step(0, 5, 0).unwrap();
    r.restored();
    assert_eq!(hold(&mut r, 0, 6), vec![5], "put back, it runs on");
}

#[test]
fn a_frame_follows_the_last_whole_frame_or_those_before_it_run_first() {
    let mut r = example();
    let passes = r.session.plan.passes.len();
    r.run_whole(0).unwrap();
    assert_eq!(r.session.frames_run(), 1);
    hold(&mut r, 1, 2);
    assert_eq!(r.session.frames_run(), 1, "frame 1 follows frame 0 at once");
    // Ending frame 1 part way leaves no whole frame before a new frame 1: frame 0 runs first.
    r.release();
    assert_eq!(r.session.frames_run(), 2);
    hold(&mut r, 1, 2);
    assert_eq!(
        r.session.frames_run(),
        3,
        "frame 0 ran again, then frame 1 began"
    );
    // Frame 1 run to its end counts as whole: frame 2 follows it.
    hold(&mut r, 1, passes);
    r.release();
    hold(&mut r, 2, 1);
    assert_eq!(r.session.frames_run(), 4);
    // A whole frame run ends the open one.
    r.run_whole(5).unwrap();
    assert_eq!(r.open(), None);
    assert_eq!(r.session.frames_run(), 6);
}

#[test]
fn names_resolve_to_the_plan_or_are_refused_by_kind() {
    let r = example();
    let capture = r.capture();
    let pass = capture.pass(r.pass_ids[1]);
    assert_eq!(r.plan_pass(&pass.name), Ok(1));
    assert_eq!(
        r.plan_pass("no such pass"),
        Err(NameError::NoPass("no such pass".into()))
    );
    let texture = capture.resources.iter().find(|x| x.is_texture()).unwrap();
    let buffer = capture.resources.iter().find(|x| !x.is_texture()).unwrap();
    let t = r.plan_texture(&texture.name).unwrap();
    assert_eq!(r.session.plan.textures[t].name, texture.name);
    assert!(r.plan_buffer(&buffer.name).is_ok());
    assert_eq!(
        r.plan_buffer(&texture.name),
        Err(NameError::NotReplayed {
            name: texture.name.clone(),
            kind: "buffer"
        })
    );
    assert_eq!(
        r.plan_texture("nothing"),
        Err(NameError::NoResource("nothing".into()))
    );
}

#[test]
fn the_worker_takes_jobs_until_it_stops_and_is_waited_for() {
    let (tx, rx) = std::sync::mpsc::channel();
    let worker = Worker::start(
        "test-worker",
        move |jobs: std::sync::mpsc::Receiver<u32>| {
            // Serves two jobs, then stops.
            for _ in 0..2 {
                let Ok(j) = jobs.recv() else { return };
                tx.send(j * 10).unwrap();
            }
        },
    );
    assert!(worker.send(1));
    assert!(worker.send(2));
    assert_eq!((rx.recv().unwrap(), rx.recv().unwrap()), (10, 20));
    // Once its loop is over, the channel is closed and jobs are refused.
    while rx.recv().is_ok() {}
    assert!(!worker.send(3));
    let (tx, rx) = std::sync::mpsc::channel();
    let long = Worker::start("test-worker", move |jobs: std::sync::mpsc::Receiver<()>| {
        while jobs.recv().is_ok() {}
        std::thread::sleep(std::time::Duration::from_millis(50));
        tx.send("done").unwrap();
    });
    drop(long);
    assert_eq!(
        rx.try_recv(),
        Ok("done"),
        "dropping the handle waited for the thread"
    );
}
