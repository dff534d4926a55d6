//! The one integration-test binary of `framelab-replay`: the shaders under `captures/` pass
//! naga without a GPU, and the available adapter runs a compute round trip.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod captures_wgsl;
mod gpu_smoke;
