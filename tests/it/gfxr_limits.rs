//! What an import of a binary capture may not do whatever the file says: take memory its
//! blocks claim but nothing backs (a few bytes of zstd can claim gigabytes), or replace what
//! it should not (its own input, a folder of the user's files, a link, a pipe).

use std::path::Path;

use crate::common::{framelab, gfxr_fixture, json, stderr};
use crate::gfxr_binary::{block_offsets, edited, refused, temp_dir};

/// A compressed block of `kind` (call 4 or meta-data 3) with `id`, `fields` and `payload`.
fn compressed_block(kind: u32, id: u32, fields: &[u64], payload: &[u8]) -> Vec<u8> {
    let size = 4 + 8 * fields.len() + payload.len();
    let mut b = Vec::new();
    b.extend_from_slice(&(size as u64).to_le_bytes());
    b.extend_from_slice(&(0x8000_0000 | kind).to_le_bytes());
    b.extend_from_slice(&id.to_le_bytes());
    for f in fields {
        b.extend_from_slice(&f.to_le_bytes());
    }
    b.extend_from_slice(payload);
    b
}

#[test]
fn a_small_block_cannot_claim_gigabytes() {
    let dir = temp_dir("claims");
    let name = "vkcube_f3_zstd.gfxr";
    let first = block_offsets(&std::fs::read(gfxr_fixture(name)).unwrap())[0];
    let claim = 3u64 << 30;
    // Three bytes of (not even valid) zstd that say they are 3 GiB of call parameters
    // (vkCreateBuffer's id; thread 1). The claim is refused before anything is decompressed.
    let call = compressed_block(4, 0x1008, &[1, claim], &[0x28, 0xb5, 0x2f]);
    let e = refused(
        &edited(&dir, name, |b| {
            b.splice(first..first, call);
        }),
        &dir,
    );
    assert!(
        e.contains(&format!("block 0 at byte {first}")) && e.contains("over the 256 MiB"),
        "{e}"
    );
    // A memory fill (meta-data command 2: thread, memory, offset, size) of 3 GiB into memory
    // the capture never allocated.
    let fill = compressed_block(3, 2, &[1, 0xdead, 0, claim], &[0x28, 0xb5, 0x2f]);
    let e = refused(
        &edited(&dir, name, |b| {
            b.splice(first..first, fill);
        }),
        &dir,
    );
    assert!(
        e.contains(&format!("block 0 at byte {first}"))
            && e.contains("memory 0xdead, which the capture never allocated"),
        "{e}"
    );
}

fn import(input: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "import",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    framelab(&args)
}

#[test]
fn an_import_replaces_only_what_it_wrote() {
    let dir = temp_dir("replaces");
    let d: &Path = &dir;
    let input = d.join("cube.gfxr");
    std::fs::copy(gfxr_fixture("vkcube_f3.gfxr"), &input).unwrap();
    let original = std::fs::read(&input).unwrap();

    // Its own input.
    let o = import(&input, &input, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is also what this command reads"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&input).unwrap(), original);

    // A folder where the capture would go: refused before any side file is written.
    std::fs::create_dir(d.join("taken")).unwrap();
    let o = import(&input, &d.join("taken"), &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("it is a directory"), "{}", stderr(&o));
    for side in ["taken.contents", "taken.shaders"] {
        assert!(!d.join(side).exists(), "{side} left behind");
    }

    // A side folder holding a file the import did not write.
    std::fs::create_dir(d.join("cap.shaders")).unwrap();
    std::fs::write(d.join("cap.shaders/notes.txt"), b"mine").unwrap();
    let o = import(&input, &d.join("cap.json"), &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("notes.txt"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(d.join("cap.shaders/notes.txt")).unwrap(),
        b"mine"
    );
    assert!(!d.join("cap.json").exists());
    // Its own side folder, though, is replaced by the next import.
    std::fs::remove_file(d.join("cap.shaders/notes.txt")).unwrap();
    for _ in 0..2 {
        let o = import(&input, &d.join("cap.json"), &[]);
        assert!(o.status.success(), "{}", stderr(&o));
    }

    // A link is written through: the capture lands where it leads, its side folders beside
    // it, and the link stays a link.
    std::fs::create_dir(d.join("real")).unwrap();
    std::os::unix::fs::symlink("real/linked.json", d.join("link.json")).unwrap();
    let o = import(&input, &d.join("link.json"), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(crate::common::is_symlink(&d.join("link.json")));
    assert!(d.join("real/linked.json").is_file());
    assert!(d.join("real/linked.shaders").is_dir());
    let o = framelab(&["validate", d.join("link.json").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn frames_past_the_end_are_refused_and_a_partial_read_says_so() {
    let dir = temp_dir("frames");
    let input = gfxr_fixture("vkcube_whole.gfxr");
    let out = dir.join("w.json");
    let o = import(&input, &out, &["--frames", "2-5"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("frames 2-5 were asked for, but the stream holds 3 frame(s)"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let o = import(&input, &out, &["--frames", "1-1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = crate::common::stdout(&o);
    assert!(text.contains("read up to the end of frame 1: "), "{text}");
    let o = import(&input, &out, &["--frames", "1-1", "--json"]);
    assert_eq!(json(&o)["stopped_after_selection"], true);
    let o = import(&input, &out, &["--json"]);
    let whole = json(&o);
    assert_eq!(whole["stopped_after_selection"], false);
    assert_eq!(whole["frames_in_stream"], 3);
}

/// `template_compute` records three barriers: two before its dispatches, and a compute-to-host
/// barrier after them that no pass follows. The summary counts the two and names the third.
#[test]
fn a_barrier_after_the_last_pass_is_named_not_lost() {
    let dir = temp_dir("trailing");
    let o = import(
        &gfxr_fixture("template_compute.gfxr"),
        &dir.join("t.json"),
        &["--json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let s = json(&o);
    assert_eq!(s["recorded_barriers"], 2);
    let trailing: Vec<&serde_json::Value> = s["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|k| {
            k["what"]
                .as_str()
                .unwrap()
                .starts_with("barriers after the last pass")
        })
        .collect();
    assert_eq!(trailing.len(), 1, "{}", s["skipped"]);
    assert_eq!(trailing[0]["count"], 1);
}

/// One submission listing the same command buffer 70,000 times (the vkd3d triangle's upload
/// buffer, which records barriers and clears): a few bytes a repetition in the stream. The
/// import stops at its pass ceiling, says so, and writes a capture framelab still reads.
#[test]
fn a_command_buffer_submitted_over_and_over_stops_at_the_pass_ceiling() {
    let dir = temp_dir("resubmitted");
    let text = std::fs::read_to_string(gfxr_fixture("vkd3d_triangle.jsonl")).unwrap();
    let n = 70_000;
    let many = vec!["16"; n].join(",");
    let mut replaced = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            if l.contains("\"vkQueueSubmit\"") && l.contains("\"pCommandBuffers\":[16]") {
                replaced += 1;
                l.replace(
                    "\"pCommandBuffers\":[16]",
                    &format!("\"pCommandBuffers\":[{many}]"),
                )
                .replace(
                    "\"commandBufferCount\":1",
                    &format!("\"commandBufferCount\":{n}"),
                )
            } else {
                l.to_owned()
            }
        })
        .collect();
    assert_eq!(replaced, 1, "the triangle's upload submission");
    let stream = dir.join("resubmitted.jsonl");
    std::fs::write(&stream, lines.join("\n") + "\n").unwrap();
    let out = dir.join("r.json");
    let o = import(&stream, &out, &["--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = json(&o);
    assert_eq!(s["passes"], 65_536);
    let skipped = s["skipped"].to_string();
    assert!(
        skipped.contains("passes beyond the limit of 65536"),
        "{skipped}"
    );
    let why = s["not_replayable"].to_string();
    assert!(why.contains("passes beyond the limit of 65536"), "{why}");
    let o = framelab(&["info", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}
