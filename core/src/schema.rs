//! The JSON Schema of the capture format, generated from the serde types so that it cannot
//! drift from what the loader accepts. A copy is committed under `captures/` for editors.

/// The schema as pretty-printed JSON with a trailing newline.
pub fn schema_json() -> String {
    let schema = schemars::schema_for!(crate::capture::format::RawCapture);
    let mut text = serde_json::to_string_pretty(&schema).unwrap_or_default();
    text.push('\n');
    text
}

/// Where the committed copy lives, relative to the repository root.
pub const COMMITTED_PATH: &str = "captures/framelab-capture-v1.schema.json";
