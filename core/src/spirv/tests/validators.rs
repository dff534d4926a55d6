//! Rewritten modules as naga and SPIRV-Tools see them.

use super::*;

// ---- naga -------------------------------------------------------------------------------------

pub(super) fn naga_accepts(words: &[u32]) -> Result<(), String> {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let module = naga::front::spv::parse_u8_slice(&bytes, &naga::front::spv::Options::default())
        .map_err(|e| format!("parse: {e:?}"))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| format!("validate: {e:?}"))?;
    Ok(())
}

#[test]
fn naga_reads_rewritten_vkcube_modules() {
    let fragment = rewrite(
        &fixture("vkcube_f3/sh38"),
        ExecutionModel::Fragment,
        "main",
        &opts(false),
    )
    .unwrap();
    naga_accepts(&fragment).unwrap();
    let vertex = rewrite(
        &fixture("vkcube_f3/sh37"),
        ExecutionModel::Vertex,
        "main",
        &opts(true),
    )
    .unwrap();
    naga_accepts(&vertex).unwrap();
}

/// naga's SPIR-V front end is stricter than Vulkan in places (capabilities it lacks, matrix
/// strides): the rewrite must not add to what it refuses.
#[test]
fn naga_accepts_every_rewritten_fixture_it_accepted_before() {
    let mut accepted = 0;
    for (name, words) in all_fixtures() {
        let words = split_descriptor_arrays(&words).unwrap().unwrap_or(words);
        for e in reflect(&words).unwrap().entry_points {
            let out = rewrite(&words, e.model, &e.name, &opts(true)).unwrap();
            match (naga_accepts(&words), naga_accepts(&out)) {
                (_, Ok(())) => accepted += 1,
                (Ok(()), Err(after)) => panic!("{name} {}: {after}", e.name),
                (Err(_), Err(_)) => {}
            }
        }
    }
    // Every vkcube module among them: the fragment shaders only once split.
    assert!(accepted >= 24, "{accepted}");
}

// ---- spirv-val ----------------------------------------------------------------------------------

/// Rewrites every entry point of every fixture module and runs SPIRV-Tools' validator on the
/// result. Needs `spirv-val` on PATH (Debian's spirv-tools, which CI installs), and fails when
/// it is missing.
#[test]
fn rewritten_fixtures_pass_spirv_val() {
    let dir = std::env::temp_dir().join(format!("framelab-spirv-val-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut failures = Vec::new();
    let mut checked = 0;
    let mut modules: Vec<(String, Vec<u32>)> = all_fixtures();
    for shape in [
        Shape::default(),
        Shape {
            cross_block: true,
            ..Shape::default()
        },
        Shape {
            version_1_4: true,
            ..Shape::default()
        },
        Shape {
            via_function: true,
            ..Shape::default()
        },
    ] {
        modules.push((format!("built {shape:?}"), combined_sampler_module(shape)));
    }
    modules.push(("built geometry".to_owned(), geometry_module()));
    modules.push(("built demote".to_owned(), super::demote::demote_module()));
    modules.push((
        "built spec-constant operations".to_owned(),
        super::specop::spec_module(false).words,
    ));
    for (name, words) in modules {
        // As the lowering reads them: descriptor arrays split per element.
        let words = split_descriptor_arrays(&words)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .unwrap_or(words);
        let r = reflect(&words).unwrap();
        // Uniform blocks past std140 are widened or read as storage, as the lowering asks.
        let beyond = uniform_blocks_beyond_std140(&words);
        let pick = |widen: bool| -> Vec<(u32, u32)> {
            beyond
                .iter()
                .filter(|b| b.widened_end.is_some() == widen)
                .map(|b| (b.set, b.binding))
                .collect()
        };
        let (std140_blocks, storage_blocks) = (pick(true), pick(false));
        for e in &r.entry_points {
            for flip_y in [false, true] {
                let opts = RewriteOptions {
                    std140_blocks: &std140_blocks,
                    storage_blocks: &storage_blocks,
                    ..opts(flip_y)
                };
                let out = rewrite(&words, e.model, &e.name, &opts)
                    .unwrap_or_else(|err| panic!("{name} {}: {err}", e.name));
                let file = dir.join(format!(
                    "{}-{}-{flip_y}.spv",
                    name.replace(['/', ' '], "_"),
                    e.name
                ));
                checked += 1;
                if let Err(why) = validate_at(&file, &out) {
                    failures.push(format!("{name} {} flip_y={flip_y}: {why}", e.name));
                }
            }
        }
    }
    if std::env::var_os("FRAMELAB_KEEP_SPIRV").is_none() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!(
        "spirv-val accepted {checked} rewritten modules (in {})",
        dir.display()
    );
    assert!(checked >= 80, "{checked}");
}

/// SPIRV-Tools' validator on `words`, written to `file`, for the Vulkan version its SPIR-V
/// version needs; its message where it refuses them.
fn validate_at(file: &std::path::Path, words: &[u32]) -> Result<(), String> {
    std::fs::write(file, without_wgsl_source(words)).unwrap();
    let env = match load(words).header.as_ref().unwrap().version() {
        (1, 0) => "vulkan1.0",
        (1, 1..=3) => "vulkan1.1",
        (1, 4) => "vulkan1.1spv1.4",
        (1, 5) => "vulkan1.2",
        _ => "vulkan1.3",
    };
    let result = std::process::Command::new("spirv-val")
        .args(["--target-env", env])
        .arg(file)
        .output()
        .expect("spirv-val (SPIRV-Tools) must be installed for this test");
    if result.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&result.stderr).into_owned())
    }
}

/// [`validate_at`] in a file of its own, removed afterwards.
pub(super) fn spirv_val(words: &[u32], name: &str) -> Result<(), String> {
    let file = std::env::temp_dir().join(format!(
        "framelab-spirv-val-{name}-{}.spv",
        std::process::id()
    ));
    let result = validate_at(&file, words);
    let _ = std::fs::remove_file(&file);
    result
}

/// naga writes `OpSource WGSL`, which SPIRV-Tools before 2023.2 does not know; the source
/// language says nothing about validity.
fn without_wgsl_source(words: &[u32]) -> Vec<u8> {
    let mut module = load(words);
    module
        .debug_string_source
        .retain(|i| i.class.opcode != Op::Source);
    module
        .assemble()
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect()
}
