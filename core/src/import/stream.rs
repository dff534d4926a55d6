//! Reading a GFXReconstruct JSON Lines stream one line at a time, in bounded memory, and
//! telling its two dialects apart: 0.9.x writes calls as `{"index", "vkFunc": {...}}`, 1.x as
//! `{"index", "function": {...}}` with `meta`, `state` and `frame` marker lines besides.

use std::borrow::Cow;
use std::io::{BufRead, Read};

use serde_json::Value;

use super::calls::Func;
use super::tree::Tree;

/// Longest line read; a longer one is refused rather than buffered. Parsed, a line of numbers
/// takes about 75 times its size (a JSON value, then a tree node, per number); the longest
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
                Ok(n) if n as u64 > MAX_LINE_BYTES => {
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
            let text = trim_ascii(&self.buf);
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

fn parse_entry(text: &[u8], line: u64) -> Result<Entry, LineError> {
    let err = |message: String| LineError { line, message };
    let value: Value = serde_json::from_slice(text).map_err(|e| {
        err(if e.is_eof() {
            format!("truncated JSON ({e})")
        } else {
            format!("not JSON: {e}")
        })
    })?;
    let Value::Object(mut obj) = value else {
        return Err(err("expected a JSON object per line".to_owned()));
    };
    if let Some(h) = obj.get("header") {
        let field = |k: &str| {
            h.get(k)
                .and_then(Value::as_str)
                .unwrap_or("unknown")
                .to_owned()
        };
        return Ok(Entry::Header {
            gfxr_version: field("gfxrecon-version"),
            json_version: field("json-version"),
        });
    }
    for (key, dialect) in [("vkFunc", "0.9.x"), ("function", "1.x")] {
        if let Some(f) = obj.remove(key) {
            let Value::Object(f) = f else {
                return Err(err(format!("`{key}` is not an object")));
            };
            let name = match f.get("name") {
                Some(Value::String(s)) => s.clone(),
                _ => return Err(err(format!("`{key}.name` is missing or not a string"))),
            };
            let index = obj.get("index").and_then(Value::as_u64).unwrap_or(0);
            let result = match f.get("return") {
                Some(Value::String(s)) => Some(Cow::Owned(s.clone())),
                Some(v) if !v.is_null() => Some(Cow::Owned(v.to_string())),
                _ => None,
            };
            let args = Tree::from_json(f.get("args").unwrap_or(&Value::Null));
            return Ok(Entry::Call(Call {
                line,
                index,
                func: Func::of(&name),
                // The registry's own name where it has one, so every origin the call's
                // commands carry borrows it.
                name: super::gfxr::registry::command_named(&name)
                    .map_or(Cow::Owned(name), |c| Cow::Borrowed(c.name)),
                args,
                result,
                dialect,
            }));
        }
    }
    if let Some(frame) = obj.get("frame") {
        let end = frame.get("marker_type").and_then(Value::as_str) == Some("EndMarker");
        return Ok(if end {
            Entry::FrameEnd
        } else {
            Entry::Other("frame marker".to_owned())
        });
    }
    let kind = obj
        .keys()
        .find(|k| *k != "index")
        .cloned()
        .unwrap_or_else(|| "empty object".to_owned());
    Ok(Entry::Other(kind))
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
    fn an_endless_line_is_refused_not_buffered() {
        let long = "x".repeat(64);
        let mut lines = Lines::new(long.as_bytes());
        // The limit is large; a short non-JSON line still fails as JSON, located.
        assert!(matches!(lines.next_entry(), Some(Err(e)) if e.line == 1));
    }
}
