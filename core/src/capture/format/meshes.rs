//! Meshes: vertex streams in any layout, index formats, and generated or file contents.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ParamValue;

/// Geometry: structure-of-arrays vertex streams and an optional index buffer.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Mesh {
    pub name: String,
    /// Where the vertex and index data come from.
    pub source: MeshSource,
    /// Vertex streams, one per input slot, each with its own format.
    pub streams: Vec<VertexStream>,
    /// Index format; non-indexed when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index_format: Option<IndexFormat>,
    /// Vertex count; required for file sources (generators compute it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex_count: Option<u32>,
    /// Index count; required for indexed file sources.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index_count: Option<u32>,
    /// Instance count of per-instance streams; required when any stream steps per instance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instance_count: Option<u32>,
    /// Content generator of the per-instance transform rows of a generator mesh (`instances`
    /// scatters them, `city_lots` places one box per building lot); `instances` with the mesh's
    /// seed when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instances: Option<InstanceGenerator>,
}

/// A named content generator for per-instance rows, with its seed and parameters.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InstanceGenerator {
    pub name: String,
    #[serde(default)]
    pub seed: u64,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum MeshSource {
    /// A binary file: each per-vertex stream's data in stream order, then per-instance streams,
    /// then the indices, tightly packed, little-endian.
    File { path: String },
    /// A procedural generator (grid, box, city_blocks, terrain, water_plate, foliage_cards,
    /// sphere, capsule) with a seed and its parameters.
    Generator {
        name: String,
        #[serde(default)]
        seed: u64,
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        params: BTreeMap<String, ParamValue>,
    },
}

/// One vertex buffer slot.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VertexStream {
    /// Input slot (VB0, VB1, ...).
    pub slot: u32,
    /// Attributes in the stream, interleaved within it in this order.
    pub attributes: Vec<VertexAttribute>,
    /// Per-vertex (default) or per-instance data.
    #[serde(default = "per_vertex")]
    pub step: StepMode,
}

pub(crate) fn per_vertex() -> StepMode {
    StepMode::Vertex
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VertexAttribute {
    /// HLSL semantic, e.g. POSITION0, TEXCOORD1, INSTANCE_TRANSFORM2.
    pub semantic: String,
    pub format: VertexFormat,
    /// WGSL `@location` the attribute feeds.
    pub location: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StepMode {
    Vertex,
    Instance,
}

/// Vertex attribute encodings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum VertexFormat {
    /// Four signed normalised 16-bit integers (positions scaled into [-1, 1]).
    Snorm16x4,
    Snorm16x2,
    Unorm16x2,
    Float16x2,
    Float16x4,
    /// Normal or tangent packed in 32 bits: 10:10:10:2, signed normalised.
    PackedSnorm10x3,
    Unorm8x4,
    Snorm8x4,
    Uint8x4,
    Float32,
    Float32x2,
    Float32x3,
    Float32x4,
    Uint32,
    Uint32x2,
}

impl VertexFormat {
    pub fn size(self) -> u32 {
        match self {
            VertexFormat::Snorm16x4 | VertexFormat::Float16x4 | VertexFormat::Float32x2 => 8,
            VertexFormat::Uint32x2 => 8,
            VertexFormat::Snorm16x2
            | VertexFormat::Unorm16x2
            | VertexFormat::Float16x2
            | VertexFormat::PackedSnorm10x3
            | VertexFormat::Unorm8x4
            | VertexFormat::Snorm8x4
            | VertexFormat::Uint8x4
            | VertexFormat::Float32
            | VertexFormat::Uint32 => 4,
            VertexFormat::Float32x3 => 12,
            VertexFormat::Float32x4 => 16,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum IndexFormat {
    Uint16,
    Uint32,
}

impl IndexFormat {
    pub fn size(self) -> u32 {
        match self {
            IndexFormat::Uint16 => 2,
            IndexFormat::Uint32 => 4,
        }
    }
}
