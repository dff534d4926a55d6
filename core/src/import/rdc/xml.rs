//! Reading the XML `renderdoccmd convert -c zip.xml` writes, one chunk at a time, in bounded
//! memory: the header (which API the capture is of), the `<chunks version=...>` the rest is
//! read against, and each `<chunk>` as a small tree of named, typed values. Nothing past the
//! chunk being read is held, and a chunk larger than any real one is refused.

use std::io::BufRead;

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

/// Deepest nesting of elements inside one chunk; Vulkan structures nest a few levels.
const MAX_DEPTH: usize = 48;
/// Most elements in one chunk (a chunk's parameters, down to every array element).
const MAX_NODES: usize = 1 << 20;
/// Longest text of one element.
const MAX_TEXT: usize = 1 << 20;
/// Most text in one chunk, all its elements together.
const MAX_CHUNK_TEXT: usize = 64 << 20;

/// One element: its tag (`struct`, `array`, `uint`, `enum`, `ResourceId`, `buffer`, ...), the
/// attributes the import reads, its text and its children.
#[derive(Debug, Default, Clone)]
pub struct Node {
    pub tag: String,
    pub name: Option<String>,
    pub typename: Option<String>,
    /// An enum's or flag's symbolic value (`VK_FORMAT_B8G8R8A8_UNORM`).
    pub string: Option<String>,
    /// A `buffer`'s length in bytes; its text is the zip member holding it.
    pub byte_length: Option<u64>,
    /// The `id` attribute: a chunk's type, the header's driver.
    pub id: Option<u64>,
    pub text: String,
    pub children: Vec<Node>,
}

impl Node {
    /// The child named `name`.
    pub fn child(&self, name: &str) -> Option<&Node> {
        self.children
            .iter()
            .find(|c| c.name.as_deref() == Some(name))
    }

    pub fn u64(&self) -> Option<u64> {
        self.text.trim().parse().ok()
    }
}

/// The capture's header: the API it records.
#[derive(Debug, Default)]
pub struct Header {
    pub driver: String,
    pub driver_id: Option<u32>,
    pub machine: Option<String>,
}

/// A chunk: its name, its ordinal in the file (1-based, as RenderDoc's event browser counts
/// chunks), and its parameters as the root's children.
#[derive(Debug)]
pub struct Chunk {
    pub ordinal: u64,
    pub name: String,
    pub root: Node,
}

/// Where the reader is, for messages: the chunk and the byte of the XML.
#[derive(Debug, Clone, Copy)]
pub struct At {
    pub chunk: u64,
    pub byte: u64,
}

#[derive(Debug)]
pub struct XmlError {
    pub at: At,
    pub message: String,
}

pub struct Chunks<R> {
    reader: Reader<R>,
    buf: Vec<u8>,
    pub header: Header,
    /// The `version` of `<chunks>`: the serialisation version of the API's chunks.
    pub version: u32,
    chunk: u64,
    done: bool,
}

impl<R> std::fmt::Debug for Chunks<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Chunks")
            .field("version", &self.version)
            .field("chunk", &self.chunk)
            .finish_non_exhaustive()
    }
}

fn attr(e: &BytesStart<'_>, key: &str) -> Option<String> {
    e.try_get_attribute(key).ok().flatten().and_then(|a| {
        a.normalized_value(quick_xml::XmlVersion::Explicit1_0)
            .ok()
            .map(|v| v.into_owned())
    })
}

impl<R: BufRead> Chunks<R> {
    /// Reads up to the first chunk: the header and the chunks' version.
    pub fn new(reader: R) -> Result<Self, XmlError> {
        // Text is kept as written (a string's spaces around `&amp;` matter); the whitespace
        // between elements is dropped when its element turns out to have children.
        let reader = Reader::from_reader(reader);
        let mut chunks = Chunks {
            reader,
            buf: Vec::new(),
            header: Header::default(),
            version: 0,
            chunk: 0,
            done: false,
        };
        let mut seen_root = false;
        loop {
            chunks.buf.clear();
            let event = match chunks.reader.read_event_into(&mut chunks.buf) {
                Ok(e) => e.into_owned(),
                Err(e) => return Err(chunks.error(format!("not well-formed XML: {e}"))),
            };
            match event {
                Event::Start(e) => {
                    match e.name().as_ref() {
                        b"rdc" => seen_root = true,
                        b"header" if seen_root => {
                            let node = chunks.tree(&e)?;
                            chunks.header = header(&node);
                        }
                        b"chunks" if seen_root => {
                            let v = attr(&e, "version").unwrap_or_default();
                            chunks.version = v.parse().map_err(|_| {
                                chunks.error(format!("<chunks> has no numeric version (\"{v}\")"))
                            })?;
                            return Ok(chunks);
                        }
                        _ if seen_root => {
                            // Thumbnails and other sections: not needed.
                            chunks.tree(&e)?;
                        }
                        other => {
                            return Err(chunks.error(format!(
                                "starts with <{}>, not <rdc>: not an XML written by renderdoccmd convert",
                                String::from_utf8_lossy(other)
                            )));
                        }
                    }
                }
                Event::Eof => {
                    return Err(chunks.error(if seen_root {
                        "the XML ends before its <chunks>".to_owned()
                    } else {
                        "no <rdc> element: not an XML written by renderdoccmd convert".to_owned()
                    }));
                }
                _ => {}
            }
        }
    }

    pub fn at(&self) -> At {
        At {
            chunk: self.chunk,
            byte: self.reader.buffer_position(),
        }
    }

    fn error(&self, message: String) -> XmlError {
        XmlError {
            at: self.at(),
            message,
        }
    }

    /// The next chunk; `None` after `</chunks>`.
    pub fn next_chunk(&mut self) -> Option<Result<Chunk, XmlError>> {
        if self.done {
            return None;
        }
        loop {
            self.buf.clear();
            let event = match self.reader.read_event_into(&mut self.buf) {
                Ok(e) => e.into_owned(),
                Err(e) => {
                    self.done = true;
                    return Some(Err(self.error(format!("not well-formed XML: {e}"))));
                }
            };
            let (start, empty) = match event {
                Event::Start(e) => (e, false),
                Event::Empty(e) => (e, true),
                Event::End(_) => {
                    self.done = true;
                    return None;
                }
                Event::Eof => {
                    self.done = true;
                    return Some(Err(self.error(
                        "the XML ends inside <chunks>: truncated conversion".to_owned(),
                    )));
                }
                _ => continue,
            };
            if start.name().as_ref() != b"chunk" {
                self.done = true;
                return Some(Err(self.error(format!(
                    "<{}> inside <chunks>, where only <chunk> belongs",
                    String::from_utf8_lossy(start.name().as_ref())
                ))));
            }
            self.chunk += 1;
            let name = attr(&start, "name").unwrap_or_default();
            let root = if empty {
                Ok(Node {
                    tag: "chunk".to_owned(),
                    ..Node::default()
                })
            } else {
                self.tree(&start)
            };
            return Some(match root {
                Ok(root) => Ok(Chunk {
                    ordinal: self.chunk,
                    name,
                    root,
                }),
                Err(e) => {
                    self.done = true;
                    Err(e)
                }
            });
        }
    }

    /// The element `start` opened, with everything inside it, up to its end.
    fn tree(&mut self, start: &BytesStart<'_>) -> Result<Node, XmlError> {
        let mut stack = vec![node(start)];
        let mut nodes = 1usize;
        let mut text_bytes = 0usize;
        loop {
            self.buf.clear();
            let event = match self.reader.read_event_into(&mut self.buf) {
                Ok(e) => e.into_owned(),
                Err(e) => return Err(self.error(format!("not well-formed XML: {e}"))),
            };
            let fail = |this: &Self, m: String| XmlError {
                at: this.at(),
                message: m,
            };
            match event {
                Event::Start(e) => {
                    nodes += 1;
                    if stack.len() >= MAX_DEPTH || nodes > MAX_NODES {
                        return Err(fail(
                            self,
                            format!(
                                "a chunk nested deeper than {MAX_DEPTH} or with more than {MAX_NODES} elements"
                            ),
                        ));
                    }
                    stack.push(node(&e));
                }
                Event::Empty(e) => {
                    nodes += 1;
                    if nodes > MAX_NODES {
                        return Err(fail(
                            self,
                            format!("a chunk with more than {MAX_NODES} elements"),
                        ));
                    }
                    let n = node(&e);
                    if let Some(top) = stack.last_mut() {
                        top.children.push(n);
                    }
                }
                Event::Text(t) => {
                    let text = t
                        .decode()
                        .map_err(|e| fail(self, format!("text is not UTF-8: {e}")))?;
                    push_text(&mut stack, &text, &mut text_bytes)
                        .map_err(|m| fail(self, m.to_string()))?;
                }
                Event::CData(t) => {
                    let text = t
                        .decode()
                        .map_err(|e| fail(self, format!("text is not UTF-8: {e}")))?;
                    push_text(&mut stack, &text, &mut text_bytes)
                        .map_err(|m| fail(self, m.to_string()))?;
                }
                Event::GeneralRef(r) => {
                    let c = match r.resolve_char_ref() {
                        Ok(Some(c)) => c,
                        _ => match r.as_ref() {
                            b"amp" => '&',
                            b"lt" => '<',
                            b"gt" => '>',
                            b"quot" => '"',
                            b"apos" => '\'',
                            other => {
                                return Err(fail(
                                    self,
                                    format!("unknown entity &{};", String::from_utf8_lossy(other)),
                                ));
                            }
                        },
                    };
                    push_text(&mut stack, c.encode_utf8(&mut [0; 4]), &mut text_bytes)
                        .map_err(|m| fail(self, m.to_string()))?;
                }
                Event::End(_) => {
                    let Some(mut done) = stack.pop() else {
                        return Err(fail(self, "unbalanced end tag".to_owned()));
                    };
                    if !done.children.is_empty() {
                        done.text.clear();
                    }
                    match stack.last_mut() {
                        Some(parent) => parent.children.push(done),
                        None => return Ok(done),
                    }
                }
                Event::Eof => {
                    return Err(fail(
                        self,
                        "the XML ends inside an element: truncated conversion".to_owned(),
                    ));
                }
                _ => {}
            }
        }
    }
}

/// Text past what a chunk or an element may hold.
#[derive(Debug, thiserror::Error)]
enum TooMuchText {
    #[error("a chunk with more than {} MiB of text", MAX_CHUNK_TEXT >> 20)]
    Chunk,
    #[error("an element's text is longer than {} KiB", MAX_TEXT >> 10)]
    Element,
}

fn push_text(stack: &mut [Node], text: &str, total: &mut usize) -> Result<(), TooMuchText> {
    *total += text.len();
    if *total > MAX_CHUNK_TEXT {
        return Err(TooMuchText::Chunk);
    }
    if let Some(top) = stack.last_mut() {
        if top.text.len() + text.len() > MAX_TEXT {
            return Err(TooMuchText::Element);
        }
        top.text.push_str(text);
    }
    Ok(())
}

fn node(e: &BytesStart<'_>) -> Node {
    Node {
        tag: String::from_utf8_lossy(e.name().as_ref()).into_owned(),
        name: attr(e, "name"),
        typename: attr(e, "typename"),
        string: attr(e, "string"),
        byte_length: attr(e, "byteLength").and_then(|v| v.parse().ok()),
        id: attr(e, "id").and_then(|v| v.parse().ok()),
        text: String::new(),
        children: Vec::new(),
    }
}

fn header(node: &Node) -> Header {
    let mut h = Header::default();
    for c in &node.children {
        match c.tag.as_str() {
            "driver" => {
                h.driver = c.text.clone();
                h.driver_id = c.id.and_then(|i| u32::try_from(i).ok());
            }
            "machineIdent" => h.machine = Some(c.text.clone()),
            _ => {}
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = r#"<?xml version="1.0"?>
<rdc>
	<header>
		<driver id="8">Vulkan</driver>
		<thumbnail width="4" height="4">thumb.png</thumbnail>
	</header>
	<chunks version="21">
"#;

    #[test]
    fn chunks_are_read_one_at_a_time_with_their_values() {
        let xml = format!(
            r#"{HEAD}<chunk id="1019" name="vkCreateShaderModule" length="8">
<struct name="CreateInfo" typename="VkShaderModuleCreateInfo">
<buffer name="pCode" typename="Byte Buffer" byteLength="1560">0</buffer>
<string name="label">a &amp; b</string>
</struct>
<ResourceId name="ShaderModule" typename="VkShaderModule" width="8">181</ResourceId>
</chunk>
<chunk id="6" name="Internal::End of Capture" length="0"/>
</chunks></rdc>"#
        );
        let mut chunks = Chunks::new(xml.as_bytes()).unwrap();
        assert_eq!(
            (chunks.header.driver.as_str(), chunks.header.driver_id),
            ("Vulkan", Some(8))
        );
        assert_eq!(chunks.version, 21);
        let c = chunks.next_chunk().unwrap().unwrap();
        assert_eq!((c.ordinal, c.name.as_str()), (1, "vkCreateShaderModule"));
        let ci = c.root.child("CreateInfo").unwrap();
        let code = ci.child("pCode").unwrap();
        assert_eq!((code.byte_length, code.text.as_str()), (Some(1560), "0"));
        assert_eq!(ci.child("label").unwrap().text, "a & b");
        assert_eq!(c.root.child("ShaderModule").unwrap().u64(), Some(181));
        let end = chunks.next_chunk().unwrap().unwrap();
        assert_eq!(
            (end.ordinal, end.name.as_str()),
            (2, "Internal::End of Capture")
        );
        assert!(chunks.next_chunk().is_none());
    }

    #[test]
    fn damaged_xml_is_located() {
        assert!(
            Chunks::new("<html></html>".as_bytes())
                .unwrap_err()
                .message
                .contains("not <rdc>")
        );
        assert!(Chunks::new("<rdc><header>".as_bytes()).is_err());
        let cut = format!("{HEAD}<chunk id=\"1\" name=\"vkCmdDraw\"><uint name=\"x\">3");
        let mut chunks = Chunks::new(cut.as_bytes()).unwrap();
        let e = chunks.next_chunk().unwrap().unwrap_err();
        assert_eq!(e.at.chunk, 1);
        assert!(e.message.contains("truncated"), "{}", e.message);
        let deep = format!("{HEAD}<chunk name=\"x\">{}", "<struct>".repeat(100));
        let mut chunks = Chunks::new(deep.as_bytes()).unwrap();
        let e = chunks.next_chunk().unwrap().unwrap_err();
        assert!(e.message.contains("deeper than"), "{}", e.message);
    }
}
