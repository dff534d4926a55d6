//! Every capture in `tests/invalid/` must be rejected with exit code 1 and the diagnostic
//! `expected.json` names (code, JSON path, message fragment), both in `--json` output and in
//! the human-readable stderr. A file without an expectation fails the test, so the corpus and
//! its expectations cannot drift apart.

use std::collections::BTreeSet;

use crate::common::{Scratch, framelab, json, repo, stderr};

#[derive(serde::Deserialize)]
struct Case {
    file: String,
    code: String,
    path: String,
    message: String,
}

fn cases() -> Vec<Case> {
    let text = std::fs::read_to_string(repo().join("tests/invalid/expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn corpus_is_large_and_fully_described() {
    let cases = cases();
    assert!(cases.len() >= 25, "only {} invalid captures", cases.len());
    let described: BTreeSet<String> = cases.iter().map(|c| c.file.clone()).collect();
    assert_eq!(described.len(), cases.len(), "a file is described twice");
    let on_disk: BTreeSet<String> = std::fs::read_dir(repo().join("tests/invalid"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".json") && n != "expected.json")
        .collect();
    assert_eq!(on_disk, described, "files and expectations differ");
}

#[test]
fn every_invalid_capture_is_rejected_with_its_diagnostic() {
    let mut failures = Vec::new();
    for case in cases() {
        let file = format!("tests/invalid/{}", case.file);
        let out = framelab(&["validate", "--json", &file]);
        if out.status.code() != Some(1) {
            failures.push(format!(
                "{}: exit {:?}, expected 1",
                case.file,
                out.status.code()
            ));
            continue;
        }
        let report = json(&out);
        assert_eq!(report["valid"], false, "{}", case.file);
        let found = report["diagnostics"].as_array().unwrap().iter().any(|d| {
            d["code"] == case.code.as_str()
                && d["path"] == case.path.as_str()
                && d["message"].as_str().unwrap().contains(&case.message)
        });
        if !found {
            failures.push(format!(
                "{}: no diagnostic [{}] at {} containing {:?}; got {}",
                case.file,
                case.code,
                case.path,
                case.message,
                serde_json::to_string_pretty(&report["diagnostics"]).unwrap()
            ));
        }
        let human = framelab(&["validate", &file]);
        assert_eq!(human.status.code(), Some(1), "{}", case.file);
        let err = stderr(&human);
        if !err.contains(&case.message) || !err.contains(&case.file) {
            failures.push(format!(
                "{}: stderr lacks the file name or {:?}:\n{err}",
                case.file, case.message
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn misspelled_names_get_suggestions() {
    let out = framelab(&[
        "validate",
        "--json",
        "tests/invalid/misspelled_resource.json",
    ]);
    let report = json(&out);
    let d = &report["diagnostics"][0];
    assert_eq!(d["suggestion"], "data");
    let human = stderr(&framelab(&[
        "validate",
        "tests/invalid/misspelled_resource.json",
    ]));
    assert!(
        human.contains("$.passes[0].bindings.particles.resource"),
        "{human}"
    );
    assert!(human.contains("did you mean \"data\"?"), "{human}");

    let format = json(&framelab(&[
        "validate",
        "--json",
        "tests/invalid/unknown_format.json",
    ]));
    assert_eq!(format["diagnostics"][0]["suggestion"], "R8G8B8A8_UNORM");
}

#[test]
fn validation_reports_all_errors_at_once() {
    // Two independent mistakes in one file: both are reported.
    let dir = tempdir();
    let mut capture: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo().join("tests/fixtures/minimal.json")).unwrap(),
    )
    .unwrap();
    capture["resources"][0]["format"] = "R8G8B8A8_UNROM".into();
    capture["passes"][1]["queue"] = "dmaa".into();
    let file = dir.join("two_errors.json");
    std::fs::write(&file, serde_json::to_string(&capture).unwrap()).unwrap();
    let report = json(&framelab(&["validate", "--json", file.to_str().unwrap()]));
    let codes: Vec<&str> = report["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap())
        .collect();
    assert!(
        codes.contains(&"unknown-format") && codes.contains(&"unknown-queue"),
        "{codes:?}"
    );
}

fn tempdir() -> Scratch {
    Scratch::temp("framelab-test")
}
