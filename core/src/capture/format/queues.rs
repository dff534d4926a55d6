//! Queues and the fences between them.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A command queue (`D3D12_COMMAND_LIST_TYPE`): graphics queues can do everything, compute
/// queues compute and copies, copy queues only copies.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Queue {
    pub name: String,
    #[serde(rename = "type")]
    pub queue_type: QueueType,
}

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum QueueType {
    Graphics,
    Compute,
    Copy,
}

/// A fence. A pass lists the fences it signals when it finishes and the fences it waits for
/// before it starts; this is how work on different queues is ordered.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Fence {
    pub name: String,
}

impl QueueType {
    /// The name reports and messages use (D3D12's spelling where it has one).
    pub fn name(self) -> &'static str {
        match self {
            QueueType::Graphics => "graphics",
            QueueType::Compute => "compute",
            QueueType::Copy => "copy",
        }
    }
}
