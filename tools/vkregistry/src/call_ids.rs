//! Reads GFXReconstruct's `format/api_call_id.h`: the id each captured call is written
//! under. The ids are assigned by GFXReconstruct, not by the registry, so this header is the
//! only source for them.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};

/// The Vulkan calls, `(id, "vkName")`, in the header's order.
pub fn read(path: &Path) -> Result<Vec<(u32, String)>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut families = HashMap::new();
    let mut calls = Vec::new();
    for line in text.lines() {
        // Whitespace-free, the entries read `ApiFamily_Vulkan=1,` and
        // `ApiCall_vkCreateInstance=MakeApiCallId(ApiFamily_Vulkan,0x1000),`.
        let line: String = line
            .split("//")
            .next()
            .unwrap_or("")
            .split_whitespace()
            .collect();
        let Some((lhs, rhs)) = line.trim_end_matches(',').split_once('=') else {
            continue;
        };
        if let Some(family) = lhs.strip_prefix("ApiFamily_") {
            let number: u16 = rhs
                .parse()
                .with_context(|| format!("family {family}: {rhs:?}"))?;
            families.insert(family.to_owned(), number);
        } else if let Some(call) = lhs.strip_prefix("ApiCall_")
            && call.starts_with("vk")
        {
            let args = rhs
                .strip_prefix("MakeApiCallId(")
                .and_then(|r| r.strip_suffix(')'))
                .ok_or_else(|| anyhow!("{call}: unexpected id {rhs:?}"))?;
            let (family, number) = args
                .split_once(',')
                .ok_or_else(|| anyhow!("{call}: {rhs:?}"))?;
            let family = family
                .strip_prefix("ApiFamily_")
                .and_then(|f| families.get(f))
                .copied();
            let Some(family) = family else {
                bail!("{call}: unknown family in {rhs:?}")
            };
            let number = number
                .strip_prefix("0x")
                .ok_or_else(|| anyhow!("{call}: {rhs:?}"))?;
            let number =
                u16::from_str_radix(number, 16).with_context(|| format!("{call}: {rhs:?}"))?;
            calls.push((
                (u32::from(family) << 16) | u32::from(number),
                call.to_owned(),
            ));
        }
    }
    if calls.is_empty() {
        bail!("{}: no ApiCall_vk* ids", path.display());
    }
    Ok(calls)
}
