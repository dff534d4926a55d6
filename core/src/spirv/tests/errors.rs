//! Bad input: every refusal is the right error, and nothing damaged panics.

use super::*;

// ---- errors -----------------------------------------------------------------------------------

#[test]
fn words_refuses_partial_words_and_bad_magic() {
    let bytes = std::fs::read(extracted().join("vkcube_f3/sh37")).unwrap();
    assert_eq!(
        words(&bytes[..bytes.len() - 1]),
        Err(SpirvError::NotWords {
            len: bytes.len() - 1
        })
    );
    let mut wrong = bytes.clone();
    wrong[0] = 0;
    assert!(matches!(words(&wrong), Err(SpirvError::BadMagic { found }) if found == 0x0723_0200));
    assert!(matches!(words(&[]), Err(SpirvError::Malformed { .. })));
    // A big-endian file reads as the same words.
    let swapped: Vec<u8> = bytes
        .chunks_exact(4)
        .flat_map(|c| [c[3], c[2], c[1], c[0]])
        .collect();
    assert_eq!(words(&swapped).unwrap(), words(&bytes).unwrap());
}

#[test]
fn truncated_module_is_malformed_at_the_cut_instruction() {
    let words = fixture("vkcube_f3/sh37");
    let cut = words.len() - 3;
    let err = reflect(&words[..cut]).unwrap_err();
    let SpirvError::Malformed { at_word, .. } = err else {
        panic!("{err:?}")
    };
    assert!(at_word <= cut && at_word > 5, "{at_word}");
    assert!(matches!(
        reflect(&words[..3]),
        Err(SpirvError::Malformed { .. })
    ));
    let mut bad = words.clone();
    bad[0] ^= 1;
    assert!(matches!(reflect(&bad), Err(SpirvError::BadMagic { .. })));
    assert!(matches!(
        rewrite(&words[..cut], ExecutionModel::Vertex, "main", &opts(true)),
        Err(SpirvError::Malformed { .. })
    ));
}

#[test]
fn binding_missing_from_the_layout_is_an_error() {
    let err = rewrite(
        &fixture("vkcube_f3/sh37"),
        ExecutionModel::Vertex,
        "main",
        &RewriteOptions {
            flip_y: false,
            binding: &|_, _, _| None,
            specialization: &[],
            texel_formats: &[],
            lod_bias: &[],
            gl_depth: false,
            swizzles: &[],
            storage_blocks: &[],
            std140_blocks: &[],
            unnormalized: &[],
            mirror_once: &[],
            attached_outputs: None,
            scaled_inputs: &[],
        },
    )
    .unwrap_err();
    assert_eq!(
        err,
        SpirvError::BindingNotInLayout {
            set: 0,
            binding: 0,
            role: Role::Whole
        }
    );
    let err = rewrite(
        &fixture("vkcube_f3/sh38"),
        ExecutionModel::Fragment,
        "main",
        &RewriteOptions {
            flip_y: false,
            binding: &|_, b, role| (role != Role::SplitSampler).then_some(b),
            specialization: &[],
            texel_formats: &[],
            lod_bias: &[],
            gl_depth: false,
            swizzles: &[],
            storage_blocks: &[],
            std140_blocks: &[],
            unnormalized: &[],
            mirror_once: &[],
            attached_outputs: None,
            scaled_inputs: &[],
        },
    )
    .unwrap_err();
    assert_eq!(
        err,
        SpirvError::BindingNotInLayout {
            set: 0,
            binding: 1,
            role: Role::SplitSampler
        }
    );
}

#[test]
fn missing_entry_point_is_an_error() {
    let words = fixture("vkcube_f3/sh37");
    for (model, name) in [
        (ExecutionModel::Vertex, "vs_main"),
        (ExecutionModel::Fragment, "main"),
    ] {
        assert_eq!(
            rewrite(&words, model, name, &opts(true)),
            Err(SpirvError::EntryPointNotFound {
                model,
                name: name.to_owned()
            })
        );
    }
}

#[test]
fn uses_the_split_cannot_follow_are_refused() {
    for (shape, feature, opcode) in [
        (
            Shape {
                array: true,
                ..Shape::default()
            },
            "array of combined image samplers",
            "",
        ),
        (
            Shape {
                copy: true,
                ..Shape::default()
            },
            "use of a combined image sampler other than loading it",
            "OpCopyObject",
        ),
        (
            Shape {
                grouped: true,
                ..Shape::default()
            },
            "descriptor decorated through a decoration group",
            "",
        ),
    ] {
        let err = rewrite(
            &combined_sampler_module(shape),
            ExecutionModel::Fragment,
            "main",
            &opts(false),
        )
        .unwrap_err();
        let SpirvError::Unsupported { feature: f, detail } = &err else {
            panic!("{err:?}")
        };
        assert_eq!(*f, feature);
        assert!(detail.contains("set 1 binding 3"), "{detail}");
        assert!(detail.contains(opcode), "{detail}");
    }
}

/// Every prefix, and many deterministic corruptions, of real modules: errors, never panics.
#[test]
fn damaged_modules_never_panic() {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let geometry = geometry_module();
    let inputs = [
        (
            "vkcube_f3/sh37",
            fixture("vkcube_f3/sh37"),
            ExecutionModel::Vertex,
        ),
        (
            "vkcube_f3/sh38",
            fixture("vkcube_f3/sh38"),
            ExecutionModel::Fragment,
        ),
        (
            "mpv_testsrc_f5/sh83",
            fixture("mpv_testsrc_f5/sh83"),
            ExecutionModel::Fragment,
        ),
        ("geometry", geometry, ExecutionModel::Geometry),
        // Arrays split through value and pointer parameters, and a loop's switch.
        (
            "ffmpeg_filters/avgblur_h",
            fixture("ffmpeg_filters/avgblur_h"),
            ExecutionModel::GLCompute,
        ),
        (
            "ffmpeg_filters/chromaber",
            fixture("ffmpeg_filters/chromaber"),
            ExecutionModel::GLCompute,
        ),
        (
            "ffmpeg_filters/overlay",
            fixture("ffmpeg_filters/overlay"),
            ExecutionModel::GLCompute,
        ),
    ];
    let run = |words: &[u32], model| {
        let _ = reflect(words);
        let _ = rewrite(words, model, "main", &opts(true));
        if let Ok(Some(split)) = split_descriptor_arrays(words) {
            let _ = rewrite(&split, model, "main", &opts(true));
        }
    };
    let mut variants = 0;
    for (name, words, model) in &inputs {
        for len in 0..words.len() {
            run(&words[..len], *model);
        }
        for _ in 0..1500 {
            let mut damaged = words.clone();
            for _ in 0..=(next() % 3) {
                let at = 5 + (next() % (words.len() as u64 - 5)) as usize;
                damaged[at] = match next() % 4 {
                    0 => damaged[at] ^ (1 << (next() % 32)),
                    1 => damaged[at].wrapping_add(1),
                    2 => next() as u32 % 64,
                    _ => next() as u32,
                };
            }
            if std::panic::catch_unwind(|| run(&damaged, *model)).is_err() {
                panic!("{name}: panicked on {damaged:?}");
            }
            variants += 1;
        }
    }
    assert_eq!(variants, 1500 * inputs.len());
}

#[test]
fn a_source_language_the_grammar_does_not_know_is_no_refusal() {
    // vkcube's fragment shader with its OpSource (word 25: GLSL) said to be of language 99,
    // which SPIRV-Tools rejects and drivers run: reflected and rewritten as the original.
    let original = fixture("vkcube_f3/sh37");
    assert_eq!(original[25] & 0xffff, 3, "an OpSource at word 25");
    let mut words = original.clone();
    words[26] = 99;
    assert_eq!(reflect(&words).unwrap(), reflect(&original).unwrap());
    let out = rewrite(&words, ExecutionModel::Vertex, "main", &opts(false)).unwrap();
    // rspirv loads what the rewrite wrote: the language, where kept, is one it knows.
    let module = load(&out);
    assert!(
        module
            .debug_string_source
            .iter()
            .all(|i| i.class.opcode != Op::Source || i.operands[0] != Operand::LiteralBit32(99))
    );
}
