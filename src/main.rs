//! The `framelab` binary: the allocator choice and the entry point; everything else is in `cli`.

mod cli;

/// Analyses allocate and free several MiB per run. The system allocator hands that memory back
/// to the kernel between runs and faults it in again; mimalloc keeps it, which on a 2-core
/// machine halves the analysis of a 10k-pass frame (README, Performance). The `system-alloc`
/// feature keeps the system allocator.
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    cli::main()
}
