//! Descriptor arrays split into one variable per element, on FFmpeg's Vulkan filters: indices
//! that are constants in the entry point, handed to functions by value or through a pointer,
//! and a loop over the planes; and the refusal of an index known only at run time.

use super::validators::{naga_accepts, spirv_val};
use super::*;

const FILTERS: [&str; 12] = [
    "avgblur_h",
    "avgblur_v",
    "blend",
    "chromaber",
    "flip",
    "gblur_h",
    "gblur_v",
    "hflip",
    "overlay",
    "scale",
    "transpose",
    "vflip",
];

fn ffmpeg(name: &str) -> Vec<u32> {
    fixture(&format!("ffmpeg_filters/{name}"))
}

/// The descriptors a module declares: (set, binding, count), sorted.
fn declared(words: &[u32]) -> Vec<(u32, u32, Option<u32>)> {
    let mut out: Vec<_> = reflect(words)
        .unwrap()
        .resources
        .iter()
        .map(|r| (r.set, r.binding, r.count))
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn every_ffmpeg_filter_has_its_arrays_split_into_elements_that_validate() {
    for name in FILTERS {
        let words = ffmpeg(name);
        let before = declared(&words);
        assert!(
            before.iter().any(|b| b.2.is_some_and(|n| n > 1)),
            "{name}: no descriptor array to split"
        );
        let split = split_descriptor_arrays(&words)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .expect("split");
        let after = declared(&split);
        for &(set, binding, count) in &after {
            assert_eq!(
                count, None,
                "{name}: set {set} binding {binding} is still an array"
            );
            let (array, element) = binding_element(binding);
            let (_, _, len) = before
                .iter()
                .find(|b| (b.0, b.1) == (set, array))
                .unwrap_or_else(|| panic!("{name}: binding {binding} decodes to no array"));
            assert!(
                element < len.unwrap_or(1),
                "{name}: element {element} of {array}"
            );
        }
        // Each plane the filter writes is an element of its own.
        assert!(after.len() >= 3, "{name}: {after:?}");
        spirv_val(&split, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        for e in reflect(&split).unwrap().entry_points {
            let out = rewrite(&split, e.model, &e.name, &opts(false))
                .unwrap_or_else(|err| panic!("{name}: {err}"));
            naga_accepts(&out).unwrap_or_else(|err| panic!("{name} through naga: {err}"));
        }
    }
}

/// avgblur hands the plane to a function by value, chromaber through a pointer, overlay from
/// a loop over the planes: the first two call a clone per plane, the loop switches over them.
#[test]
fn indices_handed_to_functions_become_clones_and_a_loop_a_switch() {
    let count = |words: &[u32], op: Op| {
        load(words)
            .functions
            .iter()
            .flat_map(|f| f.all_inst_iter())
            .filter(|i| i.class.opcode == op)
            .count()
    };
    for (name, functions) in [("avgblur_h", 4), ("chromaber", 3), ("overlay", 4)] {
        let split = split_descriptor_arrays(&ffmpeg(name)).unwrap().unwrap();
        let m = load(&split);
        assert_eq!(
            m.functions.len(),
            functions,
            "{name}: main and a clone per plane"
        );
        let switches = count(&split, Op::Switch);
        assert_eq!(switches, usize::from(name == "overlay"), "{name}");
        // Every element 0 to 2 of every array is bound.
        let elements: BTreeSet<u32> = declared(&split)
            .iter()
            .map(|b| binding_element(b.1).1)
            .collect();
        assert_eq!(elements, BTreeSet::from([0, 1, 2]), "{name}");
    }
}

#[test]
fn an_index_known_only_at_run_time_is_refused_by_name() {
    // transpose indexes its arrays with constants; give one chain the invocation's x instead.
    let mut m = load(&ffmpeg("transpose"));
    let main = m
        .functions
        .iter_mut()
        .find(|f| f.blocks.len() > 1)
        .expect("main");
    let mut run_time = None;
    let mut edited = false;
    for i in main
        .blocks
        .iter_mut()
        .flat_map(|b| b.instructions.iter_mut())
    {
        if i.class.opcode == Op::Load && run_time.is_none() && i.operands.len() == 1 {
            let ty = i.result_type;
            if ty.is_some() && i.result_id.is_some() {
                run_time = i.result_id;
            }
        }
        if i.class.opcode == Op::AccessChain
            && i.operands.len() == 2
            && let (Some(x), false) = (run_time, edited)
        {
            i.operands[1] = Operand::IdRef(x);
            edited = true;
        }
    }
    assert!(edited);
    let err = split_descriptor_arrays(&m.assemble())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("descriptor array") && err.contains("known only at run time"),
        "{err}"
    );
    assert!(err.contains("set 0 binding"), "{err}");
}

#[test]
fn a_module_without_arrays_is_left_as_it_is() {
    assert_eq!(
        split_descriptor_arrays(&fixture("vkcube_f3/sh38")).unwrap(),
        None
    );
}

/// FFmpeg 5.1's `scale_vulkan` from RGBA (`ffmpeg_filters/scale_array_of_one`, from a capture
/// of `format=rgba,hwupload,vflip_vulkan,scale_vulkan=format=yuv420p`): its input is an array
/// of one combined image sampler and its output an array of one storage image. An array of
/// one is split too (its element keeps the binding), so the combined image sampler is a single
/// variable the rewrite can split into an image and a sampler; the result validates.
#[test]
fn arrays_of_one_are_split_so_their_combined_image_samplers_rewrite() {
    let words = ffmpeg("scale_array_of_one");
    assert_eq!(declared(&words), [(0, 0, Some(1)), (0, 1, Some(1))]);
    let split = split_descriptor_arrays(&words).unwrap().expect("split");
    assert_eq!(declared(&split), [(0, 0, None), (0, 1, None)]);
    let out = rewrite(&split, ExecutionModel::GLCompute, "main", &opts(false)).unwrap();
    spirv_val(&out, "scale_array_of_one").unwrap();
    assert!(rewrite(&words, ExecutionModel::GLCompute, "main", &opts(false)).is_err());
}
