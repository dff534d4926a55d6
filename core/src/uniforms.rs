//! Uniform packing by reflection: a WGSL uniform struct's members are found by name in the naga
//! module, with the offsets naga's layout rules gave them, and values are written there in the
//! member's scalar type. Captures name parameters, never offsets, so a shader can reorder or add
//! members without the capture changing.

use naga::{Module, ScalarKind, TypeInner};

/// Per-pass (or per-draw) parameters by uniform struct member name.
pub type Params = std::collections::BTreeMap<String, Vec<f64>>;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UniformError {
    #[error("`{variable}` is not a uniform struct in the shader")]
    NotAStruct { variable: String },
    #[error("`{variable}` has no member `{member}`{}", if members.is_empty() { String::new() } else { format!(" (members: {})", members.join(", ")) })]
    UnknownMember {
        variable: String,
        member: String,
        members: Vec<String>,
    },
    #[error("`{variable}.{member}` is not given a value")]
    Missing { variable: String, member: String },
    #[error("`{variable}.{member}` takes {expected} value(s), got {got}")]
    Count {
        variable: String,
        member: String,
        expected: usize,
        got: usize,
    },
    #[error("`{variable}.{member}` has a type framelab cannot fill ({ty})")]
    Unsupported {
        variable: String,
        member: String,
        ty: String,
    },
}

/// Component count and scalar kind of a member type, for scalars, vectors and matrices.
fn shape(module: &Module, inner: &TypeInner) -> Option<(usize, ScalarKind, usize)> {
    match inner {
        TypeInner::Scalar(s) => Some((1, s.kind, 1)),
        TypeInner::Vector { size, scalar } => Some((*size as usize, scalar.kind, *size as usize)),
        TypeInner::Matrix {
            columns,
            rows,
            scalar,
        } => {
            // Columns are padded to vec4 when rows == 3 (std140-like layout in WGSL).
            let stride = if *rows as usize == 3 {
                4
            } else {
                *rows as usize
            };
            Some((*columns as usize * *rows as usize, scalar.kind, stride))
        }
        TypeInner::Array {
            base,
            size: naga::ArraySize::Constant(n),
            ..
        } => {
            let (count, kind, _) = shape(module, &module.types[*base].inner)?;
            (count == 1).then_some((n.get() as usize, kind, 1))
        }
        _ => None,
    }
}

/// The byte size and members of a uniform variable named `variable`, if the module has one.
pub fn uniform_struct(module: &Module, variable: &str) -> Option<(u32, Vec<String>)> {
    let (_, var) = module
        .global_variables
        .iter()
        .find(|(_, v)| v.name.as_deref() == Some(variable))?;
    match &module.types[var.ty].inner {
        TypeInner::Struct { members, span } => Some((
            *span,
            members.iter().filter_map(|m| m.name.clone()).collect(),
        )),
        _ => None,
    }
}

/// Packs `values` into the uniform struct `variable`. With `strict`, a value for a member the
/// struct lacks is an error (capture parameters); without, extra values are ignored (the frame
/// constants offer more than a shader uses).
pub fn pack(
    module: &Module,
    variable: &str,
    values: &Params,
    strict: bool,
) -> Result<Vec<u8>, UniformError> {
    let not_struct = || UniformError::NotAStruct {
        variable: variable.to_owned(),
    };
    let (_, var) = module
        .global_variables
        .iter()
        .find(|(_, v)| v.name.as_deref() == Some(variable))
        .ok_or_else(not_struct)?;
    let TypeInner::Struct { members, span } = &module.types[var.ty].inner else {
        return Err(not_struct());
    };
    let names: Vec<String> = members.iter().filter_map(|m| m.name.clone()).collect();
    if strict && let Some(extra) = values.keys().find(|k| !names.contains(k)) {
        return Err(UniformError::UnknownMember {
            variable: variable.to_owned(),
            member: extra.clone(),
            members: names,
        });
    }
    let mut bytes = vec![0u8; *span as usize];
    for m in members {
        let name = m.name.clone().unwrap_or_default();
        let inner = &module.types[m.ty].inner;
        let Some((count, kind, column)) = shape(module, inner) else {
            return Err(UniformError::Unsupported {
                variable: variable.to_owned(),
                member: name,
                ty: format!("{inner:?}"),
            });
        };
        let Some(v) = values.get(&name) else {
            return Err(UniformError::Missing {
                variable: variable.to_owned(),
                member: name,
            });
        };
        if v.len() != count {
            return Err(UniformError::Count {
                variable: variable.to_owned(),
                member: name,
                expected: count,
                got: v.len(),
            });
        }
        let element_stride = match inner {
            TypeInner::Array { stride, .. } => *stride as usize,
            _ => 4,
        };
        for (i, x) in v.iter().enumerate() {
            let offset = match inner {
                TypeInner::Matrix { rows: r, .. } => {
                    let r = *r as usize;
                    let (col, row) = (i / r, i % r);
                    m.offset as usize + (col * column + row) * 4
                }
                TypeInner::Array { .. } => m.offset as usize + i * element_stride,
                _ => m.offset as usize + i * 4,
            };
            let word = match kind {
                ScalarKind::Float => (*x as f32).to_le_bytes(),
                ScalarKind::Sint => (*x as i32).to_le_bytes(),
                ScalarKind::Uint => (*x as u32).to_le_bytes(),
                ScalarKind::Bool => u32::from(*x != 0.0).to_le_bytes(),
                _ => {
                    return Err(UniformError::Unsupported {
                        variable: variable.to_owned(),
                        member: name,
                        ty: format!("{kind:?}"),
                    });
                }
            };
            if let Some(slot) = bytes.get_mut(offset..offset + 4) {
                slot.copy_from_slice(&word);
            }
        }
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn module(src: &str) -> Module {
        naga::front::wgsl::parse_str(src).unwrap()
    }

    #[test]
    fn members_are_packed_at_their_offsets() {
        let m = module(
            "struct P { a: f32, b: vec3<f32>, c: u32, m: mat4x4<f32> }
             @group(0) @binding(0) var<uniform> params: P;",
        );
        let mut values = Params::new();
        values.insert("a".into(), vec![1.5]);
        values.insert("b".into(), vec![1.0, 2.0, 3.0]);
        values.insert("c".into(), vec![7.0]);
        values.insert("m".into(), (0..16).map(f64::from).collect());
        let bytes = pack(&m, "params", &values, true).unwrap();
        let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        assert_eq!(f(0), 1.5);
        // vec3 aligns to 16.
        assert_eq!((f(16), f(20), f(24)), (1.0, 2.0, 3.0));
        assert_eq!(u32::from_le_bytes(bytes[28..32].try_into().unwrap()), 7);
        // mat4x4 at 32, column-major.
        assert_eq!((f(32), f(36), f(48)), (0.0, 1.0, 4.0));
        assert_eq!(bytes.len(), 96);
    }

    #[test]
    fn names_are_checked() {
        let m = module("struct P { exposure: f32 } @group(0) @binding(0) var<uniform> params: P;");
        let mut values = Params::new();
        values.insert("exposur".into(), vec![1.0]);
        assert!(matches!(
            pack(&m, "params", &values, true),
            Err(UniformError::UnknownMember { .. })
        ));
        assert!(matches!(
            pack(&m, "params", &Params::new(), false),
            Err(UniformError::Missing { .. })
        ));
        values.insert("exposure".into(), vec![1.0, 2.0]);
        assert!(matches!(
            pack(&m, "params", &values, false),
            Err(UniformError::Count { .. })
        ));
    }
}
