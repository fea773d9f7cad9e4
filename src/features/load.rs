//! Scene files as hitkit's types: OBJ (through `tobj`, the `obj` feature) and glTF
//! (through `gltf`, the `gltf` feature). Both need `std` (files); the core stays `no_std`.

use std::fmt;
use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use crate::{GeometryError, MaterialId, TriangleMesh};

/// Why a scene file could not be loaded: which file, and what is wrong with it.
#[derive(Debug)]
pub struct LoadError {
    /// The file.
    pub file: PathBuf,
    /// What is wrong.
    pub kind: LoadErrorKind,
}

/// What is wrong with a scene file.
#[derive(Debug)]
#[non_exhaustive]
pub enum LoadErrorKind {
    /// It could not be read.
    Io(std::io::Error),
    /// It is not a file of its format (the parser's message).
    Parse(String),
    /// A mesh in it is not one hitkit can build (a NaN vertex, an index past the vertices).
    Geometry {
        /// Which mesh, as the file names it.
        mesh: String,
        /// Why.
        error: GeometryError,
    },
    /// Something the format allows that the loader does not read (named).
    Unsupported(String),
    /// An accessor a glTF primitive reads cannot be read as it says (past its buffer, a
    /// stride shorter than its element, no elements, a type the attribute cannot take),
    /// or names no accessor; or its indices are not whole triangles.
    Malformed {
        /// The primitive, as [`GltfMesh::name`](crate::load::GltfMesh::name) names one (or
        /// the node whose `EXT_mesh_gpu_instancing` reads the accessor).
        mesh: String,
        /// The accessor's number in the file.
        accessor: usize,
        /// What is wrong.
        problem: String,
    },
    /// It holds no triangle.
    Empty,
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let file = self.file.display();
        match &self.kind {
            LoadErrorKind::Io(e) => write!(f, "cannot read {file}: {e}"),
            LoadErrorKind::Parse(e) => write!(f, "{file} is not a valid file of its kind: {e}"),
            LoadErrorKind::Geometry { mesh, error } => {
                write!(f, "{file}: mesh \"{mesh}\" cannot be built: {error}")
            }
            LoadErrorKind::Unsupported(what) => write!(f, "{file}: {what} is not supported"),
            LoadErrorKind::Malformed {
                mesh,
                accessor,
                problem,
            } => write!(f, "{file}: mesh \"{mesh}\", accessor {accessor}: {problem}"),
            LoadErrorKind::Empty => write!(f, "{file} holds no triangles"),
        }
    }
}

impl std::error::Error for LoadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            LoadErrorKind::Io(e) => Some(e),
            LoadErrorKind::Geometry { error, .. } => Some(error),
            _ => None,
        }
    }
}

impl LoadError {
    pub(crate) fn new(file: &Path, kind: LoadErrorKind) -> Self {
        Self {
            file: file.to_path_buf(),
            kind,
        }
    }
}

/// A mesh from a file's arrays, with the normals and texture coordinates where there is one
/// for every vertex (and none otherwise), its error naming the file and the mesh.
pub(crate) fn build_mesh(
    file: &Path,
    name: &str,
    positions: &[DVec3],
    faces: &[[u32; 3]],
    normals: &[DVec3],
    uvs: &[DVec2],
    material: MaterialId,
) -> Result<TriangleMesh, LoadError> {
    let built = TriangleMesh::new(positions, faces)
        .and_then(|m| {
            if !normals.is_empty() && normals.len() == positions.len() {
                m.with_normals(normals)
            } else {
                Ok(m)
            }
        })
        .and_then(|m| {
            if !uvs.is_empty() && uvs.len() == positions.len() {
                m.with_uvs(uvs)
            } else {
                Ok(m)
            }
        });
    built.map(|m| m.with_material(material)).map_err(|error| {
        LoadError::new(
            file,
            LoadErrorKind::Geometry {
                mesh: name.into(),
                error,
            },
        )
    })
}
