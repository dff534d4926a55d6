//! The named procedural generators a capture may use for initial contents and meshes, with the
//! parameters each accepts. Validation checks names and parameters against this table so a
//! misspelt generator or parameter is reported with a suggestion before anything runs.

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
