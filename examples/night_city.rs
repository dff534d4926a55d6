//! Writes the Night City captures from their Rust description (`framelab_testkit::scenes::night_city`):
//!
//!     cargo run --example night_city
//!
//! Run it after changing the scene; a test fails while the committed JSON differs.

use std::process::ExitCode;

use framelab_testkit::scenes::night_city::{self, Variant};

fn main() -> ExitCode {
    for variant in Variant::ALL {
        let text = match night_city::json(variant) {
            Ok(text) => text,
            Err(e) => {
                eprintln!(
                    "{}: the scene does not fit the capture format: {e}",
                    variant.path()
                );
                return ExitCode::FAILURE;
            }
        };
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(variant.path());
        if let Err(e) = framelab_core::output::write_atomically(&path, text.as_bytes()) {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
        println!("wrote {}", variant.path());
    }
    ExitCode::SUCCESS
}
