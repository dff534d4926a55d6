//! The `framelab` binary: the allocator choice and the entry point; the commands are in `cli`,
//! the MCP server (`framelab mcp`) in `mcp`.

mod cli;
mod mcp;

/// Analyses allocate and free several MiB per run. The system allocator hands that memory back
/// to the kernel between runs and faults it in again; mimalloc keeps it, which on a 2-core
/// machine halves the analysis of a 10k-pass frame (docs/performance.md). The `system-alloc`
/// feature keeps the system allocator.
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    quiet_device_select();
    cli::main()
}

/// Mesa's implicit device-select Vulkan layer connects to a Wayland or X display to find the
/// default GPU; without one it prints `error: XDG_RUNTIME_DIR is invalid or not set in the
/// environment.` to stderr, which users read as framelab's own error. framelab orders adapters
/// itself (best first, `--adapter` to choose), so the layer adds nothing: it is switched off
/// unless the user set `NODEVICE_SELECT` themselves.
fn quiet_device_select() {
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: this runs first in `main`, before any thread exists, so nothing else reads
        // or writes the environment at the same time.
        #[allow(unsafe_code)]
        unsafe {
            std::env::set_var("NODEVICE_SELECT", "1")
        };
    }
}
