//! The fuzz harness for the RenderDoc reader, run by CI for a bounded number of cases: real
//! captures are converted once by `renderdoccmd`, then each case damages the conversion the
//! way a broken or hostile converter could (bytes changed, the XML cut, lines dropped or
//! repeated, numbers and byte lengths replaced, the zip's bytes changed) and imports it
//! in-process. Whatever the input, the result must be a capture or a located error: no panic,
//! and (by the reader's limits) no unbounded memory.

use std::io::Cursor;
use std::sync::OnceLock;

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::import::{ImportOptions, rdc};
use framelab_core::pipeline::Loaded;
use proptest::prelude::*;

use crate::common::{Scratch, repo};

const SEEDS: [&str; 2] = ["vkcube_frame183", "mpv_testsrc_f73"];

/// Each seed's conversion: its XML and zip, made once per test run.
fn conversions() -> &'static Vec<(Vec<u8>, Vec<u8>)> {
    static DONE: OnceLock<Vec<(Vec<u8>, Vec<u8>)>> = OnceLock::new();
    DONE.get_or_init(|| {
        // The conversions are read into memory; their folder goes when they are.
        let dir = Scratch::temp("framelab-rdc-fuzz");
        SEEDS
            .iter()
            .map(|name| {
                let xml = dir.join(format!("{name}.zip.xml"));
                let out = std::process::Command::new("renderdoccmd")
                    .args(["convert", "-f"])
                    .arg(repo().join(format!("tests/fixtures/rdc/{name}.rdc")))
                    .args(["-c", "zip.xml", "-o"])
                    .arg(&xml)
                    .output()
                    .expect("renderdoccmd (apt-get install renderdoc)");
                assert!(out.status.success(), "{name}: conversion failed");
                (
                    std::fs::read(&xml).unwrap(),
                    std::fs::read(dir.join(format!("{name}.zip"))).unwrap(),
                )
            })
            .collect()
    })
}

/// Imports a conversion and, when that works, validates and analyses the capture; panics
/// only if framelab does.
fn run_import(xml: &[u8], zip: &[u8]) {
    let Ok(imported) = rdc::import(
        Cursor::new(xml),
        Cursor::new(zip),
        "fuzz.rdc",
        "fuzz",
        Some("1.24"),
        &ImportOptions::default(),
    ) else {
        return;
    };
    let dir = Scratch::temp("framelab-fuzz-rdc");
    if let Ok(v) =
        Loaded::from_raw(&dir.join("fuzz.json"), imported.capture).validate(&Options::default())
    {
        let _ = v.analyse(AnalyzeOptions { cull: true });
    }
}

/// What a broken converter does to its output.
#[derive(Clone, Debug)]
enum Damage {
    /// One byte of the XML set to this value.
    Byte(usize, u8),
    /// The XML cut after this many bytes.
    Cut(usize),
    /// A line of the XML dropped.
    Drop(usize),
    /// A line of the XML repeated this many times.
    Repeat(usize, usize),
    /// The text of the element on this line (or the next one with text) replaced.
    Number(usize, String),
    /// A `byteLength` replaced.
    Length(usize, u64),
    /// One byte of the zip set to this value.
    ZipByte(usize, u8),
}

fn damage() -> impl Strategy<Value = Damage> {
    let number = prop_oneof![
        Just(u64::MAX.to_string()),
        Just("-1".to_owned()),
        Just((1u64 << 40).to_string()),
        Just("0".to_owned()),
        Just("4294967295".to_owned()),
        Just("x".to_owned()),
        (0u64..300).prop_map(|n| n.to_string()),
    ];
    let length = prop_oneof![Just(u64::MAX), Just(1u64 << 40), Just(0u64), 0u64..5000,];
    prop_oneof![
        3 => (any::<usize>(), any::<u8>()).prop_map(|(a, b)| Damage::Byte(a, b)),
        1 => any::<usize>().prop_map(Damage::Cut),
        2 => any::<usize>().prop_map(Damage::Drop),
        1 => (any::<usize>(), 2usize..40).prop_map(|(a, n)| Damage::Repeat(a, n)),
        4 => (any::<usize>(), number).prop_map(|(a, n)| Damage::Number(a, n)),
        2 => (any::<usize>(), length).prop_map(|(a, n)| Damage::Length(a, n)),
        2 => (any::<usize>(), any::<u8>()).prop_map(|(a, b)| Damage::ZipByte(a, b)),
    ]
}

fn apply(xml: &mut Vec<u8>, zip: &mut [u8], d: &Damage) {
    let text = String::from_utf8_lossy(xml).into_owned();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let n = lines.len().max(1);
    match d {
        Damage::Byte(at, v) => {
            let i = at % xml.len().max(1);
            if let Some(b) = xml.get_mut(i) {
                *b = *v;
            }
            return;
        }
        Damage::Cut(at) => {
            xml.truncate(at % (xml.len() + 1));
            return;
        }
        Damage::ZipByte(at, v) => {
            let i = at % zip.len().max(1);
            if let Some(b) = zip.get_mut(i) {
                *b = *v;
            }
            return;
        }
        Damage::Drop(at) => {
            if !lines.is_empty() {
                lines.remove(at % n);
            }
        }
        Damage::Repeat(at, k) => {
            if !lines.is_empty() {
                let l = lines[at % n].clone();
                let i = at % n;
                lines.splice(i..i, std::iter::repeat_n(l, *k));
            }
        }
        Damage::Number(at, v) => {
            if let Some(i) = (0..n).map(|k| (at + k) % n).find(|&i| {
                lines
                    .get(i)
                    .is_some_and(|l| l.contains("\">") && l.contains("</"))
            }) {
                let l = &lines[i];
                let (open, close) = (l.find("\">").unwrap() + 2, l.rfind("</").unwrap());
                if open <= close {
                    lines[i] = format!("{}{v}{}", &l[..open], &l[close..]);
                }
            }
        }
        Damage::Length(at, v) => {
            if let Some(i) = (0..n)
                .map(|k| (at + k) % n)
                .find(|&i| lines.get(i).is_some_and(|l| l.contains("byteLength=\"")))
            {
                let l = &lines[i];
                let start = l.find("byteLength=\"").unwrap() + 12;
                if let Some(len) = l[start..].find('"') {
                    lines[i] = format!("{}{v}{}", &l[..start], &l[start + len..]);
                }
            }
        }
    }
    *xml = lines.join("\n").into_bytes();
}

#[test]
fn the_undamaged_conversions_import() {
    for (i, (xml, zip)) in conversions().iter().enumerate() {
        let imported = rdc::import(
            Cursor::new(xml),
            Cursor::new(zip),
            SEEDS[i],
            "fuzz",
            Some("1.24"),
            &ImportOptions::default(),
        );
        assert!(imported.is_ok(), "{}: {:?}", SEEDS[i], imported.err());
    }
}

proptest! {
    // Bounded for CI like the other harnesses; every case is a whole import of a real capture.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("FRAMELAB_FUZZ_CASES").ok().and_then(|c| c.parse::<u32>().ok()).map_or(200, |c| c / 2),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn damaged_conversions_never_panic(
        which in 0usize..SEEDS.len(),
        damages in proptest::collection::vec(damage(), 1..4),
    ) {
        let (xml, zip) = &conversions()[which];
        let (mut xml, mut zip) = (xml.clone(), zip.clone());
        for d in &damages {
            apply(&mut xml, &mut zip, d);
        }
        run_import(&xml, &zip);
    }
}
