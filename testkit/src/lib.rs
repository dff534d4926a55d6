//! Frames for framelab's own tests, benchmarks and examples, kept out of the library API: the
//! Night City captures generated from Rust (`scenes`) and seeded synthetic frames and capture
//! JSON of any size (`synthetic`).

pub mod scenes;
pub mod synthetic;
