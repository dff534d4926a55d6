//! Records the wgpu and naga versions this build links (from Cargo.lock) for `--version`: a
//! replay's timings depend on them, so bug reports should carry them.

fn main() {
    println!("cargo:rerun-if-changed=Cargo.lock");
    let lock = std::fs::read_to_string("Cargo.lock").unwrap_or_default();
    for (krate, var) in [
        ("wgpu", "FRAMELAB_WGPU_VERSION"),
        ("naga", "FRAMELAB_NAGA_VERSION"),
    ] {
        let needle = format!("name = \"{krate}\"\nversion = \"");
        let version = lock
            .find(&needle)
            .map(|i| &lock[i + needle.len()..])
            .and_then(|rest| rest.split('"').next())
            .unwrap_or("unknown");
        println!("cargo:rustc-env={var}={version}");
    }
}
