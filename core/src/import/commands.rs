//! The commands a command buffer holds once recorded, as the recording and the render pass
//! resolution make them and the builder reads them. A module of its own so that the
//! recording (which calls the render pass resolution) and the resolution (which makes these)
//! share them without importing each other.

use std::borrow::Cow;
use std::fmt;

use super::state::Descriptor;
use super::value::Arg;
use crate::capture::format::VkCommandState;
use crate::capture::vulkan::{AccessFlags, ImageLayout, PipelineStages};

/// Most draws one indirect call is expanded into.
pub const MAX_INDIRECT_DRAWS: u32 = 4096;

/// A mip or layer range: base, and count (`None`: VK_REMAINING_*, to the end).
pub type LevelRange = (u32, Option<u32>);

/// A descriptor a draw or dispatch can reach, with dynamic offsets applied.
#[derive(Clone, Debug)]
pub struct Use {
    pub set: u32,
    pub binding: u32,
    pub element: u32,
    pub descriptor: Descriptor,
}

#[derive(Clone, Debug)]
pub struct DrawCmd {
    pub count: u32,
    pub instances: u32,
    pub first: u32,
    pub base_vertex: i32,
    pub first_instance: u32,
    pub indirect: Option<(u64, u64)>,
    /// Where the GPU reads the draw's count (`vkCmdDrawIndirectCount`).
    pub draw_count: Option<DrawCountCmd>,
    pub uses: Vec<Use>,
    /// (binding, buffer, offset).
    pub vertex_buffers: Vec<(u32, u64, u64)>,
    /// (buffer, offset, `VK_INDEX_TYPE_*`).
    pub index_buffer: Option<(u64, u64, String)>,
    /// The graphics pipeline bound.
    pub pipeline: Option<u64>,
    pub state: VkCommandState,
    /// Dynamic states whose latest setter could not be read (state, the call and why).
    pub unread: Vec<(&'static str, Box<str>)>,
}

/// `vkCmdDrawIndirectCount`'s count buffer, the most records it draws, and how far apart
/// they are.
#[derive(Clone, Debug)]
pub struct DrawCountCmd {
    pub buffer: u64,
    pub offset: u64,
    pub max_draws: u32,
    pub stride: u32,
}

#[derive(Clone, Debug)]
pub struct DispatchCmd {
    pub groups: Option<[u32; 3]>,
    pub indirect: Option<(u64, u64)>,
    pub uses: Vec<Use>,
    /// The compute pipeline bound.
    pub pipeline: Option<u64>,
    pub state: VkCommandState,
}

#[derive(Clone, Debug, PartialEq)]
pub enum BarrierTarget {
    Global,
    Buffer {
        buffer: u64,
        /// The bytes it covers: offset and size (`VK_WHOLE_SIZE` as `u64::MAX`).
        range: (u64, u64),
    },
    Image {
        image: u64,
        mips: (u32, Option<u32>),
        layers: (u32, Option<u32>),
    },
}

/// The call a recorded command or barrier came from, spelt (`vkCmdDispatch #205`) only where
/// it is shown: the pass builder and the synchronization check meet one for every command,
/// and show few.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Origin {
    /// The call's index in the stream (the converter's block index).
    pub index: u64,
    pub name: Cow<'static, str>,
    /// A barrier a render pass implies for one of its attachments: the attachment, and
    /// whether it is the one into the render pass or out of it.
    pub attachment: Option<(u32, &'static str)>,
}

impl Origin {
    // The `Cow` itself, not its text, so that a name borrowed from the tables stays borrowed.
    #[allow(clippy::ptr_arg)]
    pub fn call(name: &Cow<'static, str>, index: u64) -> Self {
        Origin {
            index,
            name: name.clone(),
            attachment: None,
        }
    }

    /// Something no call of the stream did (spelt `text`, with no index).
    pub const fn none(text: &'static str) -> Self {
        Origin {
            index: u64::MAX,
            name: Cow::Borrowed(text),
            attachment: None,
        }
    }
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.index == u64::MAX {
            return f.write_str(&self.name);
        }
        write!(f, "{} #{}", self.name, self.index)?;
        if let Some((a, what)) = self.attachment {
            write!(f, ": attachment {a} {what}")?;
        }
        Ok(())
    }
}

#[derive(Clone, Debug)]
pub struct BarrierCmd {
    pub origin: Origin,
    pub target: BarrierTarget,
    pub src_stages: PipelineStages,
    pub dst_stages: PipelineStages,
    pub src_access: AccessFlags,
    pub dst_access: AccessFlags,
    pub layouts: Option<(ImageLayout, ImageLayout)>,
    pub families: Option<(u32, u32)>,
}

#[derive(Clone, Debug)]
pub struct AttUse {
    pub view: u64,
    /// Its index among the subpass's colour attachments, counting unused ones (what
    /// `vkCmdClearAttachments` names).
    pub slot: u32,
    pub load: String,
    pub store: String,
    pub clear: [f64; 4],
}

#[derive(Clone, Debug)]
pub struct DepthUse {
    pub view: u64,
    pub load: String,
    pub store: String,
    pub stencil_load: String,
    pub stencil_store: String,
    pub depth_clear: f64,
    pub stencil_clear: u32,
    /// The depth aspect is read-only in the subpass's layout.
    pub read_only: bool,
    /// The stencil aspect is read-only in the subpass's layout.
    pub stencil_read_only: bool,
}

/// The attachments of one subpass (or of one dynamic rendering instance).
#[derive(Clone, Debug, Default)]
pub struct SubpassUse {
    pub colors: Vec<AttUse>,
    pub depth: Option<DepthUse>,
    pub resolves: Vec<(u64, u64)>,
}

#[derive(Clone, Debug)]
pub struct RenderInstance {
    pub subpasses: Vec<SubpassUse>,
    /// Layout transitions the render pass performs at its start and its end.
    pub begin_barriers: Vec<BarrierCmd>,
    pub end_barriers: Vec<BarrierCmd>,
    /// Each attachment view with the layout the render pass expects it in at its start
    /// (`initialLayout`; `None` for `UNDEFINED`, which accepts any) and leaves it in.
    pub layouts: Vec<(u64, Option<ImageLayout>, ImageLayout)>,
    /// The framebuffer's (or `VkRenderingInfo`'s) layers: more than one is layered rendering,
    /// which the replay, rendering one layer of each attachment, refuses.
    pub layers: u32,
}

#[derive(Clone, Debug)]
pub struct Region {
    pub src_mip: u32,
    pub src_layer: u32,
    pub src_origin: [u32; 3],
    pub src_offset: u64,
    pub dst_mip: u32,
    pub dst_layer: u32,
    pub dst_origin: [u32; 3],
    pub dst_offset: u64,
    /// Buffer to buffer: bytes.
    pub size: Option<u64>,
    /// With a texture: texels.
    pub extent: Option<[u32; 3]>,
    /// Buffer footprint: texels per row (0: tightly packed).
    pub row_texels: u32,
    /// Rows per image of buffer data (`bufferImageHeight`; 0: the extent's height).
    pub image_rows: u32,
    /// Layers the region covers (`layerCount`).
    pub layers: u32,
}

/// One layer of a blit: mip, layer and the two corners (`srcOffsets` / `dstOffsets`, x and y)
/// of each side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlitRegionCmd {
    pub src: (u32, u32, [[u32; 2]; 2]),
    pub dst: (u32, u32, [[u32; 2]; 2]),
}

#[derive(Clone, Debug)]
pub enum TransferCmd {
    Copy {
        /// The pass's name, after the call (`copy_buffer_to_image`).
        name: String,
        src: u64,
        dst: u64,
        regions: Vec<Region>,
        /// The layouts the call says its source and destination images are in.
        layouts: (Option<ImageLayout>, Option<ImageLayout>),
    },
    Clear {
        /// `vkCmdClearDepthStencilImage` rather than `vkCmdClearColorImage`.
        depth_stencil: bool,
        target: u64,
        value: [f64; 4],
        stencil: u32,
        ranges: Vec<(LevelRange, LevelRange)>,
        /// The layout the call says the image is in.
        layout: Option<ImageLayout>,
    },
    Fill {
        /// `vkCmdUpdateBuffer` rather than `vkCmdFillBuffer`.
        update: bool,
        buffer: u64,
        /// The bytes written: offset and size (`VK_WHOLE_SIZE` as `u64::MAX`).
        range: (u64, u64),
    },
    Resolve {
        src: u64,
        dst: u64,
    },
    /// `vkCmdBlitImage` / `vkCmdBlitImage2`: one region per layer blitted.
    Blit {
        src: u64,
        dst: u64,
        regions: Vec<BlitRegionCmd>,
        linear: bool,
        layouts: (Option<ImageLayout>, Option<ImageLayout>),
        /// Why the replay cannot do it (a cubic filter, a 3D region), named at the build.
        refused: Option<String>,
    },
}

/// A `vkCmdClearAttachments`: colour attachments by their subpass index with values, the
/// depth and stencil values, and rectangles (`[x, y, width, height]`, base layer, layers).
#[derive(Clone, Debug, Default)]
pub struct AttachmentClearCmd {
    pub colors: Vec<(u32, ClearColorValue)>,
    pub depth: Option<f32>,
    pub stencil: Option<u32>,
    pub rects: Vec<([i64; 4], u32, u32)>,
}

#[derive(Clone, Debug)]
pub enum Cmd {
    BeginRender(Box<RenderInstance>),
    NextSubpass,
    EndRender,
    Draw(Box<DrawCmd>),
    Dispatch(Box<DispatchCmd>),
    Barrier(Vec<BarrierCmd>),
    Transfer(Box<TransferCmd>),
    BeginLabel(String),
    EndLabel,
    Execute(Vec<u64>),
    /// `vkCmdClearAttachments`.
    ClearAttachments(Box<AttachmentClearCmd>),
    /// A command the replay cannot reproduce, by its function's name (`coverage::command`
    /// says why).
    Refused(Box<str>),
}

/// A `VkClearColorValue` read through the view the attachment's format `format`
/// (`VK_FORMAT_*`) reads it by (`ClearColorValue::through`).
pub fn clear_color_of(v: &Arg<'_>, format: Option<&str>) -> [f64; 4] {
    ClearColorValue::read(v).through(format)
}

/// A `VkClearColorValue` as each member of the union reads it, for a command whose
/// attachment's format is known only later (`vkCmdClearAttachments` names its attachment by
/// its index in the subpass).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClearColorValue {
    pub(super) float32: Option<[f64; 4]>,
    pub(super) uint32: Option<[f64; 4]>,
    pub(super) int32: Option<[f64; 4]>,
}

impl ClearColorValue {
    /// The members `v` (a `VkClearColorValue`, or a `VkClearValue` holding one) has. A
    /// component that is not a finite number is 0: JSON holds none, and programs leave the
    /// channels a format lacks unset (zink clears a one-channel float attachment with NaN in
    /// the other three).
    pub fn read(v: &Arg<'_>) -> Self {
        let color = v.opt("color").unwrap_or(*v);
        let member = |key: &str| {
            let list = color.opt(key)?.items().ok()?;
            let mut out = [0.0; 4];
            for (o, x) in out.iter_mut().zip(&list) {
                *o = x.f64().ok().filter(|x| x.is_finite()).unwrap_or(0.0);
            }
            Some(out)
        };
        ClearColorValue {
            float32: member("float32"),
            uint32: member("uint32"),
            int32: member("int32"),
        }
    }

    /// The value as the format `format` reads it: `uint32` for unsigned integer formats,
    /// `int32` for signed ones, `float32` otherwise (and where the format is not known); a
    /// member the source lacks gives way to the others, in that order.
    pub fn through(&self, format: Option<&str>) -> [f64; 4] {
        let first = match format {
            Some(f) if f.ends_with("_UINT") => self.uint32,
            Some(f) if f.ends_with("_SINT") => self.int32,
            _ => self.float32,
        };
        first
            .or(self.float32)
            .or(self.uint32)
            .or(self.int32)
            .unwrap_or_default()
    }
}
