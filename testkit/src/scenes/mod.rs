//! Captures framelab generates from Rust rather than keeping only as hand-edited JSON: frames
//! with variants that must share their passes (Night City by day and by night).

pub mod night_city;
