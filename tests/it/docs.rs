//! The manual's commands stay current: every `framelab` command written in the README and in
//! `docs/` (in `sh` blocks, and inline where it is a literal command line) is given to the
//! command line with `--help` after its arguments, so each subcommand, flag and value it names
//! is parsed as users would type it; one that no longer parses fails here. The pages' local
//! links are checked to lead somewhere too.

use std::path::{Path, PathBuf};

use crate::common::repo;

/// The README and every chapter under `docs/`.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![repo().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(repo().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

/// A line split into words as a shell would: quotes group, a backslash escapes.
fn words(line: &str) -> Vec<String> {
    let (mut out, mut word, mut quote, mut any) = (Vec::new(), String::new(), None, false);
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        match (quote, c) {
            (None, '\'' | '"') => {
                quote = Some(c);
                any = true;
            }
            (Some(q), c) if c == q => quote = None,
            (None, '\\') => {
                if let Some(n) = chars.next() {
                    word.push(n);
                }
            }
            (None, c) if c.is_whitespace() => {
                if any || !word.is_empty() {
                    out.push(std::mem::take(&mut word));
                }
                any = false;
            }
            (_, c) => word.push(c),
        }
    }
    if any || !word.is_empty() {
        out.push(word);
    }
    out
}

/// The `framelab` commands of one shell line: comments, redirections, pipes, `&&`, `&` and
/// environment assignments left out; `cargo run ... -- ARGS` counts as `framelab ARGS`.
fn commands_of(line: &str) -> Vec<Vec<String>> {
    let line = line.split(" #").next().unwrap_or("");
    let mut out = Vec::new();
    for part in line.split("&&").flat_map(|p| p.split(['|', ';', '&'])) {
        let part = part.split('>').next().unwrap_or("");
        let w = words(part);
        let start = w.iter().position(|x| !x.contains('='));
        let Some(start) = start else { continue };
        let w = &w[start..];
        match w.first().map(String::as_str) {
            Some("framelab") => out.push(w[1..].to_vec()),
            Some("cargo") if w.get(1).is_some_and(|x| x == "run") => {
                if let Some(dash) = w.iter().position(|x| x == "--") {
                    out.push(w[dash + 1..].to_vec());
                }
            }
            _ => {}
        }
    }
    out
}

/// Every command the page writes out, with where.
fn commands(page: &Path) -> Vec<(String, Vec<String>)> {
    let text = std::fs::read_to_string(page).unwrap();
    let name = page.file_name().unwrap().to_string_lossy().into_owned();
    let mut out = Vec::new();
    let mut in_sh = false;
    let mut in_block = false;
    let mut pending = String::new();
    // Prose outside code blocks, for the inline spans (which may run over a line break).
    let mut prose = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.starts_with("```") {
            in_sh = !in_block && ["```sh", "```bash", "```console"].contains(&trimmed);
            in_block = !in_block;
            continue;
        }
        if in_sh {
            if let Some(head) = line.strip_suffix('\\') {
                pending.push_str(head);
                continue;
            }
            pending.push_str(line);
            for c in commands_of(&std::mem::take(&mut pending)) {
                out.push((format!("{name}:{}", n + 1), c));
            }
        } else if !in_block {
            prose.push((n + 1, line));
        }
    }
    // Inline: `framelab SUBCOMMAND ...` spans that are literal command lines (no placeholders
    // or alternatives).
    let mut joined = String::new();
    let mut line_at = Vec::new();
    for (n, line) in prose {
        line_at.push((joined.len(), n));
        joined.push_str(line);
        joined.push(' ');
    }
    let mut offset = 0;
    for (k, span) in joined.split('`').enumerate() {
        let start = offset;
        offset += span.len() + 1;
        if k % 2 == 0 {
            continue;
        }
        let literal = !span.contains(['[', ']', '<', '>', '|', '…']) && !span.contains("...");
        if let Some(rest) = span.strip_prefix("framelab ")
            && literal
            && rest.split_whitespace().count() > 1
        {
            let n = line_at
                .iter()
                .rev()
                .find(|(o, _)| *o <= start)
                .map_or(0, |x| x.1);
            out.push((format!("{name}:{n}"), words(rest)));
        }
    }
    out
}

#[test]
fn every_command_in_the_manual_parses() {
    let mut checked = 0;
    let mut failed = Vec::new();
    for page in pages() {
        for (at, mut args) in commands(&page) {
            // Before a `--` that hands the rest to a program, so the help is framelab's.
            let at_dash = args.iter().position(|a| a == "--").unwrap_or(args.len());
            args.insert(at_dash, "--help".to_owned());
            let out = std::process::Command::new(env!("CARGO_BIN_EXE_framelab"))
                .args(&args)
                .current_dir(repo())
                .output()
                .unwrap();
            checked += 1;
            let said = String::from_utf8_lossy(&out.stdout);
            if !out.status.success() || !said.contains("Usage:") {
                failed.push(format!(
                    "{at}: framelab {}\n{}",
                    args.join(" "),
                    String::from_utf8_lossy(&out.stderr)
                ));
            }
        }
    }
    assert!(checked >= 30, "only {checked} commands found");
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn the_manuals_local_links_lead_somewhere() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let dir = page.parent().unwrap();
        for (start, _) in text.match_indices("](") {
            let target: String = text[start + 2..]
                .chars()
                .take_while(|c| *c != ')' && !c.is_whitespace())
                .collect();
            let path = target.split('#').next().unwrap_or("");
            if path.is_empty() || target.starts_with("http") {
                continue;
            }
            if !dir.join(path).exists() {
                broken.push(format!("{}: {target}", page.display()));
            }
        }
    }
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}
