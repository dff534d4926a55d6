//! The fuzz harness for the capture entry point (load, validate, analyse), run by CI for a
//! bounded number of cases: each case mutates a bundled capture structurally (a value replaced
//! by a hostile one, a key dropped, an array element duplicated many times, a subtree nested
//! deep) and feeds it through the same path `framelab analyze` takes. Whatever the input, the
//! result must be a report or a list of diagnostics: no panic, and (by the limits validation
//! enforces) no unbounded time or memory. Every input that ever failed is kept in
//! `tests/fuzz_corpus/` and replayed first. Besides the example, mutations start from the
//! captures of each class of frames a driver rejects.

use std::path::Path;

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::pipeline::{Loaded, Validated};
use proptest::prelude::*;
use serde_json::Value;

use crate::common::{Scratch, repo};

/// Loads, validates and (when valid) analyses `file`; panics only if framelab does.
fn run_entry_point(file: &Path) {
    let options = Options {
        scale: 0.25,
        ..Options::default()
    };
    if let Ok(v) = Validated::load(file, &options) {
        let _ = v.clone().analyse(AnalyzeOptions { cull: true });
        let _ = v.analyse(AnalyzeOptions { cull: false });
    }
}

/// Values a hostile capture puts where a field was.
fn hostile() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::Null),
        Just(serde_json::json!(0)),
        Just(serde_json::json!(-1)),
        Just(serde_json::json!(4_294_967_295u64)),
        Just(serde_json::json!(18_446_744_073_709_551_615u64)),
        Just(serde_json::json!(1e308)),
        Just(serde_json::json!(-1e-308)),
        Just(serde_json::json!(0.5)),
        Just(serde_json::json!("")),
        Just(serde_json::json!("full")),
        Just(serde_json::json!("scene_color")),
        Just(serde_json::json!("R32G8X24_TYPELESS")),
        Just(serde_json::json!("x".repeat(70_000))),
        Just(serde_json::json!([])),
        Just(serde_json::json!({})),
        Just(serde_json::json!([0, 0, 0])),
        Just(serde_json::json!([65535, 65535, 65535])),
        Just(serde_json::json!({"base": 4_000_000_000u64, "count": 4_000_000_000u64})),
        Just(serde_json::json!(true)),
        any::<i64>().prop_map(|v| serde_json::json!(v)),
        "[a-z_]{0,12}".prop_map(Value::String),
    ]
}

/// One structural mutation, steered by `picks` (each pick chooses a child at one level).
#[derive(Clone, Debug)]
enum Mutation {
    Replace(Value),
    Remove,
    Duplicate(usize),
    Nest(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => hostile().prop_map(Mutation::Replace),
        2 => Just(Mutation::Remove),
        1 => (2usize..400).prop_map(Mutation::Duplicate),
        1 => (2usize..300).prop_map(Mutation::Nest),
    ]
}

/// Applies `m` at the node `picks` lead to (stopping early at a leaf).
fn mutate(v: &mut Value, picks: &[usize], m: &Mutation) {
    let child = match (v, picks.split_first()) {
        (Value::Object(map), Some((&pick, rest))) if !map.is_empty() => {
            let key = map
                .keys()
                .nth(pick % map.len())
                .cloned()
                .unwrap_or_default();
            if rest.is_empty() || !map[&key].is_object() && !map[&key].is_array() {
                match m {
                    Mutation::Remove => {
                        map.remove(&key);
                    }
                    other => apply(map.get_mut(&key).unwrap(), other),
                }
                return;
            }
            map.get_mut(&key).unwrap()
        }
        (Value::Array(items), Some((&pick, rest))) if !items.is_empty() => {
            let i = pick % items.len();
            if rest.is_empty() || !items[i].is_object() && !items[i].is_array() {
                match m {
                    Mutation::Remove => {
                        items.remove(i);
                    }
                    Mutation::Duplicate(n) => {
                        let copy = items[i].clone();
                        items.extend(std::iter::repeat_n(copy, *n));
                    }
                    other => apply(&mut items[i], other),
                }
                return;
            }
            &mut items[i]
        }
        (v, _) => {
            apply(v, m);
            return;
        }
    };
    mutate(child, &picks[1..], m);
}

fn apply(v: &mut Value, m: &Mutation) {
    match m {
        Mutation::Replace(x) => *v = x.clone(),
        Mutation::Nest(depth) => {
            for _ in 0..*depth {
                *v = Value::Array(vec![v.take()]);
            }
        }
        Mutation::Remove | Mutation::Duplicate(_) => *v = Value::Null,
    }
}

/// A scratch copy of the example's folder (so side files resolve) for mutated captures, with
/// the invalid corpus's shaders beside it for the captures taken from there.
fn scratch() -> Scratch {
    let dir = Scratch::temp("framelab-fuzz");
    let shaders = dir.join("shaders");
    std::fs::create_dir_all(&shaders).unwrap();
    for e in std::fs::read_dir(repo().join("captures/example/shaders")).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), shaders.join(e.file_name())).unwrap();
    }
    for e in std::fs::read_dir(repo().join("tests/invalid")).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "wgsl") {
            std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
        }
    }
    dir
}

/// What the mutations start from: the example, and one capture of each class of frames a
/// driver rejects that validation once accepted (`tests/invalid/`), so that variants around
/// each class are tried too.
const SOURCES: [&str; 8] = [
    "captures/example/frame.json",
    "captures/example/frame_sync.json",
    "tests/invalid/depth_format_3d.json",
    "tests/invalid/draw_range_wraps.json",
    "tests/invalid/generator_draw_past_mesh.json",
    "tests/invalid/srv_uav_same_subresource.json",
    "tests/invalid/r1_unorm_render_target_clear.json",
    "tests/invalid/typed_buffer_typeless_view.json",
];

/// Each corpus capture runs beside the example's shaders and the corpus's own (`deep.wgsl`).
#[test]
fn every_input_that_ever_failed_now_passes() {
    let corpus = repo().join("tests/fuzz_corpus");
    let dir = scratch();
    for e in std::fs::read_dir(corpus.join("shaders")).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), dir.join("shaders").join(e.file_name())).unwrap();
    }
    let mut seen = 0;
    for e in std::fs::read_dir(&corpus).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "json") {
            let copy = dir.join(path.file_name().unwrap());
            std::fs::copy(&path, &copy).unwrap();
            run_entry_point(&copy);
            seen += 1;
        }
    }
    assert!(seen >= 5, "the corpus has only {seen} inputs");
}

proptest! {
    // Bounded for CI (3,000 cases, seconds: validation's limits keep each case to
    // milliseconds); FRAMELAB_FUZZ_CASES runs longer campaigns.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("FRAMELAB_FUZZ_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(3000),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_captures_never_panic(
        which in 0usize..SOURCES.len(),
        picks in proptest::collection::vec(any::<usize>(), 1..7),
        m in mutation(),
    ) {
        let source = SOURCES[which];
        let mut capture: Value =
            serde_json::from_str(&std::fs::read_to_string(repo().join(source)).unwrap()).unwrap();
        mutate(&mut capture, &picks, &m);
        let dir = scratch();
        let file = dir.join(format!("case-{}.json", std::thread::current().name().unwrap_or("t").replace(':', "_")));
        std::fs::write(&file, serde_json::to_vec(&capture).unwrap()).unwrap();
        run_entry_point(&file);
        let _ = std::fs::remove_file(&file);
    }
}

/// Imports a stream and, when it gives a capture, validates and analyses it as `framelab
/// import` and `analyze` would; panics only if framelab does.
fn run_import(bytes: &[u8], name: &str) {
    use framelab_core::import::{ImportOptions, import};
    let Ok(imported) = import(bytes, name, &ImportOptions::default()) else {
        return;
    };
    let dir = Scratch::temp("framelab-fuzz-import");
    let path = dir.join("imported.json");
    if let Ok(v) = Loaded::from_raw(&path, imported.capture).validate(&Options::default()) {
        let _ = v.clone().analyse(AnalyzeOptions { cull: true });
        let _ = v.analyse(AnalyzeOptions { cull: false });
    }
}

#[test]
fn every_stream_that_ever_failed_now_imports_or_is_refused() {
    let mut seen = 0;
    for e in std::fs::read_dir(repo().join("tests/fuzz_corpus/gfxr")).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "jsonl") {
            run_import(&std::fs::read(&path).unwrap(), &path.display().to_string());
            seen += 1;
        }
    }
    assert!(seen >= 5, "the stream corpus has only {seen} inputs");
}

/// What a hostile stream does to one line.
#[derive(Clone, Debug)]
enum LineMutation {
    /// A structural mutation of the line's JSON.
    Json(Vec<usize>, Mutation),
    /// The line cut after this many bytes.
    Truncate(usize),
    /// The line repeated.
    Repeat(usize),
    /// The call renamed to one no Vulkan version has.
    Rename,
}

fn line_mutation() -> impl Strategy<Value = LineMutation> {
    prop_oneof![
        6 => (proptest::collection::vec(any::<usize>(), 1..8), mutation()).prop_map(|(p, m)| LineMutation::Json(p, m)),
        1 => any::<usize>().prop_map(LineMutation::Truncate),
        1 => (2usize..200).prop_map(LineMutation::Repeat),
        1 => Just(LineMutation::Rename),
    ]
}

proptest! {
    // Bounded for CI like the capture harness; every case is a whole import of a real stream.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("FRAMELAB_FUZZ_CASES").ok().and_then(|c| c.parse::<u32>().ok()).map_or(600, |c| c / 5),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_streams_never_panic(
        which in 0usize..4,
        line in any::<usize>(),
        mutations in proptest::collection::vec(line_mutation(), 1..4),
    ) {
        let name = ["vkd3d_triangle.jsonl", "wgpu30_compute.jsonl", "v1_dynamic_rendering.jsonl", "vkcube_lavapipe.jsonl"][which];
        let text = std::fs::read_to_string(repo().join("tests/fixtures/gfxr").join(name)).unwrap();
        let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
        for m in &mutations {
            let i = line % lines.len();
            match m {
                LineMutation::Json(picks, m) => {
                    if let Ok(mut v) = serde_json::from_str::<Value>(&lines[i]) {
                        mutate(&mut v, picks, m);
                        lines[i] = serde_json::to_string(&v).unwrap();
                    }
                }
                LineMutation::Truncate(at) => {
                    let cut = lines[i].floor_char_boundary(at % (lines[i].len() + 1));
                    lines[i].truncate(cut);
                }
                LineMutation::Repeat(n) => {
                    let copy = lines[i].clone();
                    lines.splice(i..i, std::iter::repeat_n(copy, *n));
                }
                LineMutation::Rename => lines[i] = lines[i].replacen("\"vk", "\"vkNoSuch", 1),
            }
        }
        run_import(lines.join("\n").as_bytes(), name);
    }
}
