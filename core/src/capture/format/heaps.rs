//! Heaps: D3D12 heap types, CPU page properties, memory pools and heap flags.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A D3D12 heap (`D3D12_HEAP_DESC`): a block of memory that placed resources are put in.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Heap {
    pub name: String,
    #[serde(rename = "type")]
    pub heap_type: HeapType,
    /// Only for CUSTOM heaps; must be UNKNOWN (or absent) otherwise.
    #[serde(default = "unknown_page")]
    pub cpu_page_property: CpuPageProperty,
    /// Only for CUSTOM heaps; must be UNKNOWN (or absent) otherwise.
    #[serde(default = "unknown_pool")]
    pub memory_pool: MemoryPool,
    /// Size in bytes.
    pub size: u64,
    /// 65536 (64 KiB, the default) or 4194304 (4 MiB, needed for MSAA textures).
    #[serde(default = "default_heap_alignment")]
    pub alignment: u64,
    /// D3D12_HEAP_FLAGS; ALLOW_ONLY_* and ALLOW_ALL_BUFFERS_AND_TEXTURES are aliases of DENY_*
    /// combinations and are accepted as such.
    #[serde(default)]
    pub flags: Vec<HeapFlag>,
}

pub(crate) fn unknown_page() -> CpuPageProperty {
    CpuPageProperty::Unknown
}
pub(crate) fn unknown_pool() -> MemoryPool {
    MemoryPool::Unknown
}
pub(crate) fn default_heap_alignment() -> u64 {
    65536
}

/// D3D12_HEAP_TYPE.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum HeapType {
    /// GPU-only memory, fastest for the GPU.
    Default,
    /// CPU-writable, GPU-readable (write-combined system memory on NUMA).
    Upload,
    /// GPU-writable, CPU-readable (cached system memory).
    Readback,
    /// Page property and memory pool given explicitly.
    Custom,
}

/// D3D12_CPU_PAGE_PROPERTY.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum CpuPageProperty {
    Unknown,
    NotAvailable,
    WriteCombine,
    WriteBack,
}

/// D3D12_MEMORY_POOL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
pub enum MemoryPool {
    #[serde(rename = "UNKNOWN")]
    Unknown,
    /// System memory (the only pool on UMA).
    L0,
    /// Video memory on NUMA adapters; not CPU-accessible.
    L1,
}

/// D3D12_HEAP_FLAGS members.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum HeapFlag {
    None,
    Shared,
    DenyBuffers,
    AllowDisplay,
    SharedCrossAdapter,
    DenyRtDsTextures,
    DenyNonRtDsTextures,
    HardwareProtected,
    AllowWriteWatch,
    AllowShaderAtomics,
    AllowAllBuffersAndTextures,
    AllowOnlyBuffers,
    AllowOnlyNonRtDsTextures,
    AllowOnlyRtDsTextures,
}

impl HeapType {
    /// The name reports and messages use (D3D12's spelling where it has one).
    pub fn name(self) -> &'static str {
        match self {
            HeapType::Default => "DEFAULT",
            HeapType::Upload => "UPLOAD",
            HeapType::Readback => "READBACK",
            HeapType::Custom => "CUSTOM",
        }
    }
}

impl CpuPageProperty {
    /// The name reports and messages use (D3D12's spelling where it has one).
    pub fn name(self) -> &'static str {
        match self {
            CpuPageProperty::Unknown => "UNKNOWN",
            CpuPageProperty::NotAvailable => "NOT_AVAILABLE",
            CpuPageProperty::WriteCombine => "WRITE_COMBINE",
            CpuPageProperty::WriteBack => "WRITE_BACK",
        }
    }
}
