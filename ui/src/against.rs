//! The image diff: a second capture (or a second replay of the same one) replayed beside the
//! first by its own worker on its own device. For the current pass, the pass the structural
//! diff pairs with it there (so renamed and moved passes still meet) shows the texture of the
//! same name with the same controls, and the two images as shown are compared with FLIP
//! (NVIDIA's perceptual error metric, `framelab_replay::compare::flip`) on a thread of its own; the
//! error map is drawn with FLIP's magma colours.

use std::sync::Arc;
use std::sync::mpsc::Receiver;

use crate::model::Inspection;
use crate::worker::{TextureRequest, ViewRequest};

/// B's image as of its pass.
pub struct Shown {
    pub request: ViewRequest,
    pub texture: egui::TextureHandle,
    pub pixels: Arc<egui::ColorImage>,
}

/// FLIP between the two images as shown: its mean and 99th percentile, and the error map.
pub struct Flip {
    pub key: (ViewRequest, ViewRequest),
    pub result: Result<FlipResult, SizesDiffer>,
}

/// FLIP compares images of one size.
#[derive(Clone, Copy, Debug, thiserror::Error)]
#[error(
    "the images differ in size ({}x{} here, {}x{} there): FLIP compares equal sizes",
    .here[0], .here[1], .there[0], .there[1]
)]
pub struct SizesDiffer {
    pub here: [usize; 2],
    pub there: [usize; 2],
}

pub struct FlipResult {
    pub mean: f32,
    pub p99: f32,
    pub map: egui::TextureHandle,
}

/// What the image diff pane shows of the second capture.
pub struct Against {
    pub model: Arc<Inspection>,
    /// For each pass here, the pass there and whether the structural diff paired them as a
    /// rename.
    pub pass_of: Vec<Option<(usize, bool)>>,
    pub shown: Option<Shown>,
    pub flip: Option<Flip>,
    pub status: String,
    pub error: Option<String>,
    pub(crate) sent: Option<ViewRequest>,
    pub(crate) job: Option<FlipJob>,
}

impl std::fmt::Debug for Shown {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Shown")
            .field("request", &self.request)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for Flip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Flip")
            .field("key", &self.key)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for FlipResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FlipResult")
            .field("mean", &self.mean)
            .field("p99", &self.p99)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for Against {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Against")
            .field("capture", &self.model.capture)
            .field("sent", &self.sent)
            .finish_non_exhaustive()
    }
}

/// A FLIP computed off the UI thread: mean, 99th percentile, the map's pixels.
pub(crate) type FlipOutput = (f32, f32, egui::ColorImage);

/// A FLIP being computed: the two views it compares and where its result arrives.
pub(crate) type FlipJob = (
    (ViewRequest, ViewRequest),
    Receiver<Result<FlipOutput, SizesDiffer>>,
);

impl Against {
    /// The second capture's model, paired with `here` through `pairs` (capture pass indices,
    /// here and there, and whether the pair is a rename).
    pub fn new(here: &Inspection, model: Inspection, pairs: &[(usize, usize, bool)]) -> Against {
        let pass_of = here
            .passes
            .iter()
            .map(|p| {
                let &(_, j, renamed) = pairs.iter().find(|(i, _, _)| *i == p.id.index())?;
                let there = model.pass_position(crate::model::PassId(j as u32))?;
                Some((there, renamed))
            })
            .collect();
        Against {
            model: Arc::new(model),
            pass_of,
            shown: None,
            flip: None,
            status: "starting".into(),
            error: None,
            sent: None,
            job: None,
        }
    }

    /// What to ask of the second worker for the view `here` wants: the paired pass, the texture
    /// of the same name, the same subresource and controls.
    pub fn wanted(
        &self,
        here: &Inspection,
        view: &ViewRequest,
        resource: Option<usize>,
    ) -> Option<ViewRequest> {
        let (pass, _) = self.pass_of.get(view.pass).copied().flatten()?;
        let t = view.texture.as_ref()?;
        let name = &here.resources.get(resource?)?.name;
        let there = self.model.resources.iter().find(|r| &r.name == name)?;
        let tv = there.texture.as_ref().filter(|t| t.unviewable.is_none())?;
        Some(ViewRequest {
            pass,
            step: None,
            texture: Some(TextureRequest {
                plan_index: tv.plan_index,
                sampling: t.sampling,
                volume: tv.volume,
                sub: t.sub,
                controls: t.controls,
                stride: t.stride,
            }),
            buffer: None,
        })
    }
}

/// An egui image as the `image` crate holds it.
fn rgba(i: &egui::ColorImage) -> image::RgbaImage {
    let bytes: Vec<u8> = i.pixels.iter().flat_map(|c| c.to_array()).collect();
    image::RgbaImage::from_raw(i.size[0] as u32, i.size[1] as u32, bytes).unwrap_or_default()
}

/// FLIP of `test` against `reference` (both as shown, gamma-encoded), or why not.
pub(crate) fn flip(
    reference: &egui::ColorImage,
    test: &egui::ColorImage,
) -> Result<FlipOutput, SizesDiffer> {
    let differ = SizesDiffer {
        here: reference.size,
        there: test.size,
    };
    if reference.size != test.size {
        return Err(differ);
    }
    let f = framelab_replay::compare::flip(&rgba(reference), &rgba(test)).ok_or(differ)?;
    let map: Vec<u8> = f
        .map
        .pixels()
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    Ok((
        f.mean as f32,
        f.p99 as f32,
        egui::ColorImage::from_rgba_unmultiplied(reference.size, &map),
    ))
}
