//! `framelab import frame.rdc`: a RenderDoc capture of a Vulkan frame.
//!
//! RenderDoc's chunks are serialised by its own code, one layout per chunk and version, with
//! nothing in the file saying how to read them; its `renderdoccmd convert -c zip.xml` writes
//! every chunk as XML with named, typed parameters and the bytes they reference (SPIR-V,
//! initial contents, mapped-memory writes) as members of a zip beside it. framelab reads that
//! XML as it streams, checks which version of the chunks it holds, and hands each chunk, as
//! the Vulkan calls it stands for, to the same importer that reads GFXReconstruct's captures:
//! one reconstruction of passes, resources, barriers, shaders and contents for both.

mod args;
mod chunks;
pub mod convert;
mod errors;
mod members;
mod xml;

use std::collections::BTreeMap;
use std::io::{BufRead, Read, Seek};

use super::{ImportError, ImportOptions, Imported, Importer};
use chunks::Reader;
use members::Members;
use xml::Chunks;

/// The chunk version of the Vulkan captures RenderDoc 1.24 writes: the one this reader was
/// made and tested against. RenderDoc does not promise the XML stays the same, so another
/// is refused rather than misread.
pub const VULKAN_CHUNKS_VERSION: u32 = 0x15;
/// RenderDoc's driver id for Vulkan.
const VULKAN_DRIVER: u32 = 8;

/// Whether `head` starts a RenderDoc capture file.
pub fn is_rdc(head: &[u8]) -> bool {
    head.starts_with(b"RDOC")
}

/// The RenderDoc version that wrote a capture, from its file header (`1.24`).
pub fn writer_version(head: &[u8]) -> Option<String> {
    let text = head.get(16..80)?;
    let end = text.iter().position(|&b| b == 0)?;
    let s = std::str::from_utf8(&text[..end]).ok()?;
    Some(s.split_whitespace().next()?.to_owned())
}

/// Imports the frame a converted capture holds: `xml` is what `renderdoccmd convert -c
/// zip.xml` wrote and `zip` the zip beside it. `file` names the capture in messages; side
/// files are named after `stem`.
pub fn import(
    xml: impl BufRead,
    zip: impl Read + Seek,
    file: &str,
    stem: &str,
    writer: Option<&str>,
    options: &ImportOptions,
) -> Result<Imported, ImportError> {
    let stream = |message: String| ImportError::Stream {
        file: file.to_owned(),
        message,
    };
    let mut chunks = Chunks::new(xml)
        .map_err(|e| stream(format!("converted XML, byte {}: {}", e.at.byte, e.message)))?;
    if chunks.header.driver_id != Some(VULKAN_DRIVER) {
        return Err(stream(format!(
            "a {} capture (driver id {}); framelab imports Vulkan captures",
            if chunks.header.driver.is_empty() {
                "non-Vulkan"
            } else {
                &chunks.header.driver
            },
            chunks
                .header
                .driver_id
                .map_or_else(|| "missing".to_owned(), |d| d.to_string())
        )));
    }
    if chunks.version != VULKAN_CHUNKS_VERSION {
        return Err(stream(format!(
            "its Vulkan chunks are version {:#x}; framelab reads version {VULKAN_CHUNKS_VERSION:#x} (RenderDoc 1.24): convert the capture with RenderDoc 1.24's renderdoccmd",
            chunks.version
        )));
    }
    let members = Members::new(zip).map_err(|m| stream(format!("converted zip: {m}")))?;
    let mut reader = Reader::new(members);
    let mut imp = Importer::new(options);
    imp.dialect = Some("renderdoc");
    let mut count = 0u64;
    while let Some(chunk) = chunks.next_chunk() {
        let chunk = chunk.map_err(|e| {
            stream(format!(
                "converted XML, chunk {} (byte {}): {}",
                e.at.chunk, e.at.byte, e.message
            ))
        })?;
        count += 1;
        reader
            .chunk(&mut imp, &chunk)
            .map_err(|m| stream(format!("chunk {} ({}): {m}", chunk.ordinal, chunk.name)))?;
    }
    if !reader.in_frame {
        return Err(stream(
            "no frame: the capture has no `Beginning of Capture` chunk".to_owned(),
        ));
    }
    for (name, (n, first)) in &reader.unknown {
        let e = imp
            .skipped
            .entry(format!("chunks {name} that no table knows"))
            .or_insert((0, *first));
        e.0 += n;
    }
    let other: BTreeMap<String, u64> = reader.other;
    let frame = reader
        .frame_number
        .map_or_else(String::new, |n| format!(", application frame {n}"));
    let read = super::Read {
        tool: format!(
            "RenderDoc {} (Vulkan chunks {VULKAN_CHUNKS_VERSION:#x}, through renderdoccmd convert{frame})",
            writer.unwrap_or("(version not in the file)")
        ),
        lines: count,
        other,
    };
    let extras = super::Extras {
        contents: &mut reader.contents,
        stem,
    };
    super::finish(imp, read, file, options, Some(extras))
}

/// Converts `rdc` with renderdoccmd (from the environment) and imports it.
pub fn import_file(
    rdc: &std::path::Path,
    file: &str,
    stem: &str,
    options: &ImportOptions,
) -> Result<Imported, ImportError> {
    let stream = |message: String| ImportError::Stream {
        file: file.to_owned(),
        message,
    };
    let mut head = [0u8; 128];
    let n = std::fs::File::open(rdc)
        .and_then(|mut f| f.read(&mut head))
        .map_err(|e| stream(format!("cannot read: {e}")))?;
    let writer = writer_version(&head[..n]);
    let (program, timeout) = convert::from_env().map_err(|e| stream(e.to_string()))?;
    let converted = convert::convert(rdc, &program, timeout).map_err(|e| stream(e.to_string()))?;
    let xml = std::fs::File::open(&converted.xml)
        .map_err(|e| stream(format!("cannot read the converted XML: {e}")))?;
    let zip = std::fs::File::open(&converted.zip)
        .map_err(|e| stream(format!("cannot read the converted zip: {e}")))?;
    import(
        std::io::BufReader::with_capacity(1 << 20, xml),
        std::io::BufReader::new(zip),
        file,
        stem,
        writer.as_deref(),
        options,
    )
}
