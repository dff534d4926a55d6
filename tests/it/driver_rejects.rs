//! Frames a driver would reject, walked as classes rather than one example each: every variant
//! is an edit of the bundled example capture, validated in process, and must be refused with
//! the expected diagnostic code at the expected JSON path.

use std::path::Path;

use framelab_core::capture::load::parse;
use framelab_core::capture::validate::validate;
use framelab_core::capture::{CaptureError, Diagnostic, Options};
use serde_json::{Value, json};

use crate::common::repo;

fn example() -> Value {
    let text = std::fs::read_to_string(repo().join("captures/example/frame.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The errors `capture` gets, validated as if it were the example file (its side files resolve).
fn errors(capture: &Value) -> Vec<Diagnostic> {
    let path = repo().join("captures/example/frame.json");
    let bytes = serde_json::to_vec(capture).unwrap();
    let raw = match parse(Path::new(&path), &bytes) {
        Ok(raw) => raw,
        Err(e) => panic!("edited capture does not parse: {e}"),
    };
    match validate(&raw, &path, &Options::default()) {
        Ok(_) => Vec::new(),
        Err(CaptureError::Invalid { diagnostics, .. }) => diagnostics
            .into_iter()
            .filter(|d| d.severity == framelab_core::capture::Severity::Error)
            .collect(),
        Err(e) => panic!("unexpected error: {e}"),
    }
}

fn has(errors: &[Diagnostic], code: &str, path: &str) -> bool {
    errors.iter().any(|d| d.code == code && d.path == path)
}

const NEAR: u32 = u32::MAX - 7;

/// Pass 4 ("scene") draws the indexed generator mesh "ground" (draw 0) and the indexed "orb"
/// through indirect arguments (draw 1); pass 5 draws a full-screen triangle without a mesh.
#[test]
fn draw_ranges_past_32_bits_are_refused() {
    // (pass, draw, fields set on the draw, path of the error)
    let direct: &[(usize, usize, Value, &str)] = &[
        // indexed: first index near 2^32 plus a count
        (4, 0, json!({"first": NEAR, "count": 96}), "count"),
        (4, 0, json!({"first": u32::MAX, "count": 1}), "count"),
        (4, 0, json!({"first": 1, "count": u32::MAX}), "count"),
        (4, 0, json!({"first": u32::MAX, "count": u32::MAX}), "count"),
        // non-indexed, no mesh: first vertex plus count
        (5, 0, json!({"first": NEAR, "count": 96}), "count"),
        (5, 0, json!({"first": u32::MAX, "count": 3}), "count"),
        (5, 0, json!({"first": 2, "count": u32::MAX}), "count"),
        // instanced: first instance plus instances, with and without a mesh
        (
            4,
            0,
            json!({"first_instance": NEAR, "instances": 16}),
            "first_instance",
        ),
        (
            4,
            0,
            json!({"first_instance": u32::MAX, "instances": 2}),
            "first_instance",
        ),
        (
            5,
            0,
            json!({"first_instance": NEAR, "instances": 16}),
            "first_instance",
        ),
        (
            5,
            0,
            json!({"first_instance": u32::MAX, "instances": 2}),
            "first_instance",
        ),
    ];
    let mut missed = Vec::new();
    for (pass, draw, fields, field) in direct {
        let mut c = example();
        let d = &mut c["passes"][*pass]["draws"][*draw];
        for (k, v) in fields.as_object().unwrap() {
            d[k] = v.clone();
        }
        let path = format!("$.passes[{pass}].draws[{draw}].{field}");
        let errs = errors(&c);
        if !has(&errs, "draw", &path) {
            missed.push(format!("{fields} on {path}: {errs:?}"));
        }
    }
    // Indirect arguments: offset plus the record's size near the u64 limit, and past the end.
    let offsets = [u64::MAX - 3, u64::MAX - 15, u64::MAX - 19, 1 << 63, !3];
    for offset in offsets {
        let mut c = example();
        c["passes"][4]["draws"][1]["indirect"]["offset"] = json!(offset);
        let path = "$.passes[4].draws[1].indirect.offset";
        let errs = errors(&c);
        if !has(&errs, "indirect", path) {
            missed.push(format!("indirect offset {offset}: {errs:?}"));
        }
    }
    assert!(missed.is_empty(), "accepted:\n{}", missed.join("\n"));
    // The unedited capture is valid, so each refusal above is the edit's.
    assert!(errors(&example()).is_empty());
}
