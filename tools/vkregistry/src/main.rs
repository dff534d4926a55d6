//! `framelab-vkregistry`: generates `core/src/import/gfxr/tables.rs`, the tables that drive
//! framelab's decoder of GFXReconstruct captures, from the Vulkan registry and
//! GFXReconstruct's call ids. Generating them keeps the decoder to one generic reader instead
//! of a hand-written function per call and structure.
//!
//! `cargo run -p framelab-vkregistry -- --vk-xml vk.xml --api-call-id api_call_id.h --out tables.rs`
//!
//! With `--requires <provided.rs>` instead of the call ids and the tables, it writes what
//! provides each command of the registry (a core version or extensions), from which the
//! importer tells a call of an extension the stream never enabled, and the count parameters
//! each command requires to be non-zero (its `arraylength` valid usage).

mod call_ids;
mod collect;
mod decl;
mod emit;
mod mapping;
mod vkxml;

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

const USAGE: &str = "usage: framelab-vkregistry --vk-xml <vk.xml> --api-call-id <api_call_id.h> --out <tables.rs>\n       framelab-vkregistry --vk-xml <vk.xml> --requires <provided.rs>";

enum Args {
    Tables {
        vk_xml: PathBuf,
        api_call_id: PathBuf,
        out: PathBuf,
    },
    Requires {
        vk_xml: PathBuf,
        out: PathBuf,
    },
}

struct Tables {
    vk_xml: PathBuf,
    api_call_id: PathBuf,
    out: PathBuf,
}

fn args() -> Result<Args> {
    let (mut vk_xml, mut api_call_id, mut out, mut requires) = (None, None, None, None);
    let mut it = std::env::args_os().skip(1);
    while let Some(flag) = it.next() {
        let slot = match flag.to_str() {
            Some("--vk-xml") => &mut vk_xml,
            Some("--api-call-id") => &mut api_call_id,
            Some("--out") => &mut out,
            Some("--requires") => &mut requires,
            Some("-h" | "--help") => {
                println!("{USAGE}");
                std::process::exit(0);
            }
            _ => bail!("unexpected argument {flag:?}\n{USAGE}"),
        };
        *slot = Some(PathBuf::from(
            it.next()
                .with_context(|| format!("{flag:?} needs a path"))?,
        ));
    }
    match (vk_xml, api_call_id, out, requires) {
        (Some(vk_xml), Some(api_call_id), Some(out), None) => Ok(Args::Tables {
            vk_xml,
            api_call_id,
            out,
        }),
        (Some(vk_xml), None, None, Some(out)) => Ok(Args::Requires { vk_xml, out }),
        _ => bail!("{USAGE}"),
    }
}

fn main() -> Result<()> {
    let (vk_xml, api_call_id, out) = match args()? {
        Args::Tables {
            vk_xml,
            api_call_id,
            out,
        } => (vk_xml, api_call_id, out),
        Args::Requires { vk_xml, out } => {
            let registry = vkxml::read(&vk_xml)?;
            let text = emit::render_provided(&registry);
            std::fs::write(&out, &text).with_context(|| format!("writing {}", out.display()))?;
            eprintln!("{}: {} commands", out.display(), registry.provided.len());
            return Ok(());
        }
    };
    let args = Tables {
        vk_xml,
        api_call_id,
        out,
    };
    let registry = vkxml::read(&args.vk_xml)?;
    let calls = call_ids::read(&args.api_call_id)?;
    let tables = collect::collect(&registry, &calls)?;
    let text = emit::render(&tables, &registry.version)?;
    std::fs::write(&args.out, &text).with_context(|| format!("writing {}", args.out.display()))?;

    if !tables.unknown_calls.is_empty() {
        eprintln!(
            "skipped (not in vk.xml {}): {}",
            registry.version,
            tables.unknown_calls.join(", ")
        );
    }
    eprintln!(
        "{}: {} commands, {} structures, {} enums, {} sTypes, {} bytes",
        args.out.display(),
        tables.commands.len(),
        tables.structs.len(),
        tables.enums.len(),
        tables.stypes.len(),
        text.len()
    );
    Ok(())
}
