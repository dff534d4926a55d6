//! The typed ids validation gives every named thing of a capture: an index into the
//! validated capture's list of that kind. Apart from the model so that what the model holds
//! (the Vulkan section among it) can name resources without importing the model.

use serde::Serialize;

macro_rules! id_type {
    ($($name:ident),*) => {$(
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
        pub struct $name(pub u32);
        impl $name {
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }
    )*};
}
id_type!(
    ResourceId,
    PassId,
    HeapId,
    QueueId,
    MeshId,
    SamplerId,
    FenceId,
    DescriptorHeapId
);
