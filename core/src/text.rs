//! Plain-text helpers shared by every report: byte sizes for people, padded tables, and text
//! from an input made safe for a terminal.

use std::borrow::Cow;

/// `text` with every control character but newline and tab written as an escape (`\u{1b}`):
/// a name or message taken from an input could otherwise move, recolour or erase what a
/// terminal shows.
pub fn printable(text: &str) -> Cow<'_, str> {
    escaped(text, is_hidden)
}

/// `text` for one line of a report: as `printable`, and a newline or tab written as an
/// escape too, so a name read from an input cannot begin a line of its own. Past
/// `ONE_LINE_CHARS` characters the rest is counted, not shown: an input's megabyte-long
/// name would otherwise be the whole report.
pub fn one_line(text: &str) -> Cow<'_, str> {
    match text.char_indices().nth(ONE_LINE_CHARS) {
        None => escaped(text, char::is_control),
        Some((cut, _)) => Cow::Owned(format!(
            "{}... ({} more bytes)",
            escaped(&text[..cut], char::is_control),
            text.len() - cut
        )),
    }
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

fn is_hidden(c: char) -> bool {
    c.is_control() && c != '\n' && c != '\t'
}

/// Pads columns to their widest cell.
pub fn table(headers: &[&str], rows: &[Vec<String>]) -> String {
    let mut widths: Vec<usize> = headers.iter().map(|h| h.len()).collect();
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
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
    fn cells_longer_than_a_format_width_are_padded() {
        let long = "n".repeat(70_000);
        let t = table(
            &["a", "b"],
            &[vec![long.clone(), "x".into()], vec!["y".into(), "z".into()]],
        );
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[2], format!("{long}  x"));
        assert_eq!(lines[3].len(), 70_000 + 3);
    }
}
