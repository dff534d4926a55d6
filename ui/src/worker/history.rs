//! Pixel history: for one texel of one texture, every pass of the browsed frame that wrote
//! the texture, with the texel's value after it, and inside each pass that changed the texel,
//! its value after each draw or dispatch. Pass values come from the pass copies; draw values
//! from the frame held open at the pass (`steps`): the pass replayed up to each draw in turn
//! from a copy of what it had written before it started (so a draw's value never includes the
//! draws after it).

use super::{State, TextureRequest, WorkerError};

/// Passes whose draws are looked into, at most (each costs a replay of the frame up to it).
pub const MAX_PASSES_BY_DRAW: usize = 8;
/// Draws or dispatches of one pass looked into, at most.
pub const MAX_STEPS: usize = 256;

/// What a history is asked for: a texel of a subresource of a plan texture.
#[derive(Clone, Debug, PartialEq)]
pub struct HistoryRequest {
    pub texture: TextureRequest,
    pub x: u32,
    pub y: u32,
}

/// One write: the pass (and draw or dispatch) and the texel's value after it.
#[derive(Clone, Debug, PartialEq)]
pub struct HistoryRow {
    pub pass: usize,
    pub step: Option<usize>,
    /// The value as the format stores it, or why it could not be read.
    pub value: String,
    /// The value differs from the one before.
    pub changed: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct PixelHistory {
    pub request: HistoryRequest,
    /// The value the frame started with.
    pub start: String,
    pub rows: Vec<HistoryRow>,
    /// What was left out (passes or draws beyond the limits).
    pub notes: Vec<String>,
}

/// The texel's value in `texture` (a replay texture or a copy of it), as text.
fn texel(s: &State, texture: &wgpu::Texture, h: &HistoryRequest) -> String {
    let t = &h.texture;
    let (images, note) = super::read_sub(s, texture, t);
    if let Some(why) = note {
        return format!("not read: {why}");
    }
    let images: Vec<_> = images.into_iter().map(|d| (d, ())).collect();
    super::subresource(&images, t)
        .and_then(|(d, _)| d.texel_values(h.x, h.y))
        .unwrap_or_else(|| "outside the subresource".to_owned())
}

/// The history of the requested texel through the browsed frame.
pub fn history(s: &mut State, h: &HistoryRequest) -> Result<PixelHistory, WorkerError> {
    if s.browsing {
        return Err(WorkerError::Later);
    }
    let t = h.texture.plan_index;
    let writers: Vec<usize> = s
        .writes
        .iter()
        .enumerate()
        .filter(|(_, w)| w.textures.contains(&t))
        .map(|(i, _)| i)
        .collect();
    let start = match s.snaps.frame_start_texture(t) {
        Some(copy) => texel(s, &copy, h),
        None => {
            // No copy of the frame's start: nothing writes it, or the budget evicted it.
            let (texture, _) = match writers.first() {
                Some(&0) | None => super::texture_at(s, t, 0)?,
                Some(&w) => super::texture_at(s, t, w - 1)?,
            };
            texel(s, &texture, h)
        }
    };
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    let mut before = start.clone();
    let mut by_draw = 0;
    for &pass in &writers {
        let (texture, _) = super::texture_at(s, t, pass)?;
        let value = texel(s, &texture, h);
        let changed = value != before;
        let steps = s.writes.get(pass).map_or(0, |w| w.steps);
        if changed && steps > 0 {
            if by_draw < MAX_PASSES_BY_DRAW && steps <= MAX_STEPS {
                by_draw += 1;
                let values = by_step(s, pass, steps, h)?;
                let mut last = before.clone();
                for (k, v) in values.into_iter().enumerate() {
                    let changed = v != last;
                    last = v.clone();
                    rows.push(HistoryRow {
                        pass,
                        step: Some(k),
                        value: v,
                        changed,
                    });
                }
            } else {
                notes.push(format!(
                    "pass {} not looked into draw by draw ({steps} draws or dispatches; at most \
                     {MAX_STEPS} in at most {MAX_PASSES_BY_DRAW} passes)",
                    s.replaying.session.plan.passes[pass].name
                ));
            }
        }
        rows.push(HistoryRow {
            pass,
            step: None,
            value: value.clone(),
            changed,
        });
        before = value;
    }
    Ok(PixelHistory {
        request: h.clone(),
        start,
        rows,
        notes,
    })
}

/// The texel after each of the first `steps` draws or dispatches of `pass`: the pass replayed
/// up to each in turn from its starting contents, in the frame held open at it.
fn by_step(
    s: &mut State,
    pass: usize,
    steps: usize,
    h: &HistoryRequest,
) -> Result<Vec<String>, WorkerError> {
    let t = h.texture.plan_index;
    let mut values = Vec::with_capacity(steps);
    for k in 0..steps {
        super::steps::run_until(s, pass, k)?;
        let live = s.replaying.session.texture_in_frame(t).clone();
        values.push(texel(s, &live, h));
    }
    Ok(values)
}
