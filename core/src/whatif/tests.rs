//! Edits on the example frame with recorded barriers: each kind applied and judged, and every
//! bad edit refused by name.

use std::path::{Path, PathBuf};

use super::*;
use crate::analysis::report::AnalyzeOptions;
use crate::capture::Options;
use crate::capture::format::RawCapture;
use crate::pipeline::{Analysed, Loaded};

fn path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../captures/example/frame_sync.json")
}

fn analysed(raw: RawCapture) -> Analysed {
    Loaded::from_raw(&path(), raw)
        .validate(&Options::default())
        .unwrap()
        .analyse(AnalyzeOptions { cull: false })
        .unwrap()
}

/// The frame, and the variant the edits make with what was said of each change.
fn variant(edits: &[Edit]) -> Result<(Analysed, Analysed, Vec<String>), EditError> {
    let raw = Loaded::read(&path()).unwrap().raw;
    let frame = analysed(raw.clone());
    let (edited, said) = apply(&raw, &frame.capture, &frame.analysis.lints, edits)?;
    Ok((frame, analysed(edited), said))
}

fn verdict(edits: &[Edit]) -> (StaticVerdict, Vec<String>) {
    let (a, b, said) = variant(edits).unwrap();
    (
        static_verdict(&a.capture, &a.analysis.lints, &b.capture, &b.analysis.lints),
        said,
    )
}

#[test]
fn dropping_a_barrier_the_frame_needs_is_unsafe_at_its_pass() {
    let (v, said) = verdict(&[Edit::drop_barrier("simulate:0").unwrap()]);
    assert_eq!(said, ["dropped barrier 0 of pass \"simulate\""]);
    assert!(!v.safe());
    let errors: Vec<_> = v.errors().collect();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].code, "FL020");
    assert_eq!(errors[0].pass.as_deref(), Some("simulate"));
    assert_eq!(errors[0].resource.as_deref(), Some("particles"));
}

#[test]
fn a_redundant_barrier_fixed_is_safe_and_the_finding_goes() {
    let (v, said) = verdict(&[Edit::fix("FL021").unwrap()]);
    assert_eq!(said, ["dropped barrier 3 of pass \"scene\""]);
    assert!(v.safe(), "{:?}", v.introduced);
    assert!(v.introduced.is_empty(), "{:?}", v.introduced);
    assert_eq!(v.resolved.len(), 1);
    assert_eq!(v.resolved[0].code, "FL021");
}

#[test]
fn an_unused_flag_fixed_leaves_the_resource_without_it() {
    let (_, b, said) = variant(&[Edit::fix("fl001:noise").unwrap()]).unwrap();
    assert_eq!(said, ["removed ALLOW_UNORDERED_ACCESS from \"noise\""]);
    let noise = b
        .capture
        .resources
        .iter()
        .find(|r| r.name == "noise")
        .unwrap();
    assert!(!noise.has_flag(crate::capture::format::ResourceFlag::AllowUnorderedAccess));
    assert!(noise.has_flag(crate::capture::format::ResourceFlag::AllowRenderTarget));
}

#[test]
fn culling_a_pass_whose_results_are_read_is_unsafe() {
    // The particle simulation feeds the scene's indirect draw.
    let (v, _) = verdict(&[Edit::cull("simulate").unwrap()]);
    assert!(!v.safe());
    assert!(
        v.errors()
            .any(|l| l.resource.as_deref() == Some("particles")),
        "{:?}",
        v.introduced
    );
}

#[test]
fn a_format_change_is_made_and_validated() {
    let (a, b, said) = variant(&[Edit::format("bloom=r11g11b10_float").unwrap()]).unwrap();
    assert_eq!(said, ["\"bloom\" R16G16B16A16_FLOAT -> R11G11B10_FLOAT"]);
    let size = |x: &Analysed| {
        x.capture
            .resources
            .iter()
            .find(|r| r.name == "bloom")
            .unwrap()
            .bytes
    };
    // Eight bytes a texel become four.
    assert_eq!(size(&a), 2 * size(&b));
}

#[test]
fn bad_edits_are_refused_by_name() {
    let err = |e: Edit| variant(&[e]).err().unwrap().to_string();
    assert_eq!(
        err(Edit::cull("nope").unwrap()),
        "--cull nope: the capture has no pass \"nope\""
    );
    assert_eq!(
        err(Edit::drop_barrier("scene:4").unwrap()),
        "--drop-barrier scene:4: pass \"scene\" records 4 barriers (0..4)"
    );
    assert!(err(Edit::format("bloom=R9_BOGUS").unwrap()).contains("not a format"));
    assert!(err(Edit::format("particles=R32_FLOAT").unwrap()).contains("is a buffer"));
    assert!(err(Edit::format("nothing=R32_FLOAT").unwrap()).contains("no resource \"nothing\""));
    // FL004 is advice with no change to the frame; FL005 has no finding here.
    assert!(err(Edit::fix("FL004").unwrap()).contains("none with a change"));
    assert!(err(Edit::fix("FL005").unwrap()).contains("no such finding"));
    assert!(err(Edit::fix("FL001:depth").unwrap()).contains("about \"depth\""));
    assert!(matches!(
        Edit::fix("FL999"),
        Err(EditError::UnknownLint { .. })
    ));
    assert!(matches!(
        Edit::drop_barrier("scene"),
        Err(EditError::Syntax { .. })
    ));
    assert!(matches!(
        Edit::drop_barrier(":1"),
        Err(EditError::Syntax { .. })
    ));
    assert!(matches!(
        Edit::format("bloom"),
        Err(EditError::Syntax { .. })
    ));
    assert!(matches!(Edit::cull(""), Err(EditError::Syntax { .. })));
}

#[test]
fn every_fixable_finding_fixed_at_once_is_safe_and_leaves_none() {
    let (a, b, said) = variant(&[Edit::fix("all").unwrap()]).unwrap();
    let fixable = a.analysis.lints.iter().filter(|l| l.fix.is_some()).count();
    assert!(fixable >= 2, "{fixable}");
    assert_eq!(said.len(), fixable, "{said:?}");
    let v = static_verdict(&a.capture, &a.analysis.lints, &b.capture, &b.analysis.lints);
    assert!(v.safe(), "{:?}", v.introduced);
    assert!(
        b.analysis.lints.iter().all(|l| l.fix.is_none()),
        "{:?}",
        b.analysis.lints
    );
}

#[test]
fn moving_a_pass_to_another_queue_without_fences_is_unsafe() {
    // The particle simulation reads what reset_args wrote on the graphics queue, and the scene
    // draws from what it writes: on the async queue nothing orders either.
    let (v, said) = verdict(&[Edit::queue("simulate=async").unwrap()]);
    assert_eq!(said, ["pass \"simulate\" moved from queue gfx to async"]);
    assert!(!v.safe());
    assert!(v.errors().all(|l| l.code == "FL014"), "{:?}", v.introduced);
    let err = variant(&[Edit::queue("simulate=nowhere").unwrap()])
        .err()
        .unwrap()
        .to_string();
    assert_eq!(
        err,
        "--queue simulate=nowhere: the capture has no queue \"nowhere\""
    );
}

#[test]
fn a_texture_scaled_keeps_relative_sizes_relative() {
    let (a, b, said) = variant(&[Edit::scale_resource("bloom=0.5").unwrap()]).unwrap();
    assert_eq!(said, ["\"bloom\" width and height scaled by 0.5"]);
    let size = |x: &Analysed| {
        let r = x
            .capture
            .resources
            .iter()
            .find(|r| r.name == "bloom")
            .unwrap();
        (r.width, r.height)
    };
    let ((wa, ha), (wb, hb)) = (size(&a), size(&b));
    assert_eq!((wb, hb), (wa.div_ceil(2), ha.div_ceil(2)));
    assert!(matches!(
        Edit::scale_resource("bloom=0"),
        Err(EditError::Syntax { .. })
    ));
    assert!(matches!(
        Edit::scale_resource("bloom=x"),
        Err(EditError::Syntax { .. })
    ));
}
