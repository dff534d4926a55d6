//! Descriptor heaps and samplers.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A descriptor heap (`D3D12_DESCRIPTOR_HEAP_DESC`).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DescriptorHeap {
    pub name: String,
    #[serde(rename = "type")]
    pub heap_type: DescriptorHeapType,
    /// Number of descriptors.
    pub capacity: u32,
    /// Whether shaders can reference it (only CBV_SRV_UAV and SAMPLER heaps can be).
    #[serde(default)]
    pub shader_visible: bool,
}

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize, JsonSchema,
)]
pub enum DescriptorHeapType {
    #[serde(rename = "CBV_SRV_UAV")]
    CbvSrvUav,
    #[serde(rename = "SAMPLER")]
    Sampler,
    #[serde(rename = "RTV")]
    Rtv,
    #[serde(rename = "DSV")]
    Dsv,
}

/// A static sampler.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sampler {
    pub name: String,
    #[serde(default = "linear")]
    pub min_filter: Filter,
    #[serde(default = "linear")]
    pub mag_filter: Filter,
    #[serde(default = "linear")]
    pub mip_filter: Filter,
    #[serde(default = "clamp")]
    pub address_u: AddressMode,
    #[serde(default = "clamp")]
    pub address_v: AddressMode,
    #[serde(default = "clamp")]
    pub address_w: AddressMode,
    /// Comparison function for shadow-map samplers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compare: Option<CompareFunction>,
    /// 1 disables anisotropic filtering; up to 16.
    #[serde(default = "one")]
    pub max_anisotropy: u16,
    #[serde(default)]
    pub lod_min: f32,
    #[serde(default = "lod_max")]
    pub lod_max: f32,
}

pub(crate) fn linear() -> Filter {
    Filter::Linear
}
pub(crate) fn clamp() -> AddressMode {
    AddressMode::Clamp
}
pub(crate) fn one() -> u16 {
    1
}
pub(crate) fn lod_max() -> f32 {
    32.0
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    Point,
    Linear,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AddressMode {
    Wrap,
    Clamp,
    Mirror,
    Border,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CompareFunction {
    Never,
    Less,
    Equal,
    LessEqual,
    Greater,
    NotEqual,
    GreaterEqual,
    Always,
}
