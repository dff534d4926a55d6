//! Night City: the Cyberpunk 2077 frame of NIGHT_CITY_PASSES.md, generated from Rust. The
//! capture JSON under `captures/night_city/` is this module's output (`examples/night_city.rs`
//! writes it; a test checks that the committed file is byte for byte what it writes), so the
//! day and night variants share every pass and resource instead of drifting apart as two
//! hand-edited files would. The values are assembled untyped (`serde_json::Value`, reading like
//! the JSON they become) and then deserialised into the format's own `RawCapture`, which rejects
//! any field the format does not know; the file is that `RawCapture` serialised.

mod composition;
mod helpers;
mod passes;
mod post;
mod resources;
mod scene;

pub use scene::SceneError;

use serde_json::{Value, json};

use framelab_core::capture::format::RawCapture;

/// Which capture of the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// `main_street_day.json`: down the main street towards the water, by day.
    MainStreetDay,
    /// `river_bank_night.json`: from the river back across the water to the city, at night.
    RiverBankNight,
}

impl Variant {
    pub const ALL: [Variant; 2] = [Variant::MainStreetDay, Variant::RiverBankNight];

    /// The capture's file, relative to the repository root.
    pub fn path(self) -> &'static str {
        match self {
            Variant::MainStreetDay => "captures/night_city/main_street_day.json",
            Variant::RiverBankNight => "captures/night_city/river_bank_night.json",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Variant::MainStreetDay => "main_street_day",
            Variant::RiverBankNight => "river_bank_night",
        }
    }

    fn description(self) -> &'static str {
        match self {
            Variant::MainStreetDay => {
                "Night City, main street by day: a reconstruction of the Cyberpunk 2077 frame analysed in the source article (1080p Ultra, D3D12, one graphics, one compute and one copy queue). Resources follow NIGHT_CITY_PASSES.md by name, format and size; sizes that follow the output are relative so --scale replays the same frame smaller."
            }
            Variant::RiverBankNight => {
                "Night City, river bank at night: the same frame and shaders as main_street_day, seen from over the river towards the city under the moon, with 1024 neon lights, denser fog and the water's reflection in view; no billboard copies and no dead LOD pass. Resources follow NIGHT_CITY_PASSES.md by name, format and size; sizes that follow the output are relative so --scale replays the same frame smaller."
            }
        }
    }

    fn day(self) -> bool {
        matches!(self, Variant::MainStreetDay)
    }
}

const FENCES: [&str; 23] = [
    "billboard_sources",
    "gui_drawn",
    "voxels_ready",
    "instances_ready",
    "reflection_done",
    "masks_done",
    "noised_ready",
    "ao_done",
    "omni_done",
    "cascades_done",
    "sun_shadow_ready",
    "env_captured",
    "direct_lit",
    "ssr_done",
    "indirect_ready",
    "transparent_lut_ready",
    "taa_done",
    "taa_read",
    "scene_done",
    "bloom_done",
    "gui_copied",
    "gui_ready",
    "final_ready",
];

/// Why the scene could not be written.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    #[error("the scene asks scene.wgsl for something it lacks: {0}")]
    Shader(SceneError),
    #[error("the scene does not fit the capture format: {0}")]
    Format(#[from] serde_json::Error),
}

/// The capture as JSON values, before the format's types check it.
fn value(variant: Variant) -> Result<Value, GenerateError> {
    let day = variant.day();
    let mut capture = resources::header();
    if !day {
        capture["camera"] = json!({
            "position": [-3.0, 2.5, 206.0],
            "target": [-8.0, 9.0, 100.0],
            "fov_y_degrees": 60.0,
            "near": 0.1,
            "far": 2000.0,
            "velocity": [0.1, 0.0, -0.35],
            "jitter_phases": 8
        });
        capture["frame"] = json!({
            "time_seconds": 84600.0,
            "sun_direction": [0.3, -0.45, 0.5],
            "sun_color": [0.0, 0.0, 0.0],
            "moon_direction": [0.25, 0.3, -0.9],
            "moon_color": [0.06, 0.07, 0.11],
            "exposure": 0.9,
            "shadow_cascades": {"resolution": 4096, "split_lambda": 0.8, "max_distance": 220}
        });
    }
    capture["name"] = json!(variant.name());
    capture["description"] = json!(variant.description());
    let mut resources = resources::resources();
    for r in &mut resources {
        if r["name"] == "lights" {
            // Neon and shop lights over the district (the city spans about 200 x 300 m).
            r["initial"]["generator"]["params"]["count"] = json!(scene::light_count(day));
        }
    }
    capture["resources"] = Value::Array(resources);
    capture["fences"] = FENCES
        .iter()
        .filter(|&&f| day || f != "billboard_sources")
        .map(|f| json!({ "name": f }))
        .collect();
    capture["meshes"] = Value::Array(scene::meshes());
    capture["passes"] = Value::Array(passes::passes(day).map_err(GenerateError::Shader)?);
    Ok(capture)
}

/// The capture, checked against the format's types.
pub fn capture(variant: Variant) -> Result<RawCapture, GenerateError> {
    Ok(serde_json::from_value(value(variant)?)?)
}

/// The capture file's contents: pretty JSON with a trailing newline.
pub fn json(variant: Variant) -> Result<String, GenerateError> {
    Ok(serde_json::to_string_pretty(&capture(variant)?)? + "\n")
}
