//! Comparing two sessions' textures after the same frame, or after each pass of it (the first
//! pass whose outputs differ is where a change starts): every texture the two plans name
//! alike is read back whole (every mip and layer) and its values compared exactly; a changed
//! one gets FLIP (NVIDIA's perceptual error metric, through `nv-flip`) of its first
//! subresource as shown, with the error map in FLIP's magma colours. A what-if says with it
//! whether an edit changed any image and by how much.

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;

use crate::decode::{self, DecodedImage};
use crate::export::display_rgba8;
use crate::replaying::Replaying;
use crate::run::{ReplayError, Session};

/// FLIP of `test` against `reference`: mean, 99th percentile and the error map.
#[derive(Debug, Clone)]
pub struct Flip {
    pub mean: f64,
    pub p99: f64,
    pub map: image::RgbImage,
}

fn flip_image(i: &image::RgbaImage) -> nv_flip::FlipImageRgb8 {
    let rgb = image::DynamicImage::ImageRgba8(i.clone()).to_rgb8();
    nv_flip::FlipImageRgb8::with_data(i.width(), i.height(), rgb.as_raw())
}

/// FLIP of two images of one size; `None` where their sizes differ.
pub fn flip(reference: &image::RgbaImage, test: &image::RgbaImage) -> Option<Flip> {
    if reference.dimensions() != test.dimensions() {
        return None;
    }
    let error = nv_flip::flip(
        flip_image(reference),
        flip_image(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mut pool = nv_flip::FlipPool::from_image(&error);
    let map = error.apply_color_lut(&nv_flip::magma_lut());
    Some(Flip {
        mean: f64::from(pool.mean()),
        p99: f64::from(pool.get_percentile(0.99, false)),
        map: image::RgbImage::from_raw(reference.width(), reference.height(), map.to_vec())?,
    })
}

/// How one texture compares.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "state")]
pub enum TextureState {
    /// Every value of every subresource is the same.
    Identical,
    /// Some value differs: how many texels of the first subresource and the FLIP of it.
    Changed {
        texels: usize,
        flip_mean: Option<f64>,
        flip_p99: Option<f64>,
    },
    /// The two have other sizes or subresources (a format or size edit).
    Reshaped,
    /// Not read back (a format the replay cannot read), with why.
    NotCompared { why: String },
}

/// One texture of both sessions, compared.
#[derive(Debug, Clone, Serialize)]
pub struct TextureComparison {
    pub name: String,
    /// A file-name stem for it, unique among the plan's textures (as `export` names files).
    #[serde(skip)]
    pub stem: String,
    #[serde(flatten)]
    pub state: TextureState,
    /// The first subresource of each side as shown and the FLIP map, for changed textures.
    #[serde(skip)]
    pub images: Option<(image::RgbaImage, image::RgbaImage, Option<image::RgbImage>)>,
}

/// Why a texture was not read back for the comparison.
#[derive(Debug, thiserror::Error)]
enum NotRead {
    #[error("{}", .0.0)]
    Format(decode::Unreadable),
    #[error(transparent)]
    Read(#[from] decode::ReadError),
}

fn read(session: &Session, index: usize) -> Result<Vec<DecodedImage>, NotRead> {
    let spec = &session.plan.textures[index];
    let format = decode::readable_format(spec).map_err(NotRead::Format)?;
    Ok(decode::read_texture(
        &session.device,
        &session.queue,
        session.texture(index),
        spec,
        format,
    )?)
}

fn compare_one(
    (name, stem): (&str, &str),
    a: &Session,
    ia: usize,
    b: &Session,
    ib: usize,
) -> TextureComparison {
    let state = |state| TextureComparison {
        name: name.to_owned(),
        stem: stem.to_owned(),
        state,
        images: None,
    };
    let (da, db) = match (read(a, ia), read(b, ib)) {
        (Ok(x), Ok(y)) => (x, y),
        (Err(why), _) | (_, Err(why)) => {
            return state(TextureState::NotCompared {
                why: why.to_string(),
            });
        }
    };
    let shape = |d: &[DecodedImage]| -> Vec<(u32, u32, u32, u32)> {
        d.iter()
            .map(|i| (i.mip, i.layer, i.width, i.height))
            .collect()
    };
    if shape(&da) != shape(&db) {
        return state(TextureState::Reshaped);
    }
    if da.iter().zip(&db).all(|(x, y)| x.values == y.values) {
        return state(TextureState::Identical);
    }
    let (first_a, first_b) = (&da[0], &db[0]);
    let texels = first_a
        .values
        .iter()
        .zip(&first_b.values)
        .filter(|(x, y)| x != y)
        .count();
    let (ra, rb) = (display_rgba8(first_a), display_rgba8(first_b));
    let f = flip(&ra, &rb);
    TextureComparison {
        name: name.to_owned(),
        stem: stem.to_owned(),
        state: TextureState::Changed {
            texels,
            flip_mean: f.as_ref().map(|f| f.mean),
            flip_p99: f.as_ref().map(|f| f.p99),
        },
        images: Some((ra, rb, f.map(|f| f.map))),
    }
}

/// Every texture both sessions' plans name alike, compared as the last frame left it, in
/// name order; textures of one plan only are left out (the caller's structural diff names
/// them).
pub fn compare_textures(a: &Session, b: &Session) -> Vec<TextureComparison> {
    let (na, nb) = (texture_index(a), texture_index(b));
    let stems = crate::export::unique_stems(&a.plan.textures);
    na.iter()
        .filter_map(|(name, &ia)| Some((name, ia, *nb.get(name)?)))
        .map(|(name, ia, ib)| compare_one((name, &stems[ia]), a, ia, b, ib))
        .collect()
}

/// The textures one pass writes, compared after it on both sides, where any differs.
#[derive(Debug, Clone, Serialize)]
pub struct PassComparison {
    /// The pass, as the capture names it.
    pub pass: String,
    /// Each texture the pass writes that differs after it.
    pub changed: Vec<TextureComparison>,
}

/// The plan passes of a replay by the capture pass's name, in plan order: a pass of `a` meets
/// the one of `b` with its name and occurrence.
fn passes_by_name(r: &Replaying) -> BTreeMap<String, Vec<usize>> {
    let mut out: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (k, &id) in r.pass_ids.iter().enumerate() {
        out.entry(r.capture().pass(id).name.clone())
            .or_default()
            .push(k);
    }
    out
}

/// The names of the textures plan pass `k` writes.
fn written_by(r: &Replaying, k: usize) -> BTreeSet<String> {
    let c = r.capture();
    c.pass(r.pass_ids[k])
        .accesses
        .iter()
        .filter(|x| x.writes)
        .map(|x| c.resource(x.resource).name.clone())
        .collect()
}

/// Runs frame `f` of both replays stopped after each pass of `a` that `b` has too (by name and
/// occurrence; a pass `renamed` names there by that name), and compares the textures that pass writes on both sides: the passes whose
/// outputs differ, in `a`'s order. Each stop replays the frame from its start, so this costs
/// about half as many frames as there are passes, on each side; the frames are not timed.
pub fn after_each_pass(
    a: &mut Replaying,
    b: &mut Replaying,
    f: u32,
    renamed: &BTreeMap<String, String>,
) -> Result<Vec<PassComparison>, ReplayError> {
    let theirs = passes_by_name(b);
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let (index_a, index_b) = (texture_index(&a.session), texture_index(&b.session));
    let stems = crate::export::unique_stems(&a.session.plan.textures);
    let mut out = Vec::new();
    for k in 0..a.pass_ids.len() {
        let name = a.capture().pass(a.pass_ids[k]).name.clone();
        let occurrence = seen.entry(name.clone()).or_default();
        let there = theirs
            .get(renamed.get(&name).unwrap_or(&name))
            .and_then(|ks| ks.get(*occurrence))
            .copied();
        *occurrence += 1;
        let Some(kb) = there else { continue };
        let written: Vec<(String, usize, usize)> = written_by(a, k)
            .into_iter()
            .filter_map(|t| {
                let (ia, ib) = (*index_a.get(&t)?, *index_b.get(&t)?);
                Some((t, ia, ib))
            })
            .collect();
        if written.is_empty() {
            continue;
        }
        let (ca, cb) = (a.constants(f), b.constants(f));
        a.session.run_frame(&ca, Some(k))?;
        b.session.run_frame(&cb, Some(kb))?;
        let changed: Vec<TextureComparison> = written
            .iter()
            .map(|(t, ia, ib)| compare_one((t, &stems[*ia]), &a.session, *ia, &b.session, *ib))
            .filter(|c| !matches!(c.state, TextureState::Identical))
            .collect();
        if !changed.is_empty() {
            out.push(PassComparison {
                pass: name,
                changed,
            });
        }
    }
    Ok(out)
}

/// The plan's textures by name.
fn texture_index(s: &Session) -> BTreeMap<String, usize> {
    s.plan
        .textures
        .iter()
        .enumerate()
        .map(|(i, t)| (t.name.clone(), i))
        .collect()
}
