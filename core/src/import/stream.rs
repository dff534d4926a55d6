//! Reading a GFXReconstruct JSON Lines stream one line at a time, in bounded memory, and
//! telling its two dialects apart: 0.9.x writes calls as `{"index", "vkFunc": {...}}`, 1.x as
//! `{"index", "function": {...}}` with `meta`, `state` and `frame` marker lines besides.

use std::borrow::Cow;
use std::fmt;
use std::io::{BufRead, Read};

use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, Visitor};
use serde_json::error::Category;

use super::calls::Func;
use super::tree::{Node, Put, Tree};

/// Longest line read; a longer one is refused rather than buffered. Parsed, a call's line of
/// numbers takes about 70 times its size (a tree node and an element per number); the longest
/// line of any bundled stream is 6.6 KB.
pub const MAX_LINE_BYTES: u64 = 16 << 20;

/// One API call of the stream.
#[derive(Debug)]
pub struct Call {
    /// Line number in the stream (1-based), for messages.
    pub line: u64,
    /// The converter's block index.
    pub index: u64,
    pub name: Cow<'static, str>,
    /// The function `name` names, decoded once here for every later pass.
    pub func: Func,
    pub args: Tree,
    /// `VK_SUCCESS` or an error code; absent for void functions.
    pub result: Option<Cow<'static, str>>,
    /// `0.9.x` for `vkFunc` lines, `1.x` for `function` lines.
    pub dialect: &'static str,
}

/// What one line holds.
#[derive(Debug)]
pub enum Entry {
    Header {
        gfxr_version: String,
        json_version: String,
    },
    Call(Call),
    /// A 1.x `frame` end marker.
    FrameEnd,
    /// Annotations, meta commands, D3D12 methods, other markers: counted, not used.
    Other(String),
}

/// Failure to read the stream: the line and what is wrong.
#[derive(Debug)]
pub struct LineError {
    pub line: u64,
    pub message: String,
}

pub struct Lines<R> {
    reader: R,
    line: u64,
    buf: Vec<u8>,
}

impl<R: BufRead> Lines<R> {
    pub fn new(reader: R) -> Self {
        Lines {
            reader,
            line: 0,
            buf: Vec::new(),
        }
    }

    /// The next entry; `None` at the end of the stream.
    pub fn next_entry(&mut self) -> Option<Result<Entry, LineError>> {
        loop {
            self.buf.clear();
            self.line += 1;
            let line = self.line;
            let read = (&mut self.reader)
                .take(MAX_LINE_BYTES + 1)
                .read_until(b'\n', &mut self.buf);
            match read {
                Ok(0) => return None,
                // The limit is on the line, not on its newline.
                Ok(n) if n as u64 > MAX_LINE_BYTES && !self.buf.ends_with(b"\n") => {
                    return Some(Err(LineError {
                        line,
                        message: format!(
                            "line longer than {} MiB; is this a JSON Lines stream?",
                            MAX_LINE_BYTES >> 20
                        ),
                    }));
                }
                Ok(_) => {}
                Err(e) => {
                    return Some(Err(LineError {
                        line,
                        message: format!("cannot read: {e}"),
                    }));
                }
            }
            // Editors may start a file with a UTF-8 byte-order mark.
            let body = match (line, self.buf.strip_prefix(b"\xEF\xBB\xBF")) {
                (1, Some(rest)) => rest,
                _ => &self.buf[..],
            };
            let text = trim_ascii(body);
            if text.is_empty() {
                continue;
            }
            // The converter's plain-JSON format wraps the lines in `[` ... `]` with commas.
            let text = text.strip_suffix(b",").unwrap_or(text);
            if text == b"[" || text == b"]" {
                continue;
            }
            return Some(parse_entry(text, line));
        }
    }
}

fn trim_ascii(b: &[u8]) -> &[u8] {
    let start = b
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(b.len());
    let end = b
        .iter()
        .rposition(|c| !c.is_ascii_whitespace())
        .map_or(start, |e| e + 1);
    &b[start..end.max(start)]
}

/// The members of a line the importer reads, put into one tree as they are parsed; every
/// other member is skipped without being built, so a line costs only what is kept of it.
#[derive(Default)]
struct Members {
    header: Option<usize>,
    func: Option<(&'static str, usize)>,
    frame: Option<usize>,
    index: Option<usize>,
    /// The first other member's name, which says what the line is.
    other: Option<String>,
}

struct LineSeed<'t>(&'t mut Tree);

impl<'de> DeserializeSeed<'de> for LineSeed<'_> {
    type Value = Members;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Members, D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for LineSeed<'_> {
    type Value = Members;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON object per line")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Members, A::Error> {
        let mut m = Members::default();
        while let Some(key) = map.next_key::<Cow<'de, str>>()? {
            let slot = match key.as_ref() {
                "header" => &mut m.header,
                "frame" => &mut m.frame,
                "index" => &mut m.index,
                "vkFunc" | "function" => {
                    if let Some((first, _)) = m.func {
                        return Err(de::Error::custom(format_args!(
                            "`{first}` and `{key}` in one line"
                        )));
                    }
                    let name = if key == "vkFunc" {
                        "vkFunc"
                    } else {
                        "function"
                    };
                    m.func = Some((name, map.next_value_seed(Put(self.0))?));
                    continue;
                }
                _ => {
                    map.next_value::<IgnoredAny>()?;
                    if m.other.is_none() {
                        m.other = Some(key.into_owned());
                    }
                    continue;
                }
            };
            if slot.is_some() {
                return Err(de::Error::custom(format_args!(
                    "member `{key}` given twice"
                )));
            }
            *slot = Some(map.next_value_seed(Put(self.0))?);
        }
        Ok(m)
    }
}

fn parse_entry(text: &[u8], line: u64) -> Result<Entry, LineError> {
    let err = |message: String| LineError { line, message };
    let mut tree = Tree::default();
    let mut de = serde_json::Deserializer::from_slice(text);
    let parsed = LineSeed(&mut tree)
        .deserialize(&mut de)
        .and_then(|m| de.end().map(|()| m));
    let m = parsed.map_err(|e| {
        // serde_json counts lines within the one it was given: only the column says more.
        let what = e.to_string();
        let what = what
            .rsplit_once(" at line ")
            .map_or(what.as_str(), |(m, _)| m)
            .to_owned();
        let at = e.column();
        err(match e.classify() {
            Category::Eof => format!("truncated JSON ({what}, column {at})"),
            Category::Data if !text.starts_with(b"{") => {
                "expected a JSON object per line".to_owned()
            }
            Category::Data => format!("{what}, column {at}"),
            Category::Syntax | Category::Io => format!("not JSON: {what}, column {at}"),
        })
    })?;
    let str_at = |tree: &Tree, node: Option<usize>, key: &str| -> Option<String> {
        match tree.node(tree.get(node?, key)?) {
            Node::Str(t) => Some(tree.text(t).to_owned()),
            _ => None,
        }
    };
    if let Some(h) = m.header {
        let field = |k: &str| str_at(&tree, Some(h), k).unwrap_or_else(|| "unknown".to_owned());
        return Ok(Entry::Header {
            gfxr_version: field("gfxrecon-version"),
            json_version: field("json-version"),
        });
    }
    if let Some((key, f)) = m.func {
        let dialect = if key == "vkFunc" { "0.9.x" } else { "1.x" };
        if !matches!(tree.node(f), Node::Object(_)) {
            return Err(err(format!("`{key}` is not an object")));
        }
        let Some(name) = str_at(&tree, Some(f), "name") else {
            return Err(err(format!("`{key}.name` is missing or not a string")));
        };
        let index = match m.index.map(|i| tree.node(i)) {
            Some(Node::U64(i)) => i,
            _ => 0,
        };
        let result = match tree.get(f, "return").map(|r| tree.node(r)) {
            Some(Node::Str(t)) => Some(Cow::Owned(tree.text(t).to_owned())),
            Some(Node::Null) | None => None,
            Some(_) => tree
                .get(f, "return")
                .map(|r| Cow::Owned(tree.to_json(r).to_string())),
        };
        let args = match tree.get(f, "args") {
            Some(a) => a,
            None => tree.leaf(Node::Null),
        };
        tree.set_root(args);
        return Ok(Entry::Call(Call {
            line,
            index,
            func: Func::of(&name),
            // The registry's own name where it has one, so every origin the call's
            // commands carry borrows it.
            name: super::gfxr::registry::command_named(&name)
                .map_or(Cow::Owned(name), |c| Cow::Borrowed(c.name)),
            args: tree,
            result,
            dialect,
        }));
    }
    if let Some(frame) = m.frame {
        let end = str_at(&tree, Some(frame), "marker_type").as_deref() == Some("EndMarker");
        return Ok(if end {
            Entry::FrameEnd
        } else {
            Entry::Other("frame marker".to_owned())
        });
    }
    Ok(Entry::Other(m.other.unwrap_or_else(|| {
        if m.index.is_some() {
            "index only"
        } else {
            "empty object"
        }
        .to_owned()
    })))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(text: &str) -> Vec<Result<Entry, LineError>> {
        let mut lines = Lines::new(text.as_bytes());
        std::iter::from_fn(|| lines.next_entry()).collect()
    }

    #[test]
    fn both_dialects_and_bad_lines() {
        let got = entries(concat!(
            "{\"header\":{\"json-version\":\"0.8.0\",\"gfxrecon-version\":\"0.9.18\"}}\n",
            "{\"index\":3,\"vkFunc\":{\"name\":\"vkCmdDraw\",\"args\":{\"vertexCount\":3}}}\n",
            "\n",
            "{\"index\":4,\"function\":{\"name\":\"vkQueueSubmit\",\"thread\":1,\"return\":\"VK_SUCCESS\",\"args\":{}}}\n",
            "{\"frame\":{\"marker_type\":\"EndMarker\",\"frame_number\":1}}\n",
            "{\"index\":5,\"vkFunc\":{\"name\":\"vkCmdDraw\",\"args\":{\"vert\n",
            "[1,2]\n",
        ));
        assert!(
            matches!(&got[0], Ok(Entry::Header { json_version, .. }) if json_version == "0.8.0")
        );
        assert!(
            matches!(&got[1], Ok(Entry::Call(c)) if c.name == "vkCmdDraw" && c.line == 2 && c.index == 3)
        );
        assert!(
            matches!(&got[2], Ok(Entry::Call(c)) if c.result.as_deref() == Some("VK_SUCCESS") && c.line == 4)
        );
        assert!(matches!(&got[3], Ok(Entry::FrameEnd)));
        assert!(
            matches!(&got[4], Err(e) if e.line == 6 && e.message.starts_with("truncated JSON"))
        );
        assert!(matches!(&got[5], Err(e) if e.line == 7 && e.message.contains("object")));
    }

    #[test]
    fn only_what_is_read_is_kept_and_repeats_are_refused() {
        let got = entries(concat!(
            "{\"index\":1,\"meta\":{\"name\":\"FillMemoryCommand\",\"data\":[1,2,3]}}\n",
            "{\"index\":2,\"vkFunc\":{\"args\":{\"vertexCount\":3},\"name\":\"vkCmdDraw\"}}\n",
            "{\"index\":3,\"vkFunc\":{\"name\":\"vkCmdDraw\",\"args\":{\"a\":1,\"a\":2}}}\n",
            "{\"index\":4,\"vkFunc\":{\"name\":\"a\"},\"function\":{\"name\":\"b\"}}\n",
            "{\"index\":5,\"index\":6}\n",
            "{\"index\":7,\"function\":[1]}\n",
        ));
        assert!(matches!(&got[0], Ok(Entry::Other(k)) if k == "meta"));
        // The call's tree reads from its arguments, wherever they stand in the line.
        let Ok(Entry::Call(c)) = &got[1] else {
            panic!("{:?}", got[1])
        };
        let count = c.args.get(c.args.root(), "vertexCount").unwrap();
        assert_eq!(c.args.node(count), Node::U64(3));
        assert!(
            matches!(&got[2], Err(e) if e.line == 3 && e.message.contains("member `a` given twice"))
        );
        assert!(
            matches!(&got[3], Err(e) if e.line == 4 && e.message.contains("`vkFunc` and `function` in one line"))
        );
        assert!(matches!(&got[4], Err(e) if e.message.contains("member `index` given twice")));
        assert!(matches!(&got[5], Err(e) if e.message == "`function` is not an object"));
    }

    #[test]
    fn an_endless_line_is_refused_not_buffered() {
        let long = "x".repeat(64);
        let mut lines = Lines::new(long.as_bytes());
        // The limit is large; a short non-JSON line still fails as JSON, located.
        assert!(matches!(lines.next_entry(), Some(Err(e)) if e.line == 1));
    }
}
