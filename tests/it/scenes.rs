//! Generated captures stay what their generator writes: the committed Night City JSON is byte
//! for byte the output of `framelab_testkit::scenes::night_city`, so editing one without the other fails.

use framelab_testkit::scenes::night_city::{self, Variant};

use crate::common::repo;

#[test]
fn night_city_captures_are_what_the_generator_writes() {
    for variant in Variant::ALL {
        let committed = std::fs::read_to_string(repo().join(variant.path())).unwrap();
        let generated = night_city::json(variant).unwrap();
        assert!(
            committed == generated,
            "{} is not what the generator writes; run `cargo run --example night_city` and commit",
            variant.path()
        );
    }
}

#[test]
fn the_generator_is_checked_by_the_format_types() {
    // A misspelt field in the generator is a deserialisation error, not a silent extra key.
    let mut value =
        serde_json::to_value(night_city::capture(Variant::MainStreetDay).unwrap()).unwrap();
    value["passes"][0]["signals"] = serde_json::json!(["typo"]);
    let err =
        serde_json::from_value::<framelab_core::capture::format::RawCapture>(value).unwrap_err();
    assert!(err.to_string().contains("signals"), "{err}");
}

/// The night capture is the same frame with different data, as NIGHT_CITY_PASSES.md says:
/// instance preparation with 38/3/38 groups, the moon instead of the sun, at least 1024 lights,
/// denser fog, and the same shader files as the day.
#[test]
fn the_night_capture_differs_from_the_day_in_data_only() {
    let day = serde_json::to_value(night_city::capture(Variant::MainStreetDay).unwrap()).unwrap();
    let night =
        serde_json::to_value(night_city::capture(Variant::RiverBankNight).unwrap()).unwrap();
    let pass = |c: &serde_json::Value, name: &str| {
        c["passes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .cloned()
            .unwrap_or_else(|| panic!("no pass {name}"))
    };
    let groups = |c: &serde_json::Value| -> Vec<serde_json::Value> {
        pass(c, "instance_prep")["dispatches"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d["groups"].clone())
            .collect()
    };
    assert_eq!(
        groups(&night),
        [
            serde_json::json!([38, 1, 1]),
            serde_json::json!([3, 1, 1]),
            serde_json::json!([38, 1, 1])
        ]
    );
    assert_eq!(groups(&day)[0], serde_json::json!([63, 1, 1]));
    // Moon: the sun is below the horizon, the moon above it.
    assert!(night["frame"]["sun_direction"][1].as_f64().unwrap() < 0.0);
    assert!(night["frame"]["moon_direction"][1].as_f64().unwrap() > 0.0);
    assert!(day["frame"]["sun_direction"][1].as_f64().unwrap() > 0.0);
    let lights = |c: &serde_json::Value| {
        pass(c, "light_buffer_update")["params"]["light_count"]
            .as_f64()
            .unwrap()
    };
    assert!(lights(&night) >= 1024.0 && lights(&day) < lights(&night));
    let fog = |c: &serde_json::Value| {
        pass(c, "volumetric_fog_local")["params"]["density"]
            .as_f64()
            .unwrap()
    };
    assert!(fog(&night) > fog(&day));
    let shaders = |c: &serde_json::Value| -> std::collections::BTreeSet<String> {
        c["passes"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|p| p["shader"]["file"].as_str().map(str::to_owned))
            .collect()
    };
    assert_eq!(shaders(&day), shaders(&night));
    assert!(pass(&day, "billboard_copies")["copies"].is_array());
    for dead in ["billboard_copies", "unknown_color_01"] {
        assert!(
            !night["passes"]
                .as_array()
                .unwrap()
                .iter()
                .any(|p| p["name"] == dead),
            "{dead} at night"
        );
    }
}
