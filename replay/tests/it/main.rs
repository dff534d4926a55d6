//! The one integration-test binary of `framelab-replay`: the shaders under `captures/` pass
//! naga without a GPU, the available adapter runs a compute round trip, and the frame cursor
//! holds the example frame at its passes.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod captures_wgsl;
mod cursor;
mod gpu_smoke;
