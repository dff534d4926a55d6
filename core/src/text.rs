//! Plain-text helpers shared by every report: byte sizes for people, padded tables, and text
//! from an input made safe for a terminal.

use std::borrow::Cow;

/// `text` with every control character but newline and tab written as an escape (`\u{1b}`):
/// a name or message taken from an input could otherwise move, recolour or erase what a
/// terminal shows.
pub fn printable(text: &str) -> Cow<'_, str> {
    escaped(text, |c| is_hidden(c) && c != '\n' && c != '\t')
}

/// `text` for one line of a report: as `printable`, and a newline or tab written as an
/// escape too, so a name read from an input cannot begin a line of its own. Past
/// `ONE_LINE_CHARS` characters the rest is counted, not shown: an input's megabyte-long
/// name would otherwise be the whole report.
pub fn one_line(text: &str) -> Cow<'_, str> {
    one_line_within(text, ONE_LINE_CHARS)
}

/// `one_line` for a longer text of framelab's own that quotes inputs (a note listing names):
/// cut after `max` characters.
pub fn one_line_within(text: &str, max: usize) -> Cow<'_, str> {
    match cut(text, max) {
        Cow::Borrowed(t) => escaped(t, is_hidden),
        Cow::Owned(t) => Cow::Owned(escaped(&t, is_hidden).into_owned()),
    }
}

/// `text` cut after `max` characters, the rest counted: `abc... (12 more bytes)`.
pub fn cut(text: &str, max: usize) -> Cow<'_, str> {
    match text.char_indices().nth(max) {
        None => Cow::Borrowed(text),
        Some((at, _)) => Cow::Owned(format!(
            "{}... ({} more bytes)",
            &text[..at],
            text.len() - at
        )),
    }
}

/// `a, b, c and 4 more`: at most `max` names of a list a report gives in one line.
pub fn listed(names: &[String], max: usize) -> String {
    if names.len() <= max {
        return names.join(", ");
    }
    format!("{} and {} more", names[..max].join(", "), names.len() - max)
}

/// The most characters of an input's text a one-line report shows.
pub const ONE_LINE_CHARS: usize = 200;

fn escaped(text: &str, hidden: fn(char) -> bool) -> Cow<'_, str> {
    if !text.chars().any(hidden) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if hidden(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// Control characters, and the invisible ones that reorder or hide text (bidirectional
/// overrides and isolates, zero-width spaces and joiners, the byte-order mark): a name holding
/// them could show as another name.
fn is_hidden(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{200B}'..='\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2060}'..='\u{2064}' | '\u{2066}'..='\u{2069}' | '\u{FEFF}')
}

/// The widest a column is padded to: a longer cell overflows its row rather than widening
/// every row (one long name must not multiply the report by the number of rows).
pub const MAX_COLUMN: usize = 160;

/// Pads columns to their widest cell, at most `MAX_COLUMN` characters.
pub fn table(headers: &[&str], rows: &[Vec<String>]) -> String {
    let mut widths: Vec<usize> = headers.iter().map(|h| h.len()).collect();
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count().min(MAX_COLUMN));
        }
    }
    let mut out = String::new();
    let line = |out: &mut String, cells: &mut dyn Iterator<Item = &str>| {
        let mut first = true;
        for (cell, w) in cells.zip(&widths) {
            if !first {
                out.push_str("  ");
            }
            first = false;
            // Padded by hand: a width argument above 65,535 (a pass named by a very long
            // string) is out of range for `format!`.
            out.push_str(cell);
            let len = cell.chars().count();
            out.extend(std::iter::repeat_n(' ', w.saturating_sub(len)));
        }
        let trimmed = out.trim_end().len();
        out.truncate(trimmed);
        out.push('\n');
    };
    line(&mut out, &mut headers.iter().copied());
    let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
    line(&mut out, &mut rule.iter().map(String::as_str));
    for row in rows {
        line(&mut out, &mut row.iter().map(String::as_str));
    }
    out
}

/// The first five names, joined by commas, and ", ..." where there are more.
pub fn first_few<S: AsRef<str>>(names: &[S]) -> String {
    const SHOWN: usize = 5;
    let mut text = names
        .iter()
        .take(SHOWN)
        .map(AsRef::as_ref)
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > SHOWN {
        text.push_str(", ...");
    }
    text
}

pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 7] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u < UNITS.len() - 1 {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_for_terminals() {
        assert!(matches!(printable("plain\tline\n"), Cow::Borrowed(_)));
        assert_eq!(printable("a\u{1b}[2Jb\u{7}\r"), "a\\u{1b}[2Jb\\u{7}\\r");
        assert_eq!(printable("\u{9b}é"), "\\u{9b}é");
        assert_eq!(one_line("vkX\nerror: forged\t"), "vkX\\nerror: forged\\t");
        assert!(matches!(one_line("vkCmdDraw"), Cow::Borrowed(_)));
        let long = format!("vk{}", "é".repeat(1000));
        assert_eq!(one_line("a\u{202E}b\u{200B}"), "a\\u{202e}b\\u{200b}");
        assert_eq!(printable("x\ny\u{2066}"), "x\ny\\u{2066}");
        let rows = vec![
            vec!["a".to_owned(), "x".repeat(10_000), "z".to_owned()],
            vec!["b".to_owned(), "y".to_owned(), "z".to_owned()],
        ];
        let t = table(&["k", "v", "w"], &rows);
        assert!(t.len() < 10_000 + 4 * MAX_COLUMN, "{}", t.len());
        assert!(t.contains(&format!("b  y{}  z", " ".repeat(MAX_COLUMN - 1))));
        let names: Vec<String> = (0..10).map(|i| format!("n{i}")).collect();
        assert_eq!(listed(&names[..3], 4), "n0, n1, n2");
        assert_eq!(listed(&names, 4), "n0, n1, n2, n3 and 6 more");
        let shown = one_line(&long);
        assert!(shown.starts_with("vkéé"), "{shown}");
        assert!(shown.ends_with("é... (1604 more bytes)"), "{shown}");
    }

    #[test]
    fn tables_pad_to_the_widest_cell() {
        let t = table(&["a", "bb"], &[vec!["long cell".into(), "x".into()]]);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[0], "a          bb");
        assert_eq!(lines[1], "---------  --");
        assert_eq!(lines[2], "long cell  x");
    }

    #[test]
    fn a_cell_longer_than_a_column_overflows_its_row_alone() {
        let long = "n".repeat(70_000);
        let t = table(
            &["a", "b"],
            &[vec![long.clone(), "x".into()], vec!["y".into(), "z".into()]],
        );
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[1].len(), MAX_COLUMN + 3);
        assert_eq!(lines[2], format!("{long}  x"));
        assert_eq!(lines[3].len(), MAX_COLUMN + 3);
    }
}
