//! Buffer layouts for the buffer viewer: a WGSL storage or uniform variable's type flattened
//! into typed fields at byte offsets (from naga's reflection of the validated module), and
//! wgpu's indirect-argument records. Decoding a row is plain byte reading, so a viewer can show
//! any buffer as rows of the type the shaders see.

use crate::shader::ValidatedShader;

/// How one element of a field is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    F32,
    F16,
    U32,
    I32,
    F64,
    U64,
    I64,
    Bool,
}

impl Scalar {
    pub fn bytes(self) -> u64 {
        match self {
            Scalar::F16 => 2,
            Scalar::F64 | Scalar::U64 | Scalar::I64 => 8,
            _ => 4,
        }
    }

    /// The value at the start of `b` (little-endian), as text; `None` past the end.
    pub fn read(self, b: &[u8]) -> Option<String> {
        let n = self.bytes() as usize;
        let b = b.get(..n)?;
        let mut w = [0u8; 8];
        w[..n].copy_from_slice(b);
        let u = u64::from_le_bytes(w);
        Some(match self {
            Scalar::F32 => format_float(f32::from_bits(u as u32)),
            Scalar::F16 => format_float(half_to_f32(u as u16)),
            Scalar::F64 => format_float(f64::from_bits(u)),
            Scalar::U32 | Scalar::U64 => u.to_string(),
            Scalar::I32 => (u as u32 as i32).to_string(),
            Scalar::I64 => (u as i64).to_string(),
            Scalar::Bool => (u as u32 != 0).to_string(),
        })
    }
}

/// The shortest text that reads back as the same value (in the value's own width), in
/// scientific notation when plain digits would be long.
fn format_float<F: Into<f64> + std::fmt::Display + std::fmt::LowerExp + Copy>(v: F) -> String {
    let x: f64 = v.into();
    if x.is_finite() && x != 0.0 && (x.abs() >= 1e7 || x.abs() < 1e-4) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// IEEE binary16 to f32, exactly.
fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f32::from(h & 0x3ff);
    sign * match exp {
        0 => frac * 2f32.powi(-24),
        31 if frac == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        _ => (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// One column of a row: a scalar or vector at a byte offset within the row.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    /// `member.member[i]` as WGSL would spell the access.
    pub name: String,
    pub offset: u64,
    pub scalar: Scalar,
    pub components: u32,
}

impl Field {
    /// The field's value in `row` (the bytes of one row), components separated by spaces.
    pub fn read(&self, row: &[u8]) -> Option<String> {
        let step = self.scalar.bytes();
        let parts: Option<Vec<String>> = (0..u64::from(self.components))
            .map(|c| {
                let at = usize::try_from(self.offset + c * step).ok()?;
                self.scalar.read(row.get(at..)?)
            })
            .collect();
        Some(parts?.join(" "))
    }
}

/// A buffer seen as consecutive rows of one type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BufferLayout {
    /// The row's type as WGSL names it (`Light`, `vec4<f32>`, `DrawIndexedIndirectArgs`).
    pub type_name: String,
    /// Bytes from one row to the next.
    pub stride: u64,
    pub fields: Vec<Field>,
}

/// Nested arrays inside a row are shown up to this many elements, rows up to this many fields,
/// so a type like `array<array<f32, 4096>, 64>` cannot make a table of millions of columns.
const MAX_ARRAY_ELEMENTS: u32 = 16;
const MAX_FIELDS: usize = 64;

impl BufferLayout {
    /// wgpu's `draw_indirect` arguments.
    pub fn draw_indirect() -> BufferLayout {
        Self::u32_record(
            "DrawIndirectArgs",
            &[
                "vertex_count",
                "instance_count",
                "first_vertex",
                "first_instance",
            ],
        )
    }

    /// wgpu's `draw_indexed_indirect` arguments (base_vertex is signed).
    pub fn draw_indexed_indirect() -> BufferLayout {
        let mut l = Self::u32_record(
            "DrawIndexedIndirectArgs",
            &[
                "index_count",
                "instance_count",
                "first_index",
                "base_vertex",
                "first_instance",
            ],
        );
        l.fields[3].scalar = Scalar::I32;
        l
    }

    /// wgpu's `dispatch_workgroups_indirect` arguments.
    pub fn dispatch_indirect() -> BufferLayout {
        Self::u32_record("DispatchIndirectArgs", &["x", "y", "z"])
    }

    fn u32_record(type_name: &str, names: &[&str]) -> BufferLayout {
        BufferLayout {
            type_name: type_name.to_owned(),
            stride: 4 * names.len() as u64,
            fields: names
                .iter()
                .zip(0u64..)
                .map(|(n, i)| Field {
                    name: (*n).to_owned(),
                    offset: 4 * i,
                    scalar: Scalar::U32,
                    components: 1,
                })
                .collect(),
        }
    }

    /// Whether the type is a plain array of one scalar or vector (no named members).
    pub fn is_plain(&self) -> bool {
        self.fields.len() == 1 && self.fields[0].name.is_empty()
    }
}

impl ValidatedShader {
    /// The row layout of global `variable`: an array's element type, or the variable's own
    /// type when it is not an array. `None` for missing variables and opaque types.
    pub fn buffer_layout(&self, variable: &str) -> Option<BufferLayout> {
        let (_, var) = self
            .module
            .global_variables
            .iter()
            .find(|(_, v)| v.name.as_deref() == Some(variable))?;
        let types = &self.module.types;
        let (row, stride) = match &types[var.ty].inner {
            naga::TypeInner::Array { base, stride, .. } => (*base, u64::from(*stride)),
            other => (var.ty, u64::from(other.size(self.module.to_ctx()))),
        };
        let mut fields = Vec::new();
        flatten(types, row, String::new(), 0, &mut fields);
        if fields.is_empty() {
            return None;
        }
        Some(BufferLayout {
            type_name: type_name(&self.module, row),
            stride: stride.max(1),
            fields,
        })
    }
}

fn type_name(module: &naga::Module, ty: naga::Handle<naga::Type>) -> String {
    use naga::common::wgsl::TypeContext;
    module.to_ctx().type_to_string(ty)
}

fn scalar(s: naga::Scalar) -> Option<Scalar> {
    use naga::ScalarKind as K;
    Some(match (s.kind, s.width) {
        (K::Float, 4) => Scalar::F32,
        (K::Float, 2) => Scalar::F16,
        (K::Float, 8) => Scalar::F64,
        (K::Uint, 4) => Scalar::U32,
        (K::Uint, 8) => Scalar::U64,
        (K::Sint, 4) => Scalar::I32,
        (K::Sint, 8) => Scalar::I64,
        (K::Bool, _) => Scalar::Bool,
        _ => return None,
    })
}

fn push(out: &mut Vec<Field>, name: String, offset: u64, s: naga::Scalar, components: u32) {
    if out.len() < MAX_FIELDS
        && let Some(scalar) = scalar(s)
    {
        out.push(Field {
            name,
            offset,
            scalar,
            components,
        });
    }
}

fn join(prefix: &str, member: &str) -> String {
    if prefix.is_empty() {
        member.to_owned()
    } else {
        format!("{prefix}.{member}")
    }
}

/// Appends the scalar and vector leaves of type `ty` placed at `offset`.
fn flatten(
    types: &naga::UniqueArena<naga::Type>,
    ty: naga::Handle<naga::Type>,
    name: String,
    offset: u64,
    out: &mut Vec<Field>,
) {
    if out.len() >= MAX_FIELDS {
        return;
    }
    match &types[ty].inner {
        naga::TypeInner::Scalar(s) | naga::TypeInner::Atomic(s) => push(out, name, offset, *s, 1),
        naga::TypeInner::Vector { size, scalar } => push(out, name, offset, *scalar, *size as u32),
        naga::TypeInner::Matrix {
            columns,
            rows,
            scalar,
        } => {
            // A column is a vecR aligned like one: vec3 columns take 16 bytes (f32).
            let width = u64::from(scalar.width);
            let r = *rows as u64;
            let align = if r == 2 { 2 * width } else { 4 * width };
            let column = (r * width).div_ceil(align) * align;
            for c in 0..*columns as u64 {
                push(
                    out,
                    format!("{name}[{c}]"),
                    offset + c * column,
                    *scalar,
                    r as u32,
                );
            }
        }
        naga::TypeInner::Struct { members, .. } => {
            for m in members {
                let member = m.name.clone().unwrap_or_else(|| "?".to_owned());
                flatten(
                    types,
                    m.ty,
                    join(&name, &member),
                    offset + u64::from(m.offset),
                    out,
                );
            }
        }
        naga::TypeInner::Array {
            base,
            size: naga::ArraySize::Constant(n),
            stride,
        } => {
            for i in 0..n.get().min(MAX_ARRAY_ELEMENTS) {
                flatten(
                    types,
                    *base,
                    format!("{name}[{i}]"),
                    offset + u64::from(i) * u64::from(*stride),
                    out,
                );
            }
        }
        // Runtime-sized tails, pointers and opaque types have no fixed place in a row.
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shader::validate_wgsl;

    #[test]
    fn struct_arrays_flatten_to_fields_at_their_offsets() {
        let src = "
            struct Light { position: vec3<f32>, radius: f32, color: vec2<i32>, kind: u32, m: mat3x3<f32> }
            @group(0) @binding(0) var<storage, read> lights: array<Light>;
            @group(0) @binding(1) var<storage, read_write> counts: array<atomic<i32>>;
            @compute @workgroup_size(1) fn main() { let l = lights[0]; atomicAdd(&counts[0], 1); }
        ";
        let s = validate_wgsl("l.wgsl", src).unwrap();
        let l = s.buffer_layout("lights").unwrap();
        assert_eq!(l.type_name, "Light");
        assert_eq!(l.stride, 80);
        let names: Vec<(&str, u64, u32)> = l
            .fields
            .iter()
            .map(|f| (f.name.as_str(), f.offset, f.components))
            .collect();
        assert_eq!(
            names,
            [
                ("position", 0, 3),
                ("radius", 12, 1),
                ("color", 16, 2),
                ("kind", 24, 1),
                ("m[0]", 32, 3),
                ("m[1]", 48, 3),
                ("m[2]", 64, 3),
            ]
        );
        assert_eq!(l.fields[2].scalar, Scalar::I32);
        let c = s.buffer_layout("counts").unwrap();
        assert!(c.is_plain());
        assert_eq!((c.stride, c.fields[0].scalar), (4, Scalar::I32));
        assert!(s.buffer_layout("missing").is_none());
    }

    #[test]
    fn rows_decode_in_the_fields_types() {
        let l = BufferLayout::draw_indexed_indirect();
        let mut row = Vec::new();
        for v in [36u32, 2, 6, (-3i32) as u32, 1] {
            row.extend_from_slice(&v.to_le_bytes());
        }
        let values: Vec<String> = l.fields.iter().filter_map(|f| f.read(&row)).collect();
        assert_eq!(values, ["36", "2", "6", "-3", "1"]);
        let v = Field {
            name: "v".into(),
            offset: 0,
            scalar: Scalar::F16,
            components: 2,
        };
        // 1.0 and -2.5 in binary16.
        assert_eq!(v.read(&[0x00, 0x3c, 0x00, 0xc1]).as_deref(), Some("1 -2.5"));
        assert_eq!(v.read(&[0x00, 0x3c]), None, "a short row has no value");
        // f32 values print as f32 (not widened to f64 digits).
        assert_eq!(
            Scalar::F32.read(&0.1f32.to_bits().to_le_bytes()).unwrap(),
            "0.1"
        );
        assert_eq!(
            Scalar::F32.read(&3e-9f32.to_bits().to_le_bytes()).unwrap(),
            "3e-9"
        );
    }
}
