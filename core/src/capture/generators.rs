//! The named procedural generators a capture may use for initial contents and meshes, with the
//! parameters each accepts. Validation checks names and parameters against this table so a
//! misspelt generator or parameter is reported with a suggestion before anything runs, then
//! turns name and parameters into a typed generator (`Content`, `Shape`) with every default
//! applied, so lowering matches on variants and never looks a name up again.

use std::collections::BTreeMap;

use super::format::ParamValue;

/// One generator: its name, what it makes, and its parameters with their defaults.
#[derive(Debug)]
pub struct GeneratorSpec {
    pub name: &'static str,
    pub description: &'static str,
    pub params: &'static [(&'static str, f64)],
}

/// The street grid shared by the `city_blocks` mesh and the `city_lots` instance rows.
const CITY_PARAMS: &[(&str, f64)] = &[
    ("blocks_x", 8.0),
    ("blocks_z", 8.0),
    ("block_size", 40.0),
    ("street_width", 12.0),
    ("min_height", 10.0),
    ("max_height", 120.0),
    ("buildings_per_block", 4.0),
];

/// The largest magnitude a parameter that drives the amount of work may take: vertex counts
/// grow with the square of divisions and resolutions, noise cost with octaves, records with
/// counts. Generous for any real frame, and small enough that a capture cannot ask for
/// unbounded memory or time.
pub fn param_limit(param: &str) -> Option<f64> {
    Some(match param {
        "divisions" | "resolution" => 4096.0,
        "segments" | "rings" => 1024.0,
        "octaves" => 16.0,
        "count" => 1_000_000.0,
        "blocks_x" | "blocks_z" => 256.0,
        "buildings_per_block" => 64.0,
        "cells" => 65_536.0,
        "frequency" => 65_536.0,
        _ => return None,
    })
}

/// Generators for mesh sources.
pub const MESH_GENERATORS: &[GeneratorSpec] = &[
    GeneratorSpec {
        name: "grid",
        description: "flat XZ grid of size x size metres with divisions^2 quads",
        params: &[("size", 10.0), ("divisions", 16.0)],
    },
    GeneratorSpec {
        name: "box",
        description: "unit box scaled by size",
        params: &[("size", 1.0)],
    },
    GeneratorSpec {
        name: "city_blocks",
        description: "building boxes on a street grid with seeded heights",
        params: CITY_PARAMS,
    },
    GeneratorSpec {
        name: "terrain",
        description: "noise heightfield of size x size metres with resolution^2 vertices",
        params: &[
            ("size", 512.0),
            ("resolution", 128.0),
            ("height", 20.0),
            ("octaves", 5.0),
        ],
    },
    GeneratorSpec {
        name: "water_plate",
        description: "flat water grid at a given height",
        params: &[("size", 256.0), ("divisions", 64.0), ("height", 0.0)],
    },
    GeneratorSpec {
        name: "foliage_cards",
        description: "crossed alpha-tested quads scattered over an area",
        params: &[
            ("count", 64.0),
            ("area", 100.0),
            ("height", 4.0),
            ("width", 2.0),
        ],
    },
    GeneratorSpec {
        name: "sphere",
        description: "UV sphere",
        params: &[("radius", 1.0), ("segments", 32.0), ("rings", 16.0)],
    },
    GeneratorSpec {
        name: "capsule",
        description: "capsule (characters)",
        params: &[("radius", 0.3), ("height", 1.8), ("segments", 16.0)],
    },
];

/// Generators for texture and buffer initial contents.
pub const CONTENT_GENERATORS: &[GeneratorSpec] = &[
    GeneratorSpec {
        name: "noise",
        description: "fractal value noise in every channel",
        params: &[("frequency", 4.0), ("octaves", 4.0), ("amplitude", 1.0)],
    },
    GeneratorSpec {
        name: "blue_noise",
        description: "void-and-cluster style blue noise (RG used for rotations)",
        params: &[],
    },
    GeneratorSpec {
        name: "checker",
        description: "two-colour checkerboard",
        params: &[("cells", 8.0)],
    },
    GeneratorSpec {
        name: "constant",
        description: "every element set to one value",
        params: &[("value", 0.0)],
    },
    GeneratorSpec {
        name: "gradient",
        description: "horizontal and vertical ramps in R and G",
        params: &[],
    },
    GeneratorSpec {
        name: "atlas",
        description: "glyph and panel patterns for billboards and GUI elements",
        params: &[("cells", 16.0)],
    },
    GeneratorSpec {
        name: "coastline",
        description: "land/water mask with a noisy shoreline",
        params: &[("shore", 0.6), ("frequency", 3.0)],
    },
    GeneratorSpec {
        name: "lights",
        description: "point/spot light records scattered over the district",
        params: &[
            ("count", 256.0),
            ("area", 400.0),
            ("min_radius", 4.0),
            ("max_radius", 18.0),
            ("intensity", 40.0),
        ],
    },
    GeneratorSpec {
        name: "instances",
        description: "per-instance transform rows for instanced meshes",
        params: &[("count", 64.0), ("area", 200.0)],
    },
    GeneratorSpec {
        name: "city_lots",
        description: "one transform per building lot of a street grid, the same lots and heights as city_blocks (a unit box becomes a building)",
        params: CITY_PARAMS,
    },
];

pub fn find<'a>(table: &'a [GeneratorSpec], name: &str) -> Option<&'a GeneratorSpec> {
    table.iter().find(|g| g.name == name)
}

/// A generator with its seed, as validation resolved it.
#[derive(Clone, Debug, PartialEq)]
pub struct Seeded<G> {
    pub generator: G,
    pub seed: u64,
}

/// The street grid of `city_blocks` and `city_lots`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct City {
    pub blocks_x: f64,
    pub blocks_z: f64,
    pub block_size: f64,
    pub street_width: f64,
    pub min_height: f64,
    pub max_height: f64,
    pub buildings_per_block: f64,
}

impl City {
    /// The same grid with every value rounded to `f32`, as mesh generators (which build in
    /// `f32`) see it.
    pub fn rounded_to_f32(self) -> City {
        let r = |v: f64| f64::from(v as f32);
        City {
            blocks_x: r(self.blocks_x),
            blocks_z: r(self.blocks_z),
            block_size: r(self.block_size),
            street_width: r(self.street_width),
            min_height: r(self.min_height),
            max_height: r(self.max_height),
            buildings_per_block: r(self.buildings_per_block),
        }
    }
}

/// Texture and buffer contents, every parameter given or defaulted.
#[derive(Clone, Debug, PartialEq)]
pub enum Content {
    Noise {
        frequency: f64,
        octaves: f64,
        amplitude: f64,
    },
    BlueNoise,
    Checker {
        cells: f64,
    },
    Constant {
        value: f64,
    },
    Gradient,
    Atlas {
        cells: f64,
    },
    Coastline {
        shore: f64,
        frequency: f64,
    },
    Lights {
        count: f64,
        area: f64,
        min_radius: f64,
        max_radius: f64,
        intensity: f64,
    },
    Instances {
        count: f64,
        area: f64,
    },
    CityLots(City),
}

/// Mesh generators, every parameter given or defaulted.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Grid {
        size: f64,
        divisions: f64,
    },
    Box {
        size: f64,
    },
    CityBlocks(City),
    Terrain {
        size: f64,
        resolution: f64,
        height: f64,
        octaves: f64,
    },
    WaterPlate {
        size: f64,
        divisions: f64,
        height: f64,
    },
    FoliageCards {
        count: f64,
        area: f64,
        height: f64,
        width: f64,
    },
    Sphere {
        radius: f64,
        segments: f64,
        rings: f64,
    },
    Capsule {
        radius: f64,
        height: f64,
        segments: f64,
    },
}

impl Shape {
    /// The (vertices, indices) the generator builds, worked out without building them, so
    /// validation can check a draw's range against a generated mesh as against a file's
    /// stated counts. Parameters are rounded as the generator rounds them (to `f32`, then to
    /// an integer, saturating); the lowering tests hold this equal to what it builds.
    pub fn counts(&self) -> (u64, u64) {
        let whole = |v: f64| u64::from(v as f32 as u32);
        let grid = |divisions: f64| {
            let n = whole(divisions).max(1);
            ((n + 1) * (n + 1), 6 * n * n)
        };
        let sphere = |segments: u64, rings: u64| {
            let (s, r) = (segments.max(3), rings.max(2));
            ((r + 1) * (s + 1), 6 * r * s)
        };
        match *self {
            Shape::Grid { divisions, .. } | Shape::WaterPlate { divisions, .. } => grid(divisions),
            Shape::Terrain { resolution, .. } => grid(resolution),
            Shape::Box { .. } => (24, 36),
            Shape::CityBlocks(city) => {
                let c = city.rounded_to_f32();
                let n = |v: f64| (v as i64).max(0).unsigned_abs();
                let per = n(c.buildings_per_block.max(1.0));
                let buildings = n(c.blocks_x)
                    .saturating_mul(n(c.blocks_z))
                    .saturating_mul(per);
                (buildings.saturating_mul(24), buildings.saturating_mul(36))
            }
            Shape::FoliageCards { count, .. } => {
                let cards = (count as f32 as i64).max(0).unsigned_abs();
                (cards.saturating_mul(8), cards.saturating_mul(12))
            }
            Shape::Sphere {
                segments, rings, ..
            } => sphere(whole(segments), whole(rings)),
            Shape::Capsule { segments, .. } => {
                let s = whole(segments);
                let (cap_v, cap_i) = sphere(s, s / 2);
                (2 * cap_v + 2 * (s + 1), 2 * cap_i + 6 * s)
            }
        }
    }
}

/// A parameter's value: as given, else the generator's default.
fn value(spec: &GeneratorSpec, params: &BTreeMap<String, ParamValue>, name: &str) -> f64 {
    match params.get(name) {
        Some(ParamValue::Scalar(v)) => *v,
        _ => spec
            .params
            .iter()
            .find(|(p, _)| *p == name)
            .map_or(0.0, |(_, d)| *d),
    }
}

fn city(v: &dyn Fn(&str) -> f64) -> City {
    City {
        blocks_x: v("blocks_x"),
        blocks_z: v("blocks_z"),
        block_size: v("block_size"),
        street_width: v("street_width"),
        min_height: v("min_height"),
        max_height: v("max_height"),
        buildings_per_block: v("buildings_per_block"),
    }
}

impl Content {
    /// The content generator `name` with `params` (defaults filled in); `None` if unknown.
    pub fn new(name: &str, params: &BTreeMap<String, ParamValue>) -> Option<Content> {
        let spec = find(CONTENT_GENERATORS, name)?;
        let v = |n: &str| value(spec, params, n);
        Some(match name {
            "noise" => Content::Noise {
                frequency: v("frequency"),
                octaves: v("octaves"),
                amplitude: v("amplitude"),
            },
            "blue_noise" => Content::BlueNoise,
            "checker" => Content::Checker { cells: v("cells") },
            "constant" => Content::Constant { value: v("value") },
            "gradient" => Content::Gradient,
            "atlas" => Content::Atlas { cells: v("cells") },
            "coastline" => Content::Coastline {
                shore: v("shore"),
                frequency: v("frequency"),
            },
            "lights" => Content::Lights {
                count: v("count"),
                area: v("area"),
                min_radius: v("min_radius"),
                max_radius: v("max_radius"),
                intensity: v("intensity"),
            },
            "instances" => Content::Instances {
                count: v("count"),
                area: v("area"),
            },
            "city_lots" => Content::CityLots(city(&v)),
            _ => return None,
        })
    }

    /// Whether it makes per-instance transform rows (what mesh `instances` accept).
    pub fn makes_instance_rows(&self) -> bool {
        matches!(self, Content::Instances { .. } | Content::CityLots(_))
    }
}

impl Shape {
    /// The mesh generator `name` with `params` (defaults filled in); `None` if unknown.
    pub fn new(name: &str, params: &BTreeMap<String, ParamValue>) -> Option<Shape> {
        let spec = find(MESH_GENERATORS, name)?;
        let v = |n: &str| value(spec, params, n);
        Some(match name {
            "grid" => Shape::Grid {
                size: v("size"),
                divisions: v("divisions"),
            },
            "box" => Shape::Box { size: v("size") },
            "city_blocks" => Shape::CityBlocks(city(&v)),
            "terrain" => Shape::Terrain {
                size: v("size"),
                resolution: v("resolution"),
                height: v("height"),
                octaves: v("octaves"),
            },
            "water_plate" => Shape::WaterPlate {
                size: v("size"),
                divisions: v("divisions"),
                height: v("height"),
            },
            "foliage_cards" => Shape::FoliageCards {
                count: v("count"),
                area: v("area"),
                height: v("height"),
                width: v("width"),
            },
            "sphere" => Shape::Sphere {
                radius: v("radius"),
                segments: v("segments"),
                rings: v("rings"),
            },
            "capsule" => Shape::Capsule {
                radius: v("radius"),
                height: v("height"),
                segments: v("segments"),
            },
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_table_entry_has_a_typed_generator_with_its_defaults() {
        let none = BTreeMap::new();
        for spec in CONTENT_GENERATORS {
            assert!(Content::new(spec.name, &none).is_some(), "{}", spec.name);
        }
        for spec in MESH_GENERATORS {
            assert!(Shape::new(spec.name, &none).is_some(), "{}", spec.name);
        }
        assert_eq!(
            Content::new("coastline", &none),
            Some(Content::Coastline {
                shore: 0.6,
                frequency: 3.0
            })
        );
        let given = BTreeMap::from([("frequency".to_owned(), ParamValue::Scalar(9.0))]);
        assert_eq!(
            Content::new("coastline", &given),
            Some(Content::Coastline {
                shore: 0.6,
                frequency: 9.0
            })
        );
        assert!(Shape::new("noise", &none).is_none());
    }
}
