//! Generated captures stay what their generator writes: the committed Night City JSON is byte
//! for byte the output of `framelab::scenes::night_city`, so editing one without the other fails.

use framelab::scenes::night_city::{self, Variant};

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
    let err = serde_json::from_value::<framelab::capture::format::RawCapture>(value).unwrap_err();
    assert!(err.to_string().contains("signals"), "{err}");
}
