//! `framelab mcp`: a Model Context Protocol server over stdio, so assistants and scripts ask
//! framelab about frames in the protocol they speak. Only protocol goes to stdout (messages
//! about the session go to stderr); closing stdin ends the server with exit 0. The tools are
//! in `tools`, the opened captures in `store`; both call the same core functions as the
//! commands, so each answer is the command line's `--json` for the same question; the
//! replays behind `texture`, `read_texels` and `timings` are in `replay`.

mod answers;
mod args;
mod framing;
mod imports;
mod replay;
mod store;
mod tools;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use rmcp::model::{Implementation, ServerCapabilities, ServerConfig};
use rmcp::{ServerHandler, ServiceExt, tool_handler};

pub use tools::Framelab;

#[tool_handler(router = self.router())]
impl ServerHandler for Framelab {
    fn get_info(&self) -> ServerConfig {
        ServerConfig::new(ServerCapabilities::builder().enable_tools().build())
            .with_server_info(Implementation::new("framelab", env!("CARGO_PKG_VERSION")))
            .with_instructions(
                "framelab analyses GPU frames. open_capture a capture file, then list its passes \
                 and resources, ask for one pass's details (bindings, barriers, lints, DAG \
                 neighbours), the whole analysis, a structural diff of two opened captures; replayed on \
                 this machine's GPU: a texture or its texel values as they stood after any pass, \
                 and per-pass timings.",
            )
    }
}

/// Serves until the client closes stdin.
pub fn run(roots: &[PathBuf]) -> anyhow::Result<ExitCode> {
    let roots = roots
        .iter()
        .map(|r| {
            r.canonicalize()
                .with_context(|| format!("--root {}", r.display()))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    runtime.block_on(async {
        let (to_engine, engine_in) = tokio::io::duplex(framing::MAX_LINE);
        let (engine_out, from_engine) = tokio::io::duplex(framing::MAX_LINE);
        let (lines, outgoing) = tokio::sync::mpsc::channel(64);
        let writer = tokio::spawn(framing::write_lines(tokio::io::stdout(), outgoing));
        let reader = tokio::spawn(framing::read_client(
            tokio::io::BufReader::new(tokio::io::stdin()),
            to_engine,
            lines.clone(),
        ));
        let relay = tokio::spawn(framing::read_engine(from_engine, lines));
        let service = Framelab::new(roots)
            .serve((engine_in, engine_out))
            .await
            .context("the MCP session did not start")?;
        service.waiting().await.context("the MCP session failed")?;
        // The engine has stopped: its output ends, then every line queued is written.
        reader.abort();
        relay
            .await
            .context("relay")?
            .context("reading the engine")?;
        writer.await.context("writer")?.context("writing stdout")?;
        let _ = std::fs::remove_dir_all(imports::scratch());
        Ok(ExitCode::SUCCESS)
    })
}
