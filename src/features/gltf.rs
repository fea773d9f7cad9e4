//! glTF 2.0 files through `gltf`: every mesh primitive once, every node that holds a mesh
//! as instances of it under the node's composed transform, and the materials' alpha modes
//! and emission.

use std::path::Path;
use std::string::{String, ToString};
use std::sync::Arc;
use std::vec::Vec;

use glam::{DAffine3, DMat4, DVec3};

use super::load::{LoadError, LoadErrorKind, build_mesh};
use crate::light::Emitters;
use crate::{
    Affine, GeometryError, LightTree, MaterialId, Quad, Transformed, Triangle, TriangleMesh,
};

/// A glTF file's meshes, instances and materials, as [`load_gltf`] reads them.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GltfScene {
    /// Every triangle primitive of every mesh, once, in the file's order.
    pub meshes: Vec<GltfMesh>,
    /// Every primitive of every node of the scene that holds a mesh (the default scene,
    /// else the first), under the node's transform composed with its parents'.
    pub instances: Vec<GltfInstance>,
    /// The materials, in the file's order: a mesh's [`MaterialId`] is its place here.
    pub materials: Vec<GltfMaterial>,
}

/// One primitive of a glTF mesh.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GltfMesh {
    /// The mesh's name (or `mesh N`), and the primitive's number after `#`.
    pub name: String,
    /// Its triangles in the mesh's own space, with the file's normals and first texture
    /// coordinates where it has them, and its material's id (0 where it has none, which
    /// `material` tells apart).
    pub mesh: Arc<TriangleMesh>,
    /// Its material's place in [`GltfScene::materials`], if it has one.
    pub material: Option<usize>,
}

/// A node's use of a mesh primitive.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GltfInstance {
    /// The node's name (or `node N`).
    pub node: String,
    /// The primitive's place in [`GltfScene::meshes`].
    pub mesh: usize,
    /// The node's transform, composed with its parents', object to world.
    pub transform: DAffine3,
}

/// How a material's alpha is read (glTF's `alphaMode`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Alpha {
    /// Alpha is ignored: the surface is opaque.
    Opaque,
    /// Where alpha is below `cutoff`, the surface is not there: a cut-out, for a
    /// [`Filtered`](crate::Filtered) mesh.
    Mask {
        /// The cutoff (0.5 where the file does not say).
        cutoff: f64,
    },
    /// Alpha blends the surface with what lies behind.
    Blend,
}

/// A glTF material: what a renderer needs to tell cut-outs and lamps apart; textures and
/// the rest are in the file, by the same index.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct GltfMaterial {
    /// Its name (or `material N`).
    pub name: String,
    /// The base colour factor, linear RGBA.
    pub base_color: [f64; 4],
    /// Its alpha mode.
    pub alpha: Alpha,
    /// The emitted radiance factor, linear RGB (zero for a surface that emits nothing).
    pub emissive: DVec3,
    /// Whether both sides are seen (and, for a lamp, emit).
    pub double_sided: bool,
}

impl GltfScene {
    /// Every instance as a [`Transformed`] of its shared mesh, its instance id its place
    /// in [`GltfScene::instances`] (so that a hit's `instance` names it, and its
    /// `primitive` the face): for a [`Bvh`](crate::Bvh).
    ///
    /// # Errors
    /// As [`Transformed::affine`]: a node whose transform is singular (a zero scale) or
    /// not finite.
    pub fn transformed(
        &self,
    ) -> Result<Vec<Transformed<Arc<TriangleMesh>, Affine>>, GeometryError> {
        self.instances
            .iter()
            .zip(0u32..)
            .map(|(instance, id)| {
                Transformed::affine(self.meshes[instance.mesh].mesh.clone(), instance.transform)
                    .map(|t| t.with_instance_id(id))
            })
            .collect()
    }

    /// The faces of every instance whose material emits, in world space, as the lights
    /// of a [`LightTree`]: each face of power `PI * luminance * area` (the flux of a
    /// diffuse emitter of that radiance, `luminance` the Rec. 709 weighting of the
    /// emissive factor; twice that where the material is double-sided), facing the mesh's
    /// front side (the one its corners wind counterclockwise around in the mesh's own
    /// space, under a mirroring node too, as glTF says and [`Transformed`] reports it), or
    /// both. `None` where nothing emits.
    ///
    /// # Errors
    /// As [`LightTree::new`].
    pub fn lights(&self) -> Result<Option<LightTree<Quad<Triangle>>>, GeometryError> {
        let mut emitters = Emitters::default();
        for instance in &self.instances {
            let mesh = &self.meshes[instance.mesh];
            let Some(material) = mesh.material.map(|m| &self.materials[m]) else {
                continue;
            };
            let radiance = material.emissive.dot(DVec3::new(0.2126, 0.7152, 0.0722));
            if radiance.is_nan() || radiance <= 0.0 {
                continue;
            }
            // glTF: a node of negative determinant keeps the mesh's front side, which its
            // corners then wind around clockwise; swapping two turns them back.
            let mirrored = instance.transform.matrix3.determinant() < 0.0;
            for face in mesh.mesh.faces() {
                let [a, b, c] = face
                    .corners()
                    .map(|p| instance.transform.transform_point3(p));
                let corners = if mirrored { [a, c, b] } else { [a, b, c] };
                emitters.push(
                    corners,
                    radiance,
                    material.double_sided,
                    mesh.mesh.material(),
                );
            }
        }
        if emitters.is_empty() {
            return Ok(None);
        }
        emitters.tree().map(Some)
    }
}

/// The glTF file (`.gltf` with its buffers beside it or inline, or `.glb`) at `path`, as
/// meshes, instances and materials ([`GltfScene`]). Images are not read: a renderer that
/// textures its surfaces reads them by the file's indices.
///
/// # Errors
/// A [`LoadError`] naming the file: it cannot be read, is not glTF or its buffers cannot
/// be, a primitive is not made of triangles (points, lines and strips are
/// [`LoadErrorKind::Unsupported`]), it holds no triangles, or a mesh cannot be built.
pub fn load_gltf(path: impl AsRef<Path>) -> Result<GltfScene, LoadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| LoadError::new(path, LoadErrorKind::Io(e)))?;
    let parse = |e: gltf::Error| LoadError::new(path, LoadErrorKind::Parse(e.to_string()));
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(&bytes).map_err(parse)?;
    let buffers = gltf::import_buffers(&document, path.parent(), blob).map_err(parse)?;

    let materials = document
        .materials()
        .filter_map(|m| m.index().map(|i| (i, m)))
        .map(|(i, m)| {
            let color = m.pbr_metallic_roughness().base_color_factor();
            let emissive = m.emissive_factor();
            GltfMaterial {
                name: m
                    .name()
                    .map_or_else(|| format!("material {i}"), ToString::to_string),
                base_color: color.map(f64::from),
                alpha: match m.alpha_mode() {
                    gltf::material::AlphaMode::Opaque => Alpha::Opaque,
                    gltf::material::AlphaMode::Mask => Alpha::Mask {
                        cutoff: f64::from(m.alpha_cutoff().unwrap_or(0.5)),
                    },
                    gltf::material::AlphaMode::Blend => Alpha::Blend,
                },
                emissive: DVec3::from_array(emissive.map(f64::from))
                    * f64::from(m.emissive_strength().unwrap_or(1.0)),
                double_sided: m.double_sided(),
            }
        })
        .collect::<Vec<_>>();

    // Every primitive once; `first[m]` is where mesh `m`'s primitives start.
    let (mut meshes, mut first) = (Vec::new(), Vec::new());
    for mesh in document.meshes() {
        first.push(meshes.len());
        let mesh_name = mesh
            .name()
            .map_or_else(|| format!("mesh {}", mesh.index()), ToString::to_string);
        for primitive in mesh.primitives() {
            let name = format!("{mesh_name}#{}", primitive.index());
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                let what = format!("primitive \"{name}\" of mode {:?}", primitive.mode());
                return Err(LoadError::new(path, LoadErrorKind::Unsupported(what)));
            }
            let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let positions: Vec<DVec3> = reader
                .read_positions()
                .map(|p| p.map(|p| DVec3::from_array(p.map(f64::from))).collect())
                .unwrap_or_default();
            let normals: Vec<DVec3> = reader
                .read_normals()
                .map(|n| n.map(|n| DVec3::from_array(n.map(f64::from))).collect())
                .unwrap_or_default();
            let uvs: Vec<glam::DVec2> = reader
                .read_tex_coords(0)
                .map(|t| {
                    t.into_f32()
                        .map(|t| glam::DVec2::from_array(t.map(f64::from)))
                        .collect()
                })
                .unwrap_or_default();
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            let faces: Vec<[u32; 3]> = indices
                .chunks_exact(3)
                .map(|f| [f[0], f[1], f[2]])
                .collect();
            let material = primitive.material().index();
            let built = build_mesh(
                path,
                &name,
                &positions,
                &faces,
                &normals,
                &uvs,
                MaterialId(material.map_or(0, |m| m as u32)),
            )?;
            meshes.push(GltfMesh {
                name,
                mesh: Arc::new(built),
                material,
            });
        }
    }

    let mut instances = Vec::new();
    if let Some(scene) = document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        // Depth first, in the file's order; a node met twice (a cycle, or two parents,
        // which glTF forbids) is an error rather than a walk without end.
        let mut stack: Vec<(gltf::Node, DMat4)> =
            scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
        stack.reverse();
        let mut seen = vec![false; document.nodes().count()];
        while let Some((node, parent)) = stack.pop() {
            if core::mem::replace(&mut seen[node.index()], true) {
                let what = format!(
                    "node {} is reached twice in the scene's hierarchy",
                    node.index()
                );
                return Err(LoadError::new(path, LoadErrorKind::Parse(what)));
            }
            let local =
                DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
            let world = parent * local;
            if let Some(mesh) = node.mesh() {
                let transform = DAffine3::from_mat4(world);
                let name = node
                    .name()
                    .map_or_else(|| format!("node {}", node.index()), ToString::to_string);
                for primitive in mesh.primitives() {
                    instances.push(GltfInstance {
                        node: name.clone(),
                        mesh: first[mesh.index()] + primitive.index(),
                        transform,
                    });
                }
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
        }
    }
    if meshes.iter().all(|m| m.mesh.face_count() == 0) {
        return Err(LoadError::new(path, LoadErrorKind::Empty));
    }
    Ok(GltfScene {
        meshes,
        instances,
        materials,
    })
}
