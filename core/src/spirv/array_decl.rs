//! A descriptor array a module declares (more than one descriptor at one set and binding),
//! as the split (`arrays`) and the specialisation of the functions that index it
//! (`index_params`) both see it, and how their refusals name it.

use std::collections::BTreeMap;

use rspirv::spirv::{StorageClass, Word};

use super::SpirvError;

/// Why a descriptor array cannot be split, as the error names the feature.
pub(super) fn refused(detail: String) -> SpirvError {
    SpirvError::Unsupported {
        feature: "descriptor array",
        detail,
    }
}

/// One array of more than one descriptor.
pub(super) struct Array {
    pub(super) set: u32,
    pub(super) binding: u32,
    pub(super) len: u32,
    pub(super) class: StorageClass,
    pub(super) element_ty: Word,
    pub(super) name: String,
}

/// The arrays, named for a message: `set 0 binding 1 (textures), ...`.
pub(super) fn arrays_named(arrays: &BTreeMap<Word, Array>) -> String {
    let names: Vec<String> = arrays
        .values()
        .map(|a| format!("set {} binding {} ({})", a.set, a.binding, a.name))
        .collect();
    names.join(", ")
}
