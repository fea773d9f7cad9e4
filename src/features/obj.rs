//! OBJ files through `tobj`: each object and material of the file as a [`TriangleMesh`].

use std::path::Path;

use glam::{DVec2, DVec3};

use super::load::{LoadError, LoadErrorKind, build_mesh};
use crate::{MaterialId, TriangleMesh};

/// An OBJ file's meshes, as [`load_obj`] reads them.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct ObjScene {
    /// One mesh for each object (`o` or `g`) and material (`usemtl`) of the file, in the
    /// file's order.
    pub meshes: Vec<ObjMesh>,
    /// The materials' names, as the file's material library names them: a mesh's
    /// [`MaterialId`] is its place here. Empty where the file names no library, or it
    /// cannot be read (a warning a renderer may want: [`ObjScene::material_error`]).
    pub materials: Vec<String>,
    /// Why the material library named by the file could not be read, if it could not.
    pub material_error: Option<String>,
}

/// One object (or one material's part of one) of an OBJ file.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct ObjMesh {
    /// The object's name in the file.
    pub name: String,
    /// Its triangles (polygons triangulated as fans), with the file's vertex normals and
    /// texture coordinates where it gives them for every vertex, and its material's
    /// [`MaterialId`] (its place in [`ObjScene::materials`]; 0 for a face with no material,
    /// which [`ObjMesh::material`] tells apart).
    pub mesh: TriangleMesh,
    /// The material's name, as the file names it (`usemtl`), if the library has it.
    pub material: Option<String>,
}

/// The OBJ file at `path`, as meshes ([`ObjScene`]). Vertices shared by faces stay
/// shared; a vertex that has different normals or texture coordinates in different faces
/// is split (each mesh vertex has one of each).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// # let dir = std::env::temp_dir().join(format!("hitkit-doc-obj-{}", std::process::id()));
/// # std::fs::create_dir_all(&dir)?;
/// let path = dir.join("square.obj");
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")?;
/// let scene = hitkit::load::load_obj(&path)?;
/// assert_eq!(scene.meshes.len(), 1);
/// assert_eq!(scene.meshes[0].mesh.face_count(), 2); // the quad as two triangles
///
/// let err = hitkit::load::load_obj(dir.join("missing.obj")).unwrap_err();
/// assert!(err.to_string().starts_with("cannot read"));
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok(())
/// # }
/// ```
///
/// # Errors
/// A [`LoadError`] naming the file: it cannot be read, is not OBJ, holds no triangles, or a
/// mesh in it cannot be built (an index past its vertices, a NaN coordinate).
pub fn load_obj(path: impl AsRef<Path>) -> Result<ObjScene, LoadError> {
    let path = path.as_ref();
    // Opened first, so that a missing or unreadable file is refused with the operating
    // system's reason (tobj's error names none).
    std::fs::File::open(path).map_err(|e| LoadError::new(path, LoadErrorKind::Io(e)))?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(path, &options)
        .map_err(|e| LoadError::new(path, LoadErrorKind::Parse(e.to_string())))?;
    let (materials, material_error) = match materials {
        Ok(m) => (m.into_iter().map(|m| m.name).collect(), None),
        Err(e) => (Vec::new(), Some(e.to_string())),
    };
    let mut meshes = Vec::new();
    for model in models {
        let m = model.mesh;
        let faces: Vec<[u32; 3]> = m
            .indices
            .chunks_exact(3)
            .map(|f| [f[0], f[1], f[2]])
            .collect();
        if faces.is_empty() {
            continue;
        }
        let named = m.material_id.filter(|&i| i < materials.len());
        let mesh = build_mesh(
            path,
            &model.name,
            &triples(&m.positions),
            &faces,
            &triples(&m.normals),
            &pairs(&m.texcoords),
            MaterialId(named.map_or(0, |i| i as u32)),
        )?;
        meshes.push(ObjMesh {
            name: model.name,
            mesh,
            material: named.map(|i| materials[i].clone()),
        });
    }
    if meshes.is_empty() {
        return Err(LoadError::new(path, LoadErrorKind::Empty));
    }
    Ok(ObjScene {
        meshes,
        materials,
        material_error,
    })
}

/// Points from a flat list of coordinates, three by three, as formats store them.
fn triples(flat: &[f64]) -> Vec<DVec3> {
    flat.chunks_exact(3)
        .map(|p| DVec3::new(p[0], p[1], p[2]))
        .collect()
}

/// Pairs from a flat list, two by two.
fn pairs(flat: &[f64]) -> Vec<DVec2> {
    flat.chunks_exact(2)
        .map(|p| DVec2::new(p[0], p[1]))
        .collect()
}
