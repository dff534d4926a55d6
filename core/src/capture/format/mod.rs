//! The capture file format, version 1: the serde types a capture JSON file deserialises into.
//!
//! These types mirror the file one to one. Names that refer to other objects (resources, heaps,
//! queues, formats) stay strings here so that validation can report every unknown name at once
//! with a suggestion, instead of stopping at serde's first error; `validate` turns a `RawCapture`
//! into the typed `Capture`. The JSON Schema (`framelab schema`) is generated from these types,
//! so every doc comment here is also the documentation editors show.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

mod descriptors;
mod heaps;
mod meshes;
mod passes;
mod queues;
mod render_state;
mod resources;
mod vulkan_objects;
mod work;

pub use descriptors::*;
pub use heaps::*;
pub use meshes::*;
pub use passes::*;
pub use queues::*;
pub use render_state::*;
pub use resources::*;
pub use vulkan_objects::*;
pub use work::*;

/// The only format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// A GPU frame: what it allocates, where, and the passes that run on which queue.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawCapture {
    /// Format version; must be 1.
    pub format_version: u32,
    /// Short name of the frame, shown in reports.
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The output resolution at `--scale 1`; relative sizes resolve against it.
    pub resolution: Resolution,
    /// The adapter the frame was captured on, as far as validation rules depend on it.
    #[serde(default)]
    pub adapter: AdapterModel,
    /// Camera for the frame constants (view/projection) and its motion between frames.
    pub camera: Camera,
    /// Frame-level constants: time and sky.
    #[serde(default)]
    pub frame: FrameConstants,
    /// Explicit D3D12 heaps that placed resources live in.
    #[serde(default)]
    pub heaps: Vec<Heap>,
    #[serde(default)]
    pub resources: Vec<Resource>,
    #[serde(default)]
    pub descriptor_heaps: Vec<DescriptorHeap>,
    #[serde(default)]
    pub samplers: Vec<Sampler>,
    /// Command queues. Every pass runs on one of them.
    pub queues: Vec<Queue>,
    /// Fences that passes signal and wait on to order work across queues.
    #[serde(default)]
    pub fences: Vec<Fence>,
    #[serde(default)]
    pub meshes: Vec<Mesh>,
    /// Passes in the order the application recorded them (per queue, this is submission order).
    #[serde(default)]
    pub passes: Vec<Pass>,
    /// The Vulkan objects an imported frame's draws and dispatches run with (pipelines,
    /// layouts, samplers, SPIR-V modules); absent for captures written for framelab.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vulkan: Option<VulkanObjects>,
    /// The tool and API stream the capture was imported from; absent for captures written by
    /// hand or generated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<CaptureSource>,
}

/// Where an imported capture came from, and what that means for what framelab can do with it.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CaptureSource {
    /// The capture tool and its version (e.g. `GFXReconstruct 0.9.18`).
    pub tool: String,
    /// The graphics API the frame was recorded from.
    pub api: Api,
    /// The stream the capture was imported from, as given to `framelab import`.
    pub file: String,
    /// Why the capture cannot be replayed (e.g. the stream holds no shader code). Raster and
    /// compute passes of such a capture need no `shader`; `replay` and `inspect` refuse it
    /// with this reason.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_replayable: Option<String>,
    /// The synchronization hazards of the imported command stream, found at import by
    /// Vulkan's synchronization rules command by command; absent where the stream was not
    /// checked. `analyze` reports each as `FL020 barrier-missing`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sync_hazards: Option<Vec<SyncHazard>>,
    /// Valid-usage statements of the specification the stream's calls break, found at import
    /// from the calls alone; absent where the stream was not checked. `analyze` reports each
    /// as `FL025 valid-usage` with its VUID.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valid_usage: Option<Vec<ValidUsageFinding>>,
}

/// One valid-usage statement a call breaks: its VUID as the specification numbers it, the
/// call (by name and index in the stream) and what in it breaks the rule.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ValidUsageFinding {
    /// `VUID-VkAttachmentDescription-format-06699`.
    pub vuid: String,
    /// `vkCreateRenderPass #12`.
    pub command: String,
    /// The member and values that break it: `pAttachments[0] (VK_FORMAT_D24_UNORM_S8_UINT):
    /// loadOp VK_ATTACHMENT_LOAD_OP_LOAD with initialLayout VK_IMAGE_LAYOUT_UNDEFINED`.
    pub detail: String,
}

impl CaptureSource {
    /// Recorded from a Vulkan program: its own terms (layouts, stages, usage flags) are the
    /// ones to report in, and its render passes follow Vulkan's rules.
    pub fn is_vulkan(&self) -> bool {
        self.api == Api::Vulkan
    }
}

/// A pair of accesses to one resource that no dependency orders, as the Khronos
/// synchronization validation names them.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum HazardKind {
    ReadAfterWrite,
    WriteAfterRead,
    WriteAfterWrite,
    /// An image used in (or transitioned from) a layout other than the one it is in.
    LayoutMismatch,
    /// A swapchain image presented before its last write is ordered before the present
    /// (no waited semaphore was signalled after it).
    PresentAfterWrite,
    /// A swapchain image written while the presentation engine may still read it: its
    /// acquire's semaphore and fence are not waited on before the write, and only they order
    /// the presentation engine's reads of its last present before the device's work.
    WriteAfterPresent,
    /// An exclusive resource read on a queue family other than the one that used it last,
    /// with no release and acquire between them.
    OwnershipTransferMissing,
}

impl HazardKind {
    pub fn as_str(self) -> &'static str {
        match self {
            HazardKind::ReadAfterWrite => "READ_AFTER_WRITE",
            HazardKind::WriteAfterRead => "WRITE_AFTER_READ",
            HazardKind::WriteAfterWrite => "WRITE_AFTER_WRITE",
            HazardKind::LayoutMismatch => "LAYOUT_MISMATCH",
            HazardKind::PresentAfterWrite => "PRESENT_AFTER_WRITE",
            HazardKind::WriteAfterPresent => "WRITE_AFTER_PRESENT",
            HazardKind::OwnershipTransferMissing => "OWNERSHIP_TRANSFER_MISSING",
        }
    }
}

/// One synchronization hazard of an imported stream: the command that makes the later access
/// (by its call and index in the stream), the resource and subresource, and both accesses
/// with their stage and access type.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SyncHazard {
    pub kind: HazardKind,
    /// `vkCmdBeginRenderPass #236`.
    pub command: String,
    pub resource: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mip: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer: Option<u32>,
    /// The later access: `COLOR_ATTACHMENT_OUTPUT/COLOR_ATTACHMENT_READ (load op LOAD)`.
    pub access: String,
    /// The earlier access it is not ordered with.
    pub prior: String,
    /// The command that made the earlier access.
    pub prior_command: String,
    /// The pass the later command's work (or barrier) went into, where it went into one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pass: Option<String>,
}

/// A graphics API a capture was recorded from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Api {
    D3d12,
    Vulkan,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Resolution {
    pub width: u32,
    pub height: u32,
}

/// Properties of the capturing adapter that D3D12's validity rules depend on.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AdapterModel {
    /// `numa`: a discrete GPU with its own memory (L1 is video memory, not CPU-visible);
    /// `uma`: one memory shared by CPU and GPU (only L0 exists).
    #[serde(default = "default_architecture")]
    pub architecture: MemoryArchitecture,
    /// D3D12_RESOURCE_HEAP_TIER: 1 means a heap holds only one of buffers, RT/DS textures or
    /// other textures; 2 allows mixing.
    #[serde(default = "default_tier")]
    pub resource_heap_tier: u8,
}

impl Default for AdapterModel {
    fn default() -> Self {
        Self {
            architecture: default_architecture(),
            resource_heap_tier: default_tier(),
        }
    }
}

pub(crate) fn default_architecture() -> MemoryArchitecture {
    MemoryArchitecture::Numa
}
pub(crate) fn default_tier() -> u8 {
    2
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MemoryArchitecture {
    Numa,
    Uma,
}

/// A perspective camera. Frame constants (view, projection, previous-frame matrices, jitter)
/// are computed from it for every replayed frame.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: [f32; 3],
    pub target: [f32; 3],
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
    #[serde(default = "default_near")]
    pub near: f32,
    #[serde(default = "default_far")]
    pub far: f32,
    /// World-space movement of the camera per frame, so that motion vectors and temporal
    /// passes see real motion when several frames are replayed.
    #[serde(default)]
    pub velocity: [f32; 3],
    /// Sub-pixel jitter sequence length (Halton 2,3); 0 disables jitter.
    #[serde(default = "default_jitter")]
    pub jitter_phases: u32,
}

pub(crate) fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
pub(crate) fn default_near() -> f32 {
    0.1
}
pub(crate) fn default_far() -> f32 {
    1000.0
}
pub(crate) fn default_jitter() -> u32 {
    8
}

/// Frame-level constants available to every shader.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FrameConstants {
    /// Time of the first replayed frame, in seconds.
    #[serde(default)]
    pub time_seconds: f32,
    /// Seconds between frames.
    #[serde(default = "default_dt")]
    pub delta_seconds: f32,
    /// Direction *towards* the sun (need not be normalised).
    #[serde(default = "default_sun")]
    pub sun_direction: [f32; 3],
    /// Sun colour times illuminance, linear.
    #[serde(default = "default_sun_color")]
    pub sun_color: [f32; 3],
    /// Direction towards the moon.
    #[serde(default = "default_moon")]
    pub moon_direction: [f32; 3],
    #[serde(default = "default_moon_color")]
    pub moon_color: [f32; 3],
    /// Camera exposure multiplier applied before tone mapping.
    #[serde(default = "default_exposure")]
    pub exposure: f32,
    /// Cascaded shadow maps for the sun (or the moon when the sun is below the horizon).
    #[serde(default)]
    pub shadow_cascades: ShadowCascades,
    /// Half-width in metres of the orthographic top view centred under the camera (sky
    /// visibility and mini-map passes use it as `top_view_proj`).
    #[serde(default = "default_top_view_extent")]
    pub top_view_extent: f32,
}

/// How the four shadow cascades are fitted to the view frustum: practical split scheme
/// (`split_lambda` blends logarithmic and linear splits) up to `max_distance`, each cascade a
/// bounding sphere of its frustum slice snapped to whole texels of a `resolution` map so the
/// shadows do not shimmer as the camera moves.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShadowCascades {
    #[serde(default = "default_cascade_resolution")]
    pub resolution: u32,
    #[serde(default = "default_split_lambda")]
    pub split_lambda: f32,
    #[serde(default = "default_shadow_distance")]
    pub max_distance: f32,
}

impl Default for ShadowCascades {
    fn default() -> Self {
        Self {
            resolution: default_cascade_resolution(),
            split_lambda: default_split_lambda(),
            max_distance: default_shadow_distance(),
        }
    }
}

pub(crate) fn default_cascade_resolution() -> u32 {
    2048
}
pub(crate) fn default_split_lambda() -> f32 {
    0.75
}
pub(crate) fn default_shadow_distance() -> f32 {
    200.0
}
pub(crate) fn default_top_view_extent() -> f32 {
    256.0
}

impl Default for FrameConstants {
    fn default() -> Self {
        Self {
            time_seconds: 0.0,
            delta_seconds: default_dt(),
            sun_direction: default_sun(),
            sun_color: default_sun_color(),
            moon_direction: default_moon(),
            moon_color: default_moon_color(),
            exposure: default_exposure(),
            shadow_cascades: ShadowCascades::default(),
            top_view_extent: default_top_view_extent(),
        }
    }
}

pub(crate) fn default_dt() -> f32 {
    1.0 / 60.0
}
pub(crate) fn default_sun() -> [f32; 3] {
    [0.3, 0.8, 0.4]
}
pub(crate) fn default_sun_color() -> [f32; 3] {
    [1.0, 0.95, 0.9]
}
pub(crate) fn default_moon() -> [f32; 3] {
    [-0.3, 0.6, -0.5]
}
pub(crate) fn default_moon_color() -> [f32; 3] {
    [0.05, 0.06, 0.09]
}
pub(crate) fn default_exposure() -> f32 {
    1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn access_read_write_classification() {
        assert!(Access::StorageReadWrite.reads() && Access::StorageReadWrite.writes());
        assert!(!Access::StorageWrite.reads() && Access::StorageWrite.writes());
        assert!(Access::Sampled.reads() && !Access::Sampled.writes());
        assert!(Access::DepthWrite.reads() && Access::DepthWrite.writes());
        assert!(!Access::CopyDst.reads());
        assert!(Access::StorageRead.is_unordered(true) && !Access::StorageRead.is_unordered(false));
        assert!(!Access::Sampled.is_unordered(true));
    }

    #[test]
    fn extents_accept_every_spelling() {
        let parse = |s: &str| serde_json::from_str::<Extent>(s).unwrap();
        assert_eq!(parse("1024"), Extent::Texels(1024));
        assert_eq!(parse("\"half\""), Extent::Named(RelativeSize::Half));
        assert_eq!(
            parse(r#"{"scale": 0.125, "multiple_of": 8}"#),
            Extent::Scaled {
                scale: 0.125,
                multiple_of: Some(8)
            }
        );
        assert!(serde_json::from_str::<Extent>("\"double\"").is_err());
    }

    #[test]
    fn states_take_one_or_many() {
        let one: States = serde_json::from_str("\"RENDER_TARGET\"").unwrap();
        assert_eq!(one.as_slice(), [ResourceState::RenderTarget]);
        let many: States =
            serde_json::from_str(r#"["PIXEL_SHADER_RESOURCE", "NON_PIXEL_SHADER_RESOURCE"]"#)
                .unwrap();
        assert_eq!(many.as_slice().len(), 2);
        assert!(ResourceState::UnorderedAccess.is_write() && !ResourceState::CopySource.is_write());
    }
}
