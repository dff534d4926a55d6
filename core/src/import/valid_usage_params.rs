//! The rules the registry states on every command's parameters (the specification's implicit
//! valid usage): a count that another parameter takes as its length, and that the registry
//! does not mark optional, must be greater than zero (`VUID-<command>-<count>-arraylength`;
//! zink sets its colour blend equations for no attachments,
//! `vkCmdSetColorBlendEquationEXT(attachmentCount = 0)`). The table is generated from vk.xml
//! (`provided::ARRAY_LENGTHS`). Also where a command's parameters are, for the rules that
//! read them.

use super::provided::ARRAY_LENGTHS;
use super::value::{Arg, Got};
use crate::capture::format::ValidUsageFinding;

/// The zero counts of call `name` (at `index`) that its command requires to be non-zero.
pub fn array_lengths(name: &str, index: u64, args: &Arg<'_>) -> Vec<ValidUsageFinding> {
    let Ok(at) = ARRAY_LENGTHS.binary_search_by(|(n, _)| (*n).cmp(name)) else {
        return Vec::new();
    };
    ARRAY_LENGTHS[at]
        .1
        .iter()
        .filter(|count| args.opt(count).and_then(|v| v.u64().ok()) == Some(0))
        .map(|count| ValidUsageFinding {
            vuid: format!("VUID-{name}-{count}-arraylength"),
            command: format!("{name} #{index}"),
            detail: format!("{count} is 0: the registry requires it greater than 0"),
        })
        .collect()
}

/// Where a command's arguments are: in the `*Info2` structure `info` names, or the call's own.
pub(super) fn holder<'a>(args: &Arg<'a>, info: Option<&str>) -> Got<Arg<'a>> {
    match info {
        Some(key) => args.get(key),
        None => Ok(*args),
    }
}
