//! The second stage: every triangle primitive of every mesh, its accessors checked against
//! their buffers (sparse ones too) before they are read, as a [`GltfMesh`].

use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::sync::Arc;
use std::vec::Vec;

use glam::{DVec2, DVec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::{GltfMesh, LeftOut};
use crate::MaterialId;
use crate::features::load::{LoadError, LoadErrorKind, build_mesh};

/// What a primitive's texture coordinates may be stored as.
const UV_TYPES: [(Dimensions, DataType); 3] = [
    (Dimensions::Vec2, DataType::F32),
    (Dimensions::Vec2, DataType::U8),
    (Dimensions::Vec2, DataType::U16),
];

/// For each mesh of the file, for each of its primitives, its place among the meshes read.
pub(super) type Placed = Vec<Vec<Option<usize>>>;

/// Every primitive of triangles once, and `placed[m][p]`: where mesh `m`'s primitive `p`
/// is among them, if it is there. A primitive without a material is given `default`
/// (glTF's default material's place in the scene's materials).
pub(super) fn meshes(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    path: &Path,
    default: usize,
    left_out: &mut Vec<LeftOut>,
) -> Result<(Vec<GltfMesh>, Placed), LoadError> {
    let (mut meshes, mut placed) = (Vec::new(), Vec::new());
    for mesh in document.meshes() {
        let mesh_name = mesh
            .name()
            .map_or_else(|| format!("mesh {}", mesh.index()), ToString::to_string);
        let mut places = Vec::new();
        for primitive in mesh.primitives() {
            let name = format!("{mesh_name}#{}", primitive.index());
            if let Some(lines) = not_a_surface(primitive.mode()) {
                left_out.push(LeftOut::Primitive {
                    mesh: name,
                    mode: lines,
                });
                places.push(None);
                continue;
            }
            places.push(Some(meshes.len()));
            meshes.push(primitive_mesh(&primitive, name, buffers, path, default)?);
        }
        placed.push(places);
    }
    Ok((meshes, placed))
}

/// One primitive of triangles (a list, strip or fan) as a mesh.
fn primitive_mesh(
    primitive: &gltf::Primitive,
    name: String,
    buffers: &[gltf::buffer::Data],
    path: &Path,
    default: usize,
) -> Result<GltfMesh, LoadError> {
    let mode = primitive.mode();
    let malformed = |accessor: &gltf::Accessor, problem: String| {
        LoadError::new(
            path,
            LoadErrorKind::Malformed {
                mesh: name.clone(),
                accessor: accessor.index(),
                problem,
            },
        )
    };
    let check = |accessor: Option<gltf::Accessor>, allowed: &[(Dimensions, DataType)]| {
        accessor.map_or(Ok(()), |a| {
            check_accessor(&a, allowed, buffers).map_err(|problem| malformed(&a, problem))
        })
    };
    let position = primitive.get(&gltf::Semantic::Positions);
    check(position.clone(), &[(Dimensions::Vec3, DataType::F32)])?;
    check(
        primitive.get(&gltf::Semantic::Normals),
        &[(Dimensions::Vec3, DataType::F32)],
    )?;
    // Every set of texture coordinates, `TEXCOORD_0` up to the first the primitive lacks.
    let sets = (0..)
        .take_while(|&n| primitive.get(&gltf::Semantic::TexCoords(n)).is_some())
        .collect::<Vec<u32>>();
    for &n in &sets {
        check(primitive.get(&gltf::Semantic::TexCoords(n)), &UV_TYPES)?;
    }
    let index_types = [
        (Dimensions::Scalar, DataType::U8),
        (Dimensions::Scalar, DataType::U16),
        (Dimensions::Scalar, DataType::U32),
    ];
    check(primitive.indices(), &index_types)?;

    let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<DVec3> = reader
        .read_positions()
        .map(|p| p.map(|p| DVec3::from_array(p.map(f64::from))).collect())
        .unwrap_or_default();
    let normals: Vec<DVec3> = reader
        .read_normals()
        .map(|n| n.map(|n| DVec3::from_array(n.map(f64::from))).collect())
        .unwrap_or_default();
    let mut uv_sets: Vec<Vec<DVec2>> = sets
        .iter()
        .map(|&n| {
            reader
                .read_tex_coords(n)
                .map(|t| {
                    t.into_f32()
                        .map(|t| DVec2::from_array(t.map(f64::from)))
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    let uvs = if uv_sets.is_empty() {
        Vec::new()
    } else {
        uv_sets.remove(0)
    };
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    let faces = triangles(mode, &indices).ok_or_else(|| {
        let counted = primitive.indices().or(position).expect("checked by gltf");
        let problem = format!(
            "{} indices are not {} triangles",
            indices.len(),
            if mode == Mode::Triangles {
                "whole"
            } else {
                "any"
            }
        );
        malformed(&counted, problem)
    })?;
    let material = primitive.material().index().unwrap_or(default);
    let built = build_mesh(
        path,
        &name,
        &positions,
        &faces,
        &normals,
        &uvs,
        MaterialId(material as u32),
    )?;
    // A set of another length than the positions (which glTF forbids) is not read, as
    // `build_mesh` does with the first.
    uv_sets.retain(|set| set.len() == positions.len());
    Ok(GltfMesh::new(name, Arc::new(built), material, uv_sets))
}

/// Whether `accessor` can be read as one of `allowed` (its element's dimensions and
/// component type) from `buffers` without reaching past its buffer views or the buffers,
/// which the `gltf` crate's reader does not check (it panics, or reads nothing), sparse
/// storage included (its indices increasing and below the count, as the reader assumes:
/// it drops values whose index is out of order); the problem where it cannot.
pub(super) fn check_accessor(
    accessor: &gltf::Accessor,
    allowed: &[(Dimensions, DataType)],
    buffers: &[gltf::buffer::Data],
) -> Result<(), String> {
    let kind = (accessor.dimensions(), accessor.data_type());
    if !allowed.contains(&kind) {
        return Err(format!(
            "elements of {:?} {:?} are not what it holds here",
            kind.0, kind.1
        ));
    }
    let count = accessor.count();
    if count == 0 {
        return Err("it has no elements (glTF asks at least one)".into());
    }
    let element = accessor.size();
    let sparse = accessor.sparse();
    match accessor.view() {
        Some(view) => reach(&view, accessor.offset(), count, element, buffers)?,
        // Zeros, which the `gltf` crate's reader reads only under sparse values.
        None if sparse.is_none() => {
            return Err("it has no buffer view and no sparse values (all zeros): not read".into());
        }
        None => {}
    }
    let Some(sparse) = sparse else { return Ok(()) };
    let n = sparse.count();
    if n == 0 || n > count {
        return Err(format!(
            "{n} sparse values, for {count} elements (glTF asks 1 to the count)"
        ));
    }
    let indices = sparse.indices();
    let width = indices.index_type().size();
    let view = indices.view();
    reach(&view, indices.offset(), n, width, buffers)
        .map_err(|e| format!("sparse indices: {e}"))?;
    reach(
        &sparse.values().view(),
        sparse.values().offset(),
        n,
        element,
        buffers,
    )
    .map_err(|e| format!("sparse values: {e}"))?;
    // In range: checked just above.
    let bytes = &buffers[view.buffer().index()].0[view.offset() + indices.offset()..];
    let stride = view.stride().unwrap_or(width);
    let mut last = None;
    for k in 0..n {
        let at = &bytes[k * stride..k * stride + width];
        let index = match width {
            1 => usize::from(at[0]),
            2 => usize::from(u16::from_le_bytes([at[0], at[1]])),
            _ => u32::from_le_bytes([at[0], at[1], at[2], at[3]]) as usize,
        };
        if index >= count || last.is_some_and(|last| index <= last) {
            return Err(format!(
                "sparse index {index} (the {k}th) is {} (glTF asks them increasing, below {count})",
                if index >= count {
                    "past the elements"
                } else {
                    "out of order"
                }
            ));
        }
        last = Some(index);
    }
    Ok(())
}

/// Whether `count` elements of `element` bytes from byte `offset` of `view` lie inside it
/// and it inside its buffer.
fn reach(
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    element: usize,
    buffers: &[gltf::buffer::Data],
) -> Result<(), String> {
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "its stride, {stride} bytes, is shorter than its element, {element}"
        ));
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|r| r.checked_add(element))
        .and_then(|r| r.checked_add(offset));
    if end.is_none_or(|r| r > view.length()) {
        return Err(format!(
            "{count} elements from byte {offset} reach past its buffer view's {} bytes",
            view.length()
        ));
    }
    let data = buffers.get(view.buffer().index()).map_or(0, |d| d.0.len());
    if view
        .offset()
        .checked_add(view.length())
        .is_none_or(|end| end > data)
    {
        return Err(format!(
            "its buffer view (bytes {} to {}) reaches past buffer {}'s {data} bytes",
            view.offset(),
            view.offset().saturating_add(view.length()),
            view.buffer().index()
        ));
    }
    Ok(())
}

/// glTF's name for a mode of points or lines; `None` for the triangle modes.
fn not_a_surface(mode: Mode) -> Option<&'static str> {
    match mode {
        Mode::Points => Some("POINTS"),
        Mode::Lines => Some("LINES"),
        Mode::LineLoop => Some("LINE_LOOP"),
        Mode::LineStrip => Some("LINE_STRIP"),
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => None,
    }
}

/// The triangles of `indices` in `mode` (one of the triangle modes), each wound as glTF
/// says (a strip's every other triangle turned back); `None` where the indices are not
/// whole triangles (a list of triangles whose length is not a multiple of 3, or a strip
/// or a fan of fewer than 3).
fn triangles(mode: Mode, indices: &[u32]) -> Option<Vec<[u32; 3]>> {
    let n = indices.len();
    match mode {
        Mode::TriangleStrip if n >= 3 => Some(
            (0..n - 2)
                .map(|i| {
                    let (a, b, c) = (indices[i], indices[i + 1], indices[i + 2]);
                    if i.is_multiple_of(2) {
                        [a, b, c]
                    } else {
                        [b, a, c]
                    }
                })
                .collect(),
        ),
        Mode::TriangleFan if n >= 3 => Some(
            (1..n - 1)
                .map(|i| [indices[i], indices[i + 1], indices[0]])
                .collect(),
        ),
        Mode::Triangles if n.is_multiple_of(3) => Some(
            indices
                .chunks_exact(3)
                .map(|f| [f[0], f[1], f[2]])
                .collect(),
        ),
        _ => None,
    }
}
