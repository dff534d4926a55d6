//! The arguments of each MCP tool, with the doc comments that become their JSON Schema's
//! descriptions, and the bounds a request may ask for.

use schemars::JsonSchema;
use serde::Deserialize;

/// The longest side `texture` returns at most.
pub const MAX_IMAGE_SIDE: u32 = 4096;

/// The most texels one `read_texels` call returns.
pub const MAX_TEXELS: u64 = 4096;

/// The most bytes one `read_buffer` call returns.
pub const MAX_BUFFER_BYTES: u64 = 65536;

/// The most frames one `timings` call replays.
pub const MAX_FRAMES: u32 = 100;

/// The most rows one `list_*` call returns.
pub const MAX_ROWS: usize = 1000;
pub const DEFAULT_ROWS: usize = 100;

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OpenArgs {
    /// A capture file inside the client's roots: framelab JSON, `.gfxr`, JSON Lines or `.rdc`.
    pub path: String,
    /// Output-resolution multiplier the sizes are resolved for (default 1).
    pub scale: Option<f64>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ListArgs {
    /// A capture id from open_capture.
    pub capture: String,
    /// Keep rows whose name contains this text.
    pub filter: Option<String>,
    /// Rows to skip (default 0).
    pub offset: Option<usize>,
    /// Rows to return (default 100, at most 1000).
    pub limit: Option<usize>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PassArgs {
    pub capture: String,
    /// The pass's name.
    pub pass: String,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AnalyzeArgs {
    pub capture: String,
    /// Drop passes whose results never reach an output first.
    pub cull: Option<bool>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DiffMode {
    /// Passes, resources, formats and barriers added, removed or changed.
    Structure,
    /// Per-pass GPU times of both frames, replayed here, with 95% intervals and verdicts.
    Timing,
    /// Per-pass work counters of one frame of each, replayed here, compared exactly.
    Work,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiffArgs {
    /// Capture id of the first frame.
    pub a: String,
    /// Capture id of the second frame.
    pub b: String,
    pub mode: DiffMode,
    /// `timing`: frames replayed and timed per capture (default 10, at most 100).
    pub frames: Option<u32>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TextureArgs {
    pub capture: String,
    /// The texture's name.
    pub resource: String,
    /// Show it as it stood right after this pass of the frame (default: after the last).
    pub after_pass: Option<String>,
    /// Mip level (default 0).
    pub mip: Option<u32>,
    /// Array layer or cube face (default 0).
    pub layer: Option<u32>,
    /// Depth slice of a 3D texture (default 0).
    pub slice: Option<u32>,
    /// Longest side of the image returned (default 1024, at most 4096); larger textures are
    /// scaled down to it.
    pub max_size: Option<u32>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TexelArgs {
    pub capture: String,
    /// The texture's name.
    pub resource: String,
    /// As it stood right after this pass of the frame (default: after the last).
    pub after_pass: Option<String>,
    /// The region's left column.
    pub x: u32,
    /// The region's top row.
    pub y: u32,
    /// Columns (default 1).
    pub width: Option<u32>,
    /// Rows (default 1); width x height at most 4096 texels.
    pub height: Option<u32>,
    pub mip: Option<u32>,
    pub layer: Option<u32>,
    pub slice: Option<u32>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BufferArgs {
    pub capture: String,
    /// The buffer's name.
    pub resource: String,
    /// As it stood right after this pass of the frame (default: after the last).
    pub after_pass: Option<String>,
    /// First byte (default 0).
    pub offset: Option<u64>,
    /// Bytes (default 256, at most 65536).
    pub length: Option<u64>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimingsArgs {
    pub capture: String,
    /// Frames to replay and time (default 3, at most 100).
    pub frames: Option<u32>,
    /// Count each pass's pipeline statistics in every frame too (default false).
    pub counters: Option<bool>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CaptureArgs {
    /// The Vulkan program to run (a path, or a name found on PATH).
    pub program: String,
    /// Its arguments.
    #[serde(default)]
    pub args: Vec<String>,
    /// The frame to take (1 is its first presented frame).
    pub frame: u32,
    /// An existing folder inside the client's roots: the capture (`.gfxr`) and its import go
    /// there.
    pub dir: String,
    /// Seconds to wait for the frame before stopping the program (default 60, at most 600).
    pub timeout: Option<u64>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CloseArgs {
    pub capture: String,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WhatIfArgs {
    /// A capture id from open_capture.
    pub capture: String,
    /// Apply the fixes of a lint's findings: `FL005`, `FL005:ssao` (those about one pass or
    /// resource), or `all` (every fixable finding; `analyze` gives each finding's `fix`).
    #[serde(default)]
    pub fix: Vec<String>,
    /// Passes to drop.
    #[serde(default)]
    pub cull: Vec<String>,
    /// Recorded barriers to drop, as `PASS:N` (N from 0 in the pass's list).
    #[serde(default)]
    pub drop_barrier: Vec<String>,
    /// Texture formats to change, as `RESOURCE=FORMAT` (DXGI's names).
    #[serde(default)]
    pub format: Vec<String>,
    /// Passes to move to another queue, as `PASS=QUEUE`.
    #[serde(default)]
    pub queue: Vec<String>,
    /// Textures to resize, as `RESOURCE=F` (width and height times F).
    #[serde(default)]
    pub scale_resource: Vec<String>,
    /// Pairs of raster passes to make one render pass, as `FIRST+SECOND`.
    #[serde(default)]
    pub merge: Vec<String>,
    /// Measured frames per side (default 5, 2..=100).
    pub frames: Option<u32>,
    /// Compare textures after the last frame only, not also after every pass (default false).
    pub final_only: Option<bool>,
    /// Longest side of the images returned (default 512).
    pub max_size: Option<u32>,
}
