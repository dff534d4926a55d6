//! The structural diff as people read it: frame counts and memory side by side, then one line
//! per change (added, removed, renamed, moved, changed) as a text table or, for a pull-request
//! comment, Markdown.

use serde_json::Value;

use super::{Change, NamedChanges, StructureDiff};
use crate::text::{human_bytes, table};

/// A value as a person writes it: strings bare, lists comma-separated.
fn show(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Null => "-".to_owned(),
        Value::Array(items) => items.iter().map(show).collect::<Vec<_>>().join(", "),
        other => other.to_string(),
    }
}

/// `field a -> b`, or for lists what B adds and drops.
fn change(c: &Change) -> String {
    match (&c.a, &c.b) {
        (Value::Array(a), Value::Array(b)) => {
            // Names in natural order (`buffer_7` before `buffer_17`), additions then removals.
            let sorted = |mut v: Vec<String>| {
                v.sort_by(|x, y| alphanumeric_sort::compare_str(x, y));
                v
            };
            let plus = sorted(b.iter().filter(|x| !a.contains(x)).map(show).collect());
            let minus = sorted(a.iter().filter(|x| !b.contains(x)).map(show).collect());
            let mut parts = Vec::new();
            if !plus.is_empty() {
                parts.push(format!("+{}", plus.join(", +")));
            }
            if !minus.is_empty() {
                parts.push(format!("-{}", minus.join(", -")));
            }
            if parts.is_empty() {
                // Same items, another order.
                parts.push(format!("{} -> {}", show(&c.a), show(&c.b)));
            }
            format!("{} {}", c.field, parts.join(", "))
        }
        _ => format!("{} {} -> {}", c.field, show(&c.a), show(&c.b)),
    }
}

fn row(what: &str, name: &str, detail: String) -> Vec<String> {
    vec![what.to_owned(), name.to_owned(), detail]
}

fn details(changes: &[Change]) -> String {
    changes.iter().map(change).collect::<Vec<_>>().join("; ")
}

fn named_rows(section: &str, n: &NamedChanges, rows: &mut Vec<Vec<String>>) {
    for a in &n.added {
        rows.push(row(&format!("{section} added"), a, String::new()));
    }
    for r in &n.removed {
        rows.push(row(&format!("{section} removed"), r, String::new()));
    }
    for c in &n.changed {
        rows.push(row(
            &format!("{section} changed"),
            &c.name,
            details(&c.changes),
        ));
    }
}

/// Rows of (what, name, change) for every difference, in section order.
fn change_rows(d: &StructureDiff) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    named_rows("queue", &d.queues, &mut rows);
    let p = &d.passes;
    for a in &p.added {
        rows.push(row("pass added", a, String::new()));
    }
    for r in &p.removed {
        rows.push(row("pass removed", r, String::new()));
    }
    for r in &p.renamed {
        rows.push(row("pass renamed", &r.from, format!("now {}", r.to)));
    }
    for m in &p.moved {
        rows.push(row(
            "pass moved",
            &m.pass,
            format!("queue {} -> {}", m.from, m.to),
        ));
    }
    for c in &p.changed {
        rows.push(row("pass changed", &c.name, details(&c.changes)));
    }
    named_rows("resource", &d.resources, &mut rows);
    named_rows("fence", &d.fences, &mut rows);
    rows
}

fn count_rows(d: &StructureDiff) -> Vec<Vec<String>> {
    let c = &d.counts;
    [
        ("passes", c.passes),
        ("resources", c.resources),
        ("draws", c.draws),
        ("dispatches", c.dispatches),
        ("copies", c.copies),
        ("fences", c.fences),
    ]
    .iter()
    .map(|(name, [a, b])| vec![(*name).to_owned(), a.to_string(), b.to_string()])
    .collect()
}

fn memory_rows(d: &StructureDiff) -> Vec<Vec<String>> {
    let pair = |[a, b]: [u64; 2]| {
        if a == b {
            human_bytes(a)
        } else {
            format!("{} -> {}", human_bytes(a), human_bytes(b))
        }
    };
    d.memory
        .iter()
        .map(|m| {
            vec![
                m.heap_type.clone(),
                pair(m.unaliased_bytes),
                pair(m.aliased_bytes),
                pair(m.lower_bound_bytes),
            ]
        })
        .collect()
}

const COUNT_HEADERS: [&str; 3] = ["", "A", "B"];
const MEMORY_HEADERS: [&str; 4] = ["heap type", "unaliased", "aliased", "lower bound"];
const CHANGE_HEADERS: [&str; 3] = ["what", "name", "change"];

fn heading(d: &StructureDiff) -> String {
    let scale = if d.a.scale == d.b.scale {
        format!("scale {}", d.a.scale)
    } else {
        format!("scale {} (A) and {} (B)", d.a.scale, d.b.scale)
    };
    format!(
        "{} ({}) against {} ({}), {scale}",
        d.a.capture, d.a.source, d.b.capture, d.b.source
    )
}

/// The structural diff as text.
pub fn text(d: &StructureDiff) -> String {
    let changes = if d.is_empty() {
        "no structural change\n".to_owned()
    } else {
        table(&CHANGE_HEADERS, &change_rows(d))
    };
    format!(
        "{}\n\n{}\nmemory\n{}\n{changes}",
        heading(d),
        table(&COUNT_HEADERS, &count_rows(d)),
        table(&MEMORY_HEADERS, &memory_rows(d)),
    )
}

fn markdown_table(headers: &[&str], rows: &[Vec<String>]) -> String {
    let cell = |s: &str| s.replace('|', "\\|").replace('\n', " ");
    let mut out = format!("| {} |\n", headers.join(" | "));
    out.push_str(&format!("|{}\n", " --- |".repeat(headers.len())));
    for r in rows {
        let cells: Vec<String> = r.iter().map(|c| cell(c)).collect();
        out.push_str(&format!("| {} |\n", cells.join(" | ")));
    }
    out
}

/// The structural diff as Markdown.
pub fn markdown(d: &StructureDiff) -> String {
    let changes = if d.is_empty() {
        "No structural change.\n".to_owned()
    } else {
        markdown_table(&CHANGE_HEADERS, &change_rows(d))
    };
    format!(
        "### Frame structure diff\n\n{}\n\n{}\n{}\n{changes}",
        heading(d),
        markdown_table(&COUNT_HEADERS, &count_rows(d)),
        markdown_table(&MEMORY_HEADERS, &memory_rows(d)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_list_change_gives_additions_then_removals_in_natural_order() {
        let list = |v: &[&str]| Value::Array(v.iter().map(|s| Value::from(*s)).collect());
        let c = Change {
            field: "writes".into(),
            a: list(&["buffer_17", "image_11", "buffer_7", "kept"]),
            b: list(&["kept", "image_48", "image_9"]),
        };
        assert_eq!(
            change(&c),
            "writes +image_9, +image_48, -buffer_7, -buffer_17, -image_11"
        );
    }
}
