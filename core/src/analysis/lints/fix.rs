//! Machine-applicable fixes: the change to the frame a lint's advice amounts to, carried with
//! the finding (as a compiler's suggestion is) so that `what-if --fix CODE` can apply it and
//! `analyze` can say which findings are fixable.

use serde::Serialize;

use crate::capture::format::ResourceFlag;
use crate::capture::model::{Capture, PassId, ResourceId};

/// One change to the capture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Fix {
    /// Take a flag (a usage) off a resource.
    RemoveFlag {
        resource: ResourceId,
        flag: ResourceFlag,
    },
    /// Drop a pass from the frame.
    CullPass { pass: PassId },
    /// Drop the pass's recorded barrier at `index` (in the pass's own list).
    DropBarrier { pass: PassId, index: usize },
    /// Make two raster passes one render pass (`what-if --merge FIRST+SECOND`).
    MergePasses { first: PassId, second: PassId },
}

impl Fix {
    /// The change in words, with the capture's names.
    pub fn describe(&self, capture: &Capture) -> String {
        match *self {
            Fix::RemoveFlag { resource, flag } => format!(
                "remove {} from \"{}\"",
                flag.name(),
                capture.resource(resource).name
            ),
            Fix::CullPass { pass } => format!("cull pass \"{}\"", capture.pass(pass).name),
            Fix::DropBarrier { pass, index } => format!(
                "drop barrier {index} of pass \"{}\"",
                capture.pass(pass).name
            ),
            Fix::MergePasses { first, second } => format!(
                "merge passes \"{}\" and \"{}\" into one render pass",
                capture.pass(first).name,
                capture.pass(second).name
            ),
        }
    }
}
