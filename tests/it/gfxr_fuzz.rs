//! The fuzz harness for the binary capture reader, run by CI for a bounded number of cases:
//! each case damages a real capture the way a corrupt file or a hostile one would (bytes
//! flipped, the file cut, a block's size, type, or uncompressed size replaced, a block
//! dropped or repeated) and imports it in-process. Whatever the input, the result must be a
//! capture or a located error: no panic, and (by the reader's size checks) no unbounded
//! memory. Every input that ever failed is kept in `tests/fuzz_corpus/gfxr/` and replayed.

use std::io::Cursor;

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::import::{ImportOptions, gfxr};
use framelab_core::pipeline::Loaded;
use proptest::prelude::*;

use crate::common::{Scratch, repo};

/// Imports `bytes` as a binary capture and, when that works, validates and analyses it;
/// panics only if framelab does.
fn run_import(bytes: &[u8], name: &str) {
    let Ok(imported) = gfxr::import(
        Cursor::new(bytes),
        Some(bytes.len() as u64),
        name,
        "fuzz",
        &ImportOptions::default(),
    ) else {
        return;
    };
    let dir = Scratch::temp("framelab-fuzz-gfxr");
    if let Ok(v) =
        Loaded::from_raw(&dir.join("fuzz.json"), imported.capture).validate(&Options::default())
    {
        let _ = v.analyse(AnalyzeOptions { cull: true });
    }
}

const SEEDS: [&str; 4] = [
    "vkcube_f3.gfxr",
    "vkd3d_triangle_f1.gfxr",
    "vkcube_staging.gfxr",
    "template_compute.gfxr",
];

#[test]
fn every_capture_that_ever_failed_now_imports_or_is_refused() {
    let mut seen = 0;
    for e in std::fs::read_dir(repo().join("tests/fuzz_corpus/gfxr")).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "gfxr") {
            run_import(&std::fs::read(&path).unwrap(), &path.display().to_string());
            seen += 1;
        }
    }
    assert!(seen >= 3, "the binary corpus has only {seen} inputs");
}

/// What a hostile file does to one block (or the whole file).
#[derive(Clone, Debug)]
enum Damage {
    /// One byte at this position (modulo the length) set to this value.
    Byte(usize, u8),
    /// The file cut after this many bytes.
    Cut(usize),
    /// A block's size replaced.
    Size(usize, u64),
    /// A block's type replaced.
    Type(usize, u32),
    /// A block's first payload word (the call id or meta-data id) replaced.
    Id(usize, u32),
    /// A compressed call's uncompressed size replaced.
    Unpacked(usize, u64),
    /// A block dropped.
    Drop(usize),
    /// A block repeated this many times.
    Repeat(usize, usize),
}

fn damage() -> impl Strategy<Value = Damage> {
    let size = prop_oneof![
        Just(u64::MAX),
        Just(u64::MAX - 11),
        Just(1u64 << 40),
        Just(0u64),
        0u64..256,
        any::<u64>(),
    ];
    prop_oneof![
        4 => (any::<usize>(), any::<u8>()).prop_map(|(a, b)| Damage::Byte(a, b)),
        1 => any::<usize>().prop_map(Damage::Cut),
        2 => (any::<usize>(), size.clone()).prop_map(|(a, s)| Damage::Size(a, s)),
        1 => (any::<usize>(), prop_oneof![0u32..8, Just(0x8000_0001u32), Just(0x8000_0004u32), any::<u32>()]).prop_map(|(a, t)| Damage::Type(a, t)),
        2 => (any::<usize>(), prop_oneof![0x1_1000u32..0x1_1200, 0x1_0000u32..0x1_0030, any::<u32>()]).prop_map(|(a, t)| Damage::Id(a, t)),
        2 => (any::<usize>(), size).prop_map(|(a, s)| Damage::Unpacked(a, s)),
        1 => any::<usize>().prop_map(Damage::Drop),
        1 => (any::<usize>(), 2usize..50).prop_map(|(a, n)| Damage::Repeat(a, n)),
    ]
}

/// The file split into its header and blocks (each with its 12-byte header).
fn split(bytes: &[u8]) -> (Vec<u8>, Vec<Vec<u8>>) {
    let options = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut at = (16 + 8 * options.min(1 << 20)).min(bytes.len());
    let head = bytes[..at].to_vec();
    let mut blocks = Vec::new();
    while at + 12 <= bytes.len() {
        let size = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
        let end = at.saturating_add(12).saturating_add(size).min(bytes.len());
        blocks.push(bytes[at..end].to_vec());
        at = end;
    }
    (head, blocks)
}

fn apply(bytes: &mut Vec<u8>, d: &Damage) {
    let (head, mut blocks) = split(bytes);
    let n = blocks.len();
    let whole_file = matches!(d, Damage::Byte(..) | Damage::Cut(..));
    if n == 0 && !whole_file {
        return;
    }
    match *d {
        Damage::Byte(at, v) => {
            let i = at % bytes.len();
            bytes[i] = v;
            return;
        }
        Damage::Cut(at) => {
            bytes.truncate(at % (bytes.len() + 1));
            return;
        }
        // Every block `split` gives has its 12-byte header.
        Damage::Size(b, s) => blocks[b % n][..8].copy_from_slice(&s.to_le_bytes()),
        Damage::Type(b, t) => blocks[b % n][8..12].copy_from_slice(&t.to_le_bytes()),
        Damage::Id(b, id) => {
            if blocks[b % n].len() >= 16 {
                blocks[b % n][12..16].copy_from_slice(&id.to_le_bytes());
            }
        }
        Damage::Unpacked(b, s) => {
            let block = &mut blocks[b % n];
            if block.len() >= 32 {
                block[24..32].copy_from_slice(&s.to_le_bytes());
            }
        }
        Damage::Drop(b) => {
            blocks.remove(b % n);
        }
        Damage::Repeat(b, k) => {
            let copy = blocks[b % n].clone();
            let at = b % n;
            blocks.splice(at..at, std::iter::repeat_n(copy, k));
        }
    }
    *bytes = head;
    for b in blocks {
        bytes.extend_from_slice(&b);
    }
}

proptest! {
    // Bounded for CI like the other harnesses; every case is a whole import of a real capture.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("FRAMELAB_FUZZ_CASES").ok().and_then(|c| c.parse::<u32>().ok()).map_or(300, |c| c / 2),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn damaged_captures_never_panic(
        which in 0usize..SEEDS.len(),
        damages in proptest::collection::vec(damage(), 1..4),
    ) {
        let mut bytes = std::fs::read(repo().join("tests/fixtures/gfxr").join(SEEDS[which])).unwrap();
        for d in &damages {
            if bytes.len() < 16 {
                break;
            }
            apply(&mut bytes, d);
        }
        run_import(&bytes, SEEDS[which]);
    }
}
