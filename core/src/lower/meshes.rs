//! Meshes at wgpu level: generated meshes encoded into the capture's stream layout, or streams
//! and indices cut from the side file, with each attribute's format, offset and location.

use crate::plan::*;
use wgpu_types as wgpu;

use super::{LowerError, MeshError, generate};
use crate::capture::format as cf;
use crate::capture::model::*;

pub(super) fn lower_mesh(m: &MeshDesc) -> Result<MeshSpec, LowerError> {
    let err = |problem: MeshError| LowerError::Mesh {
        mesh: m.name.clone(),
        problem,
    };
    let instance_count = m.instance_count.unwrap_or(1);
    let stride = |s: &cf::VertexStream| {
        s.attributes
            .iter()
            .map(|a| u64::from(a.format.size()))
            .sum::<u64>()
    };
    let (stream_data, indices, vertex_count) = match &m.source {
        MeshSourceDesc::Generator(shape) => {
            let data = generate::mesh(shape);
            if data.positions.is_empty() {
                return Err(err(MeshError::NoVertices));
            }
            let streams = generate::encode_streams(
                &data,
                &m.streams,
                instance_count,
                shape.seed,
                m.instances.as_ref(),
            );
            let indices = m.index_format.map(|f| {
                let bytes: Vec<u8> = match f {
                    cf::IndexFormat::Uint16 => data
                        .indices
                        .iter()
                        .flat_map(|&i| (i as u16).to_le_bytes())
                        .collect(),
                    cf::IndexFormat::Uint32 => {
                        data.indices.iter().flat_map(|&i| i.to_le_bytes()).collect()
                    }
                };
                (bytes, f, data.indices.len() as u32)
            });
            if m.index_format == Some(cf::IndexFormat::Uint16) && data.positions.len() > 65536 {
                return Err(err(MeshError::TooManyFor16BitIndices {
                    vertices: data.positions.len(),
                }));
            }
            (streams, indices, data.positions.len() as u32)
        }
        MeshSourceDesc::File(path) => {
            let vertex_count = m.vertex_count.unwrap_or(0);
            // What the capture says the file holds: its streams, then its indices.
            let declared = m
                .streams
                .iter()
                .map(|s| {
                    let count = if s.step == cf::StepMode::Vertex {
                        u64::from(vertex_count)
                    } else {
                        u64::from(instance_count)
                    };
                    stride(s).saturating_mul(count)
                })
                .chain(m.index_format.map(|f| {
                    u64::from(f.size()).saturating_mul(u64::from(m.index_count.unwrap_or(0)))
                }))
                .fold(0u64, u64::saturating_add);
            let bytes =
                crate::files::read(path, crate::files::side_file(declared)).map_err(|e| {
                    err(match e {
                        crate::files::FileError::Io { path, error } => {
                            MeshError::Read { path, error }
                        }
                        e => MeshError::File(e),
                    })
                })?;
            let mut offset = 0usize;
            let mut streams = Vec::new();
            for s in &m.streams {
                let count = if s.step == cf::StepMode::Vertex {
                    u64::from(vertex_count)
                } else {
                    u64::from(instance_count)
                };
                let size = (stride(s) * count) as usize;
                streams.push(
                    bytes
                        .get(offset..offset + size)
                        .ok_or_else(|| {
                            err(MeshError::ShortFile {
                                path: path.clone(),
                                needed: offset + size,
                                len: bytes.len(),
                            })
                        })?
                        .to_vec(),
                );
                offset += size;
            }
            let indices = m.index_format.map(|f| {
                let n = m.index_count.unwrap_or(0);
                (bytes.get(offset..).unwrap_or_default().to_vec(), f, n)
            });
            (streams, indices, vertex_count)
        }
    };
    let streams = m
        .streams
        .iter()
        .zip(stream_data)
        .map(|(s, data)| {
            let mut offset = 0u64;
            let attributes = s
                .attributes
                .iter()
                .map(|a| {
                    let at = (vertex_format(a.format), offset, a.location);
                    offset += u64::from(a.format.size());
                    at
                })
                .collect();
            StreamSpec {
                slot: s.slot,
                data,
                stride: stride(s),
                step: if s.step == cf::StepMode::Vertex {
                    wgpu::VertexStepMode::Vertex
                } else {
                    wgpu::VertexStepMode::Instance
                },
                attributes,
            }
        })
        .collect();
    Ok(MeshSpec {
        name: m.name.clone(),
        streams,
        indices: indices.map(|(b, f, n)| {
            (
                b,
                if f == cf::IndexFormat::Uint16 {
                    wgpu::IndexFormat::Uint16
                } else {
                    wgpu::IndexFormat::Uint32
                },
                n,
            )
        }),
        vertex_count,
        instance_count,
    })
}

fn vertex_format(f: cf::VertexFormat) -> wgpu::VertexFormat {
    use cf::VertexFormat as V;
    match f {
        V::Snorm16x4 => wgpu::VertexFormat::Snorm16x4,
        V::Snorm16x2 => wgpu::VertexFormat::Snorm16x2,
        V::Unorm16x2 => wgpu::VertexFormat::Unorm16x2,
        V::Float16x2 => wgpu::VertexFormat::Float16x2,
        V::Float16x4 => wgpu::VertexFormat::Float16x4,
        // WebGPU fetches 10:10:10:2 only as unsigned normalised, so packed normals are stored
        // biased (n * 0.5 + 0.5) and shaders unpack them with `n * 2.0 - 1.0`.
        V::PackedSnorm10x3 => wgpu::VertexFormat::Unorm10_10_10_2,
        V::Unorm8x4 => wgpu::VertexFormat::Unorm8x4,
        V::Snorm8x4 => wgpu::VertexFormat::Snorm8x4,
        V::Uint8x4 => wgpu::VertexFormat::Uint8x4,
        V::Float32 => wgpu::VertexFormat::Float32,
        V::Float32x2 => wgpu::VertexFormat::Float32x2,
        V::Float32x3 => wgpu::VertexFormat::Float32x3,
        V::Float32x4 => wgpu::VertexFormat::Float32x4,
        V::Uint32 => wgpu::VertexFormat::Uint32,
        V::Uint32x2 => wgpu::VertexFormat::Uint32x2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(path: &std::path::Path) -> MeshDesc {
        MeshDesc {
            id: MeshId(0),
            name: "m".into(),
            source: MeshSourceDesc::File(path.to_owned()),
            streams: vec![cf::VertexStream {
                slot: 0,
                attributes: vec![cf::VertexAttribute {
                    semantic: "POSITION0".into(),
                    format: cf::VertexFormat::Snorm16x4,
                    location: 0,
                }],
                step: cf::StepMode::Vertex,
            }],
            index_format: None,
            vertex_count: Some(3),
            index_count: None,
            instance_count: None,
            instances: None,
        }
    }

    /// A mesh file is read up to the size its streams and indices need, never whole: a sparse
    /// file of 64 GiB is refused by its size.
    #[test]
    fn a_mesh_file_over_its_declared_size_is_refused_unread() {
        let dir = std::env::temp_dir().join(format!("framelab-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("mesh.bin");
        std::fs::write(&path, [0u8; 24]).unwrap();
        assert!(lower_mesh(&mesh(&path)).is_ok());
        std::fs::File::create(&path)
            .unwrap()
            .set_len(64 << 30)
            .unwrap();
        let e = lower_mesh(&mesh(&path)).unwrap_err();
        assert!(
            matches!(
                &e,
                LowerError::Mesh {
                    problem: MeshError::File(crate::files::FileError::TooLarge { limit: 24, .. }),
                    ..
                }
            ),
            "{e}"
        );
        assert!(
            e.to_string().contains("64.0 GiB is over the 24 B limit"),
            "{e}"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }
}
