//! The `vulkan` section of an imported capture checked by `validate`: each edit of a good
//! import that no device or replay could take is refused, named at its JSON path.

use serde_json::Value;

use crate::common::{framelab, gfxr_fixture, stderr, stdout};
use crate::gfxr_binary::{import, temp_dir};

/// A name, an edit of a good capture, and what validation must say about it.
type Broken = (&'static str, fn(&mut Value), &'static str);

#[test]
fn the_vulkan_section_is_validated() {
    let dir = temp_dir("vkvalid");
    let out = dir.join("cube.json");
    import(&gfxr_fixture("vkcube_f3.gfxr"), &out);
    let good: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let cases: [Broken; 20] = [
        (
            "offset",
            |c| {
                c["passes"][0]["draws"][0]["vulkan_state"]["descriptors"][0]["offset"] =
                    u64::MAX.into()
            },
            "binds bytes 18446744073709551615..18446744073709551615 of \"buffer_28\", which holds",
        ),
        (
            "set",
            |c| {
                c["passes"][0]["draws"][0]["vulkan_state"]["descriptors"][0]["set"] =
                    4_294_967_295u32.into()
            },
            "set 4294967295 is past the 32 sets any device binds",
        ),
        (
            "mips",
            |c| c["vulkan"]["image_views"][0]["base_mip"] = 4_294_967_295u32.into(),
            "reaches mip levels 4294967295..4294967296 of \"image_24\", which has 1",
        ),
        (
            "layers",
            |c| c["vulkan"]["image_views"][0]["layers"] = 7.into(),
            "reaches layers 0..7 of \"image_24\", which has 1",
        ),
        (
            "entry",
            |c| c["vulkan"]["pipelines"][0]["stages"][1]["entry"] = "mian".into(),
            "has no VK_SHADER_STAGE_FRAGMENT_BIT entry point \"mian\"",
        ),
        (
            "size",
            |c| c["vulkan"]["shader_modules"][0]["size"] = 1564.into(),
            "is 1564 bytes",
        ),
        (
            "layout",
            |c| c["vulkan"]["pipelines"][0]["layout"] = "pipeline_layout_1".into(),
            "no pipeline layout \"pipeline_layout_1\"",
        ),
        (
            "draw",
            |c| c["passes"][0]["draws"][0]["pipeline"] = "pipeline_2".into(),
            "no pipeline \"pipeline_2\"",
        ),
        (
            "view",
            |c| {
                c["passes"][0]["draws"][0]["vulkan_state"]["descriptors"][1]["view"] =
                    "view_9".into()
            },
            "no image view \"view_9\"",
        ),
        (
            "mips0",
            |c| c["vulkan"]["image_views"][0]["mips"] = 0.into(),
            "takes 0 mip levels",
        ),
        (
            "viewport",
            |c| c["passes"][0]["draws"][0]["vulkan_state"]["viewport"][2] = 1e39.into(),
            "vulkan_state.viewport: viewport value 2 is not a finite number (inf)",
        ),
        (
            "width",
            |c| c["passes"][0]["draws"][0]["vulkan_state"]["viewport"][2] = (-500.0).into(),
            "viewport width -500 is not positive",
        ),
        (
            "bounds",
            |c| c["passes"][0]["draws"][0]["vulkan_state"]["viewport"][0] = 1e30.into(),
            "wider than any device's viewport bounds",
        ),
        (
            "scissor",
            |c| c["passes"][0]["draws"][0]["vulkan_state"]["scissor"][1] = (-8).into(),
            "vulkan_state.scissor: scissor offset (0, -8) is negative",
        ),
        (
            "scissor_end",
            |c| c["passes"][0]["draws"][0]["vulkan_state"]["scissor"][2] = i64::MAX.into(),
            "reaches past 2147483647",
        ),
        (
            "push_size",
            |c| {
                c["vulkan"]["pipeline_layouts"][0]["push_constants"] =
                    serde_json::json!([{"stages": 1, "offset": 0, "size": 4_294_967_292u32}])
            },
            "push-constant range 0..4294967292 reaches past 256 bytes",
        ),
        (
            "push_words",
            |c| {
                c["vulkan"]["pipeline_layouts"][0]["push_constants"] =
                    serde_json::json!([{"stages": 1, "offset": 2, "size": 8}])
            },
            "push-constant range 2..10 is not whole 4-byte words",
        ),
        (
            "stage_twice",
            |c| {
                c["vulkan"]["pipelines"][0]["stages"][1]["stage"] =
                    "VK_SHADER_STAGE_VERTEX_BIT".into()
            },
            "names stage VK_SHADER_STAGE_VERTEX_BIT twice",
        ),
        (
            "compute_stage",
            |c| {
                c["vulkan"]["pipelines"][0]["stages"][1]["stage"] =
                    "VK_SHADER_STAGE_COMPUTE_BIT".into()
            },
            "graphics pipeline \"pipeline_40\" has a VK_SHADER_STAGE_COMPUTE_BIT stage",
        ),
        (
            "blend",
            |c| c["vulkan"]["pipelines"][0]["graphics"]["line_width"] = (-1e39).into(),
            "line_width holds -inf, not a finite number",
        ),
    ];
    let ok = framelab(&["validate", out.to_str().unwrap()]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    for (tag, edit, message) in cases {
        let mut c = good.clone();
        edit(&mut c);
        let path = dir.join(format!("{tag}.json"));
        std::fs::write(&path, serde_json::to_string(&c).unwrap()).unwrap();
        let o = framelab(&["validate", path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1), "{tag}");
        let text = format!("{}{}", stdout(&o), stderr(&o));
        assert!(text.contains(message), "{tag}: {text}");
    }
}
