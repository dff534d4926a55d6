//! `--merge` on Night City: two passes compositing into one target made one render pass, and
//! every reason two passes cannot be one named.

use std::path::{Path, PathBuf};

use super::merge::{Unmergeable, within};
use super::*;
use crate::analysis::report::AnalyzeOptions;
use crate::capture::Options;
use crate::capture::format::RawCapture;
use crate::pipeline::{Analysed, Loaded};

fn path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../captures/night_city/main_street_day.json")
}

fn options() -> Options {
    Options {
        scale: 0.25,
        ..Options::default()
    }
}

fn analysed(raw: RawCapture) -> Analysed {
    Loaded::from_raw(&path(), raw)
        .validate(&options())
        .unwrap()
        .analyse(AnalyzeOptions { cull: false })
        .unwrap()
}

fn raw() -> RawCapture {
    Loaded::read(&path()).unwrap().raw
}

/// The edits applied to `raw`, judged against it.
fn merged(raw: RawCapture, edit: &str) -> Result<(Analysed, Analysed, Vec<String>), EditError> {
    let frame = analysed(raw.clone());
    let edits = [Edit::merge(edit).unwrap()];
    let (edited, said) = apply(&raw, &frame.capture, &frame.analysis.lints, &edits)?;
    Ok((frame, analysed(edited), said))
}

fn refused(raw: RawCapture, edit: &str) -> String {
    match merged(raw, edit) {
        Err(e @ EditError::CannotMerge { .. }) => e.to_string(),
        other => panic!("{edit}: {:?}", other.map(|(_, _, s)| s)),
    }
}

#[test]
fn two_passes_blending_into_one_target_become_one_render_pass() {
    let (a, b, said) = merged(raw(), "gi_shadow+volumetric_fog").unwrap();
    assert_eq!(
        said,
        [
            "passes \"gi_shadow\" and \"volumetric_fog\" merged into one render pass \"gi_shadow+volumetric_fog\""
        ]
    );
    assert_eq!(b.capture.passes.len() + 1, a.capture.passes.len());
    let p = b
        .capture
        .passes
        .iter()
        .find(|p| p.name == "gi_shadow+volumetric_fog")
        .unwrap();
    assert_eq!(p.draws.len(), 2);
    // Each draw keeps its own fragment entry point; the bindings of both are the pass's.
    let names: Vec<&str> = p.bindings.iter().map(|b| b.variable.as_str()).collect();
    for v in ["skin_irradiance", "fog_volume", "linear_clamp"] {
        assert!(names.contains(&v), "{names:?}");
    }
    // Where it stands: after what gi_shadow came after, before what followed volumetric_fog.
    let at = |c: &crate::capture::model::Capture, n: &str| {
        c.passes.iter().position(|p| p.name == n).unwrap()
    };
    assert_eq!(
        at(&b.capture, "gi_shadow+volumetric_fog"),
        at(&a.capture, "gi_shadow")
    );
    assert_eq!(
        at(&b.capture, "water_reflection"),
        at(&a.capture, "water_reflection") - 1
    );
    let v = static_verdict(&a.capture, &a.analysis.lints, &b.capture, &b.analysis.lints);
    assert!(v.safe(), "{:?}", v.introduced);
    // The merged pass ends as the second did; the first has no counterpart.
    let into = merged_into(&a.capture, &b.capture);
    assert_eq!(into.len(), 1);
    assert_eq!(into["volumetric_fog"], "gi_shadow+volumetric_fog");
    let pairs = pass_pairs(&a.capture, &b.capture);
    let pair_of = |n: &str| {
        let i = at(&a.capture, n);
        pairs.iter().find(|p| p.0 == i).map(|p| (p.1, p.2))
    };
    assert_eq!(
        pair_of("volumetric_fog"),
        Some((at(&b.capture, "gi_shadow+volumetric_fog"), true))
    );
    assert_eq!(pair_of("gi_shadow"), None);
    assert_eq!(
        pair_of("water_reflection"),
        Some((at(&b.capture, "water_reflection"), false))
    );
    assert_eq!(pairs.len(), a.capture.passes.len() - 1);
}

#[test]
fn passes_on_other_targets_or_kinds_or_clearing_do_not_merge() {
    let r = refused(raw(), "csm_cascade_0+csm_cascade_1");
    assert!(
        r.contains("one render pass has one set of attachments"),
        "{r}"
    );
    assert!(r.contains("layer 1"), "{r}");
    let r = refused(raw(), "light_composition+gi_shadow");
    assert!(r.contains("\"composite_specular\""), "{r}");
    let r = refused(raw(), "volumetric_fog+indirect_light");
    assert!(r.contains("\"indirect_light\" is a compute pass"), "{r}");
    let r = refused(raw(), "omni_shadows_0+omni_shadows_1");
    assert!(
        r.starts_with("--merge omni_shadows_0+omni_shadows_1: \"omni_shadows_1\" clears"),
        "{r}"
    );
    assert!(matches!(
        merged(raw(), "gi_shadow+nope"),
        Err(EditError::UnknownPass { .. })
    ));
    assert!(Edit::merge("gi_shadow").is_err());
    assert!(Edit::merge("gi_shadow+gi_shadow").is_err());
}

#[test]
fn a_pass_between_them_that_the_second_depends_on_stops_the_merge() {
    // A second fog pass after water_reflection, which reads the composite it would write.
    let mut r = raw();
    let fog = r
        .passes
        .iter()
        .find(|p| p.name == "volumetric_fog")
        .unwrap()
        .clone();
    let after = r
        .passes
        .iter()
        .position(|p| p.name == "water_reflection")
        .unwrap();
    let mut again = fog;
    again.name = "fog_again".into();
    r.passes.insert(after + 1, again);
    let e = refused(r, "volumetric_fog+fog_again");
    assert!(
        e.contains("\"water_reflection\", recorded between them, reads \"composite\", which \"fog_again\" writes"),
        "{e}"
    );
}

#[test]
fn shader_accesses_one_pass_writes_and_the_other_uses_cannot_share_a_render_pass() {
    let a = analysed(raw());
    let pass = |n: &str| a.capture.passes.iter().find(|p| p.name == n).unwrap();
    // The tiled lighting writes lit_diffuse from its shader; the sky renders into it.
    let e = within(&a.capture, pass("tiled_direct_lighting"), pass("sky")).unwrap_err();
    assert_eq!(
        e,
        Unmergeable::Within {
            writer: "tiled_direct_lighting".into(),
            resource: "lit_diffuse".into(),
            reader: "sky".into(),
            access: "color_attachment",
        }
    );
    // Two passes blending into one attachment are ordered by rasterization.
    assert!(within(&a.capture, pass("gi_shadow"), pass("volumetric_fog")).is_ok());
}

#[test]
fn the_merge_lint_finds_the_pair_and_its_fix_makes_the_merge() {
    let a = analysed(raw());
    let found: Vec<_> = a
        .analysis
        .lints
        .iter()
        .filter(|l| l.kind.code() == "FL017")
        .collect();
    assert_eq!(found.len(), 1, "{found:?}");
    let first = found[0].pass.map(|p| a.capture.pass(p).name.as_str());
    assert_eq!(first, Some("gi_shadow"));
    let fix = [Edit::fix("FL017").unwrap()];
    let (edited, said) = apply(&raw(), &a.capture, &a.analysis.lints, &fix).unwrap();
    assert_eq!(
        said,
        [
            "passes \"gi_shadow\" and \"volumetric_fog\" merged into one render pass \"gi_shadow+volumetric_fog\""
        ]
    );
    let b = analysed(edited);
    assert!(!b.analysis.lints.iter().any(|l| l.kind.code() == "FL017"));
    let v = static_verdict(&a.capture, &a.analysis.lints, &b.capture, &b.analysis.lints);
    assert!(v.safe(), "{:?}", v.introduced);
    assert_eq!(v.resolved.len(), 1);
    assert_eq!(v.resolved[0].code, "FL017");
}

#[test]
fn passes_with_another_between_them_are_not_reported() {
    // Between them a pass that reads what the second writes: the merge would refuse to move
    // the second ahead of it, and the lint takes only passes recorded one after the other.
    let mut r = raw();
    let at = r
        .passes
        .iter()
        .position(|p| p.name == "volumetric_fog")
        .unwrap();
    let mut reader = r
        .passes
        .iter()
        .find(|p| p.name == "water_reflection")
        .unwrap()
        .clone();
    reader.name = "reads_composite".into();
    r.passes.insert(at, reader);
    let a = analysed(r);
    assert!(!a.analysis.lints.iter().any(|l| l.kind.code() == "FL017"));
}
