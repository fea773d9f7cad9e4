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
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

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
    /// What the file holds that the scene leaves out, and why (the file loads without it).
    pub left_out: Vec<LeftOut>,
    /// The cameras of the scene's nodes, in the order the walk meets them.
    pub cameras: Vec<GltfCamera>,
}

/// A camera of a glTF scene: where its node puts it (glTF's cameras look along their
/// node's `-z`, with `+y` up) and how it projects.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct GltfCamera {
    /// The node's name (or `node N`).
    pub node: String,
    /// The node's transform composed with its parents', camera to world.
    pub transform: DAffine3,
    /// How it projects.
    pub projection: Projection,
}

impl GltfCamera {
    /// Where the camera is.
    #[must_use]
    pub fn position(&self) -> DVec3 {
        self.transform.translation
    }

    /// The unit direction it looks along (its node's `-z`).
    #[must_use]
    pub fn forward(&self) -> DVec3 {
        self.transform.matrix3.z_axis.normalize_or_zero() * -1.0
    }

    /// The unit direction that is up in its image (its node's `+y`).
    #[must_use]
    pub fn up(&self) -> DVec3 {
        self.transform.matrix3.y_axis.normalize_or_zero()
    }
}

/// A glTF camera's projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective: the vertical field of view, in radians, and the width over the height
    /// where the file gives it (else the renderer's image's).
    Perspective {
        /// Vertical field of view, radians.
        yfov: f64,
        /// Width over height, if the file gives it.
        aspect_ratio: Option<f64>,
    },
    /// Orthographic: half the view's width and height.
    Orthographic {
        /// Half the width.
        xmag: f64,
        /// Half the height.
        ymag: f64,
    },
}

/// Something a glTF file holds that [`load_gltf`] leaves out of the scene: not a surface,
/// not placeable, or not the loader's to interpret.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum LeftOut {
    /// A primitive of points or lines (`mode` as glTF names it): nothing to trace.
    Primitive {
        /// The primitive, named as [`GltfMesh::name`] names one.
        mesh: String,
        /// Its mode: `POINTS`, `LINES`, `LINE_LOOP` or `LINE_STRIP`.
        mode: &'static str,
    },
    /// A node whose transform places nothing: scaled to zero (which files use to hide a
    /// part), or past what [`Transformed::affine`] takes. Its primitives are left out;
    /// its children are not.
    Node {
        /// The node's name (or `node N`).
        node: String,
        /// Why [`Transformed::affine`] refused its transform.
        error: GeometryError,
    },
    /// An extension the file uses (or requires) that changes only textures, shading or
    /// lights, which the loader does not interpret: a renderer may read it from the file.
    Extension(String),
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
    /// The node's name (or `node N`); for a node instanced by `EXT_mesh_gpu_instancing`,
    /// with the instance's number after `#`.
    pub node: String,
    /// The primitive's place in [`GltfScene::meshes`].
    pub mesh: usize,
    /// The node's transform, composed with its parents' (and after the instance's own,
    /// for `EXT_mesh_gpu_instancing`), object to world.
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

/// A glTF material: its factors, alpha mode and sidedness, and which textures it uses (by
/// the file's indices); the rest (metallic-roughness, occlusion, extensions) is in the
/// file, by the same index.
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
    /// The base colour texture (times [`base_color`](Self::base_color); its alpha is the
    /// surface's, for [`Alpha::Mask`] and [`Alpha::Blend`]), if any.
    pub base_color_texture: Option<GltfTexture>,
    /// The emissive texture (times [`emissive`](Self::emissive)), if any.
    pub emissive_texture: Option<GltfTexture>,
    /// The normal map, if any.
    pub normal_texture: Option<GltfTexture>,
}

/// A texture a glTF material uses: which of the file's textures and images, and which
/// texture coordinates it reads. The loader reads no image: a renderer decodes it by its
/// index in the file (the `gltf` crate's `import` gives the images in that order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct GltfTexture {
    /// The texture's place in the file's `textures` (its sampler: wrapping, filtering).
    pub texture: usize,
    /// Its image's place in the file's `images`.
    pub image: usize,
    /// Which `TEXCOORD_n` it reads: the meshes' uvs ([`TriangleMesh::uvs`], the hits'
    /// `uv`) are `TEXCOORD_0`.
    pub tex_coord: u32,
}

impl GltfTexture {
    fn of(texture: &gltf::Texture, tex_coord: u32) -> Self {
        Self {
            texture: texture.index(),
            image: texture.source().index(),
            tex_coord,
        }
    }
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
    /// An emissive texture is not read here: a face emits as if its texture were white,
    /// by the factor alone, which is right for untextured emitters and too bright (and
    /// too many lights) for a textured one, whose factor is often `[1, 1, 1]` over a
    /// texture dark but for a few lamps. [`GltfScene::lights_with`] weighs each face by
    /// what the renderer's texture gives over it.
    ///
    /// # Errors
    /// As [`LightTree::new`].
    pub fn lights(&self) -> Result<Option<LightTree<Quad<Triangle>>>, GeometryError> {
        Ok(self.lights_with(|_| 1.0)?.map(|lights| lights.tree))
    }

    /// [`GltfScene::lights`], each face's power times `weight` of it (for a textured
    /// emitter, the mean of the texture's luminance over the face, which the renderer's
    /// own texture lookup gives from the face's `uvs`): a face of weight 0 (or negative,
    /// or NaN) is not a light. With the tree, which instance and face each light is, for
    /// the texture lookup at a sampled point.
    ///
    /// ```
    /// # #[cfg(feature = "gltf")]
    /// # fn lamps(scene: &hitkit::load::GltfScene) -> Result<(), hitkit::GeometryError> {
    /// // A texture lookup of the renderer's: the mean luminance over the face's uvs.
    /// # let mean_luminance = |_: usize, _: [hitkit::glam::DVec2; 3]| 0.5;
    /// let lights = scene.lights_with(|face| match (face.material.emissive_texture, face.uvs) {
    ///     (Some(texture), Some(uvs)) => mean_luminance(texture.image, uvs),
    ///     _ => 1.0,
    /// })?;
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// As [`LightTree::new`].
    pub fn lights_with(
        &self,
        mut weight: impl FnMut(&Emitter) -> f64,
    ) -> Result<Option<GltfLights>, GeometryError> {
        let mut emitters = Emitters::default();
        let mut sources = Vec::new();
        for (i, instance) in self.instances.iter().enumerate() {
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
                let emitter = Emitter {
                    instance: i,
                    face: face.index(),
                    material,
                    uvs: face.uvs(),
                };
                let scale = weight(&emitter);
                if scale.is_nan() || scale <= 0.0 {
                    continue;
                }
                let [a, b, c] = face
                    .corners()
                    .map(|p| instance.transform.transform_point3(p));
                let corners = if mirrored { [a, c, b] } else { [a, b, c] };
                if emitters.push(
                    corners,
                    radiance * scale,
                    material.double_sided,
                    mesh.mesh.material(),
                ) {
                    sources.push((i, face.index()));
                }
            }
        }
        if emitters.is_empty() {
            return Ok(None);
        }
        Ok(Some(GltfLights {
            tree: emitters.tree()?,
            sources,
        }))
    }
}

/// An emitting face of a [`GltfScene`], as [`GltfScene::lights_with`] asks its weight.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct Emitter<'a> {
    /// The instance's place in [`GltfScene::instances`].
    pub instance: usize,
    /// The face's number in its mesh (a hit's `primitive`).
    pub face: u32,
    /// Its material.
    pub material: &'a GltfMaterial,
    /// Its corners' texture coordinates (`TEXCOORD_0`), where the mesh has them.
    pub uvs: Option<[glam::DVec2; 3]>,
}

/// A glTF scene's emitters as [`GltfScene::lights_with`] gathers them.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GltfLights {
    /// The lights.
    pub tree: LightTree<Quad<Triangle>>,
    /// For each of `tree.lights()`, in order: the instance (its place in
    /// [`GltfScene::instances`]) and the face (its number in the instance's mesh) it is.
    pub sources: Vec<(usize, u32)>,
}

/// The glTF file (`.gltf` with its buffers beside it or inline, or `.glb`) at `path`, as
/// meshes, instances and materials ([`GltfScene`]). Images are not read: a renderer that
/// textures its surfaces reads them by the file's indices.
///
/// Nodes instanced by `EXT_mesh_gpu_instancing` give one instance for each of their
/// instances. Triangle strips and fans are read as triangles (their winding kept); primitives of
/// points or lines, nodes scaled to zero and extensions that change only textures,
/// shading or lights are left out and listed in [`GltfScene::left_out`].
///
/// # Errors
/// A [`LoadError`] naming the file: it or a buffer it names cannot be read
/// ([`LoadErrorKind::Io`]), it is not glTF ([`LoadErrorKind::Parse`]), an accessor a
/// primitive reads reaches past its buffer, has a stride shorter than its element, a type
/// a primitive cannot take, or no elements ([`LoadErrorKind::Malformed`], naming the mesh
/// and the accessor), it requires an extension that changes geometry and is not read
/// (Draco or meshopt compression, quantized positions: named in
/// [`LoadErrorKind::Unsupported`]), it holds no triangles, or a mesh cannot be built.
pub fn load_gltf(path: impl AsRef<Path>) -> Result<GltfScene, LoadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| LoadError::new(path, LoadErrorKind::Io(e)))?;
    load(&bytes, path, path.parent())
}

/// [`load_gltf`] of a file held in memory: a `.glb`, or a `.gltf` whose buffers are inline
/// (`data:` URIs). Its errors name the file `(memory)`.
///
/// # Errors
/// As [`load_gltf`]; a buffer in another file is [`LoadErrorKind::Io`].
pub fn load_gltf_slice(bytes: &[u8]) -> Result<GltfScene, LoadError> {
    load(bytes, Path::new("(memory)"), None)
}

/// Extensions that change only textures, shading or lights: a file that requires one
/// still loads, with the extension listed as left out.
fn shading_only(name: &str) -> bool {
    [
        "KHR_materials_",
        "KHR_texture_",
        "EXT_texture_",
        "MSFT_texture_",
    ]
    .iter()
    .any(|prefix| name.starts_with(prefix))
        || matches!(
            name,
            "KHR_lights_punctual" | "KHR_xmp_json_ld" | "EXT_lights_image_based"
        )
}

/// Extensions the loader interprets.
const READ: &[&str] = &["KHR_materials_emissive_strength", "EXT_mesh_gpu_instancing"];

fn load(bytes: &[u8], path: &Path, base: Option<&Path>) -> Result<GltfScene, LoadError> {
    let parse = |what: String| LoadError::new(path, LoadErrorKind::Parse(what));
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let (json, bin) = split_glb(bytes).map_err(|e| parse(format!("a GLB file: {e}")))?;
        (json.to_vec(), bin.map(<[u8]>::to_vec))
    } else {
        (bytes.to_vec(), None)
    };
    let mut root: gltf::json::Root =
        gltf::json::deserialize::from_slice(&json).map_err(|e| parse(e.to_string()))?;

    let mut left_out = Vec::new();
    for name in &root.extensions_required {
        if !READ.contains(&name.as_str()) && !shading_only(name) {
            let what = format!("the required extension {name}");
            return Err(LoadError::new(path, LoadErrorKind::Unsupported(what)));
        }
    }
    for name in &root.extensions_used {
        if !READ.contains(&name.as_str()) && !left_out.contains(&LeftOut::Extension(name.clone())) {
            left_out.push(LeftOut::Extension(name.clone()));
        }
    }
    // What is left is read, or changes nothing here: the `gltf` crate need not know it.
    root.extensions_required.clear();
    check_references(&root, path)?;
    let document = gltf::Document::from_json(root).map_err(|e| parse(e.to_string()))?;
    // The `gltf` crate decodes a file name's percent escapes and unwraps the result: one
    // that is not UTF-8 once decoded would panic there.
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source()
            && !uri.contains(':')
            && !percent_decodes(uri)
        {
            let what = format!(
                "buffer {}'s file name is not UTF-8 once decoded",
                buffer.index()
            );
            return Err(parse(what));
        }
    }
    let buffers = gltf::import_buffers(&document, base, blob).map_err(|e| match e {
        gltf::Error::Io(e) => LoadError::new(path, LoadErrorKind::Io(e)),
        gltf::Error::ExternalReferenceInSliceImport => LoadError::new(
            path,
            LoadErrorKind::Io(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "a buffer in another file, for a file held in memory",
            )),
        ),
        e => parse(e.to_string()),
    })?;

    let materials = document
        .materials()
        .filter_map(|m| m.index().map(|i| (i, m)))
        .map(|(i, m)| material(i, &m))
        .collect::<Vec<_>>();

    // Every primitive of triangles once; `placed[m][p]` is where mesh `m`'s primitive `p`
    // is in `meshes`, if it is there.
    let (mut meshes, mut placed) = (Vec::new(), Vec::new());
    for mesh in document.meshes() {
        let mesh_name = mesh
            .name()
            .map_or_else(|| format!("mesh {}", mesh.index()), ToString::to_string);
        let mut places = Vec::new();
        for primitive in mesh.primitives() {
            let name = format!("{mesh_name}#{}", primitive.index());
            let mode = primitive.mode();
            if let Some(lines) = not_a_surface(mode) {
                left_out.push(LeftOut::Primitive {
                    mesh: name,
                    mode: lines,
                });
                places.push(None);
                continue;
            }
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
                    check_accessor(&a, allowed, &buffers).map_err(|problem| malformed(&a, problem))
                })
            };
            let position = primitive.get(&gltf::Semantic::Positions);
            check(position.clone(), &[(Dimensions::Vec3, DataType::F32)])?;
            check(
                primitive.get(&gltf::Semantic::Normals),
                &[(Dimensions::Vec3, DataType::F32)],
            )?;
            check(
                primitive.get(&gltf::Semantic::TexCoords(0)),
                &[
                    (Dimensions::Vec2, DataType::F32),
                    (Dimensions::Vec2, DataType::U8),
                    (Dimensions::Vec2, DataType::U16),
                ],
            )?;
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
            places.push(Some(meshes.len()));
            meshes.push(GltfMesh {
                name,
                mesh: Arc::new(built),
                material,
            });
        }
        placed.push(places);
    }

    let (mut instances, mut cameras) = (Vec::new(), Vec::new());
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
                return Err(parse(what));
            }
            let local =
                DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
            let world = parent * local;
            if let Some(camera) = node.camera() {
                cameras.push(GltfCamera {
                    node: node
                        .name()
                        .map_or_else(|| format!("node {}", node.index()), ToString::to_string),
                    transform: DAffine3::from_mat4(world),
                    projection: match camera.projection() {
                        gltf::camera::Projection::Perspective(p) => Projection::Perspective {
                            yfov: f64::from(p.yfov()),
                            aspect_ratio: p.aspect_ratio().map(f64::from),
                        },
                        gltf::camera::Projection::Orthographic(o) => Projection::Orthographic {
                            xmag: f64::from(o.xmag()),
                            ymag: f64::from(o.ymag()),
                        },
                    },
                });
            }
            if let Some(mesh) = node.mesh() {
                let name = node
                    .name()
                    .map_or_else(|| format!("node {}", node.index()), ToString::to_string);
                // `EXT_mesh_gpu_instancing`: the node's mesh at each instance's place, under
                // the node's transform; each instance named by its number after `#`.
                let locals = match node.extension_value("EXT_mesh_gpu_instancing") {
                    None => vec![(name.clone(), DMat4::IDENTITY)],
                    Some(value) => gpu_instances(value, &document, &buffers)
                        .map_err(|(accessor, problem)| {
                            LoadError::new(
                                path,
                                LoadErrorKind::Malformed {
                                    mesh: format!("{name} (EXT_mesh_gpu_instancing)"),
                                    accessor,
                                    problem,
                                },
                            )
                        })?
                        .into_iter()
                        .enumerate()
                        .map(|(k, local)| (format!("{name}#{k}"), local))
                        .collect(),
                };
                for (name, local) in locals {
                    let transform = DAffine3::from_mat4(world * local);
                    let places = placed[mesh.index()].iter().flatten();
                    // A transform that places nothing (a zero scale hides a part), or moves
                    // a primitive past f64's range: the node is left out, named, rather
                    // than failing `transformed`.
                    let refused = places.clone().find_map(|&m| {
                        Transformed::affine(meshes[m].mesh.clone(), transform).err()
                    });
                    match refused {
                        Some(error) => left_out.push(LeftOut::Node { node: name, error }),
                        None => instances.extend(places.map(|&m| GltfInstance {
                            node: name.clone(),
                            mesh: m,
                            transform,
                        })),
                    }
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
        left_out,
        cameras,
    })
}

/// The places of a node's `EXT_mesh_gpu_instancing` instances (its `value`): each
/// `T * R * S` of its `TRANSLATION`, `ROTATION` and `SCALE` (each optional, all of one
/// count), in the node's space. The accessor and what is wrong where they cannot be read.
fn gpu_instances(
    value: &gltf::json::Value,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<DMat4>, (usize, String)> {
    use gltf::accessor::Iter;
    let get = |b: gltf::Buffer| buffers.get(b.index()).map(|d| &d.0[..]);
    let named = |key: &str| -> Result<Option<gltf::Accessor>, (usize, String)> {
        let Some(index) = value.get("attributes").and_then(|a| a.get(key)) else {
            return Ok(None);
        };
        let index = index
            .as_u64()
            .map_or(usize::MAX, |i| usize::try_from(i).unwrap_or(usize::MAX));
        document
            .accessors()
            .nth(index)
            .map(Some)
            .ok_or_else(|| (index, format!("no such accessor for {key}")))
    };
    let (translation, rotation, scale) =
        (named("TRANSLATION")?, named("ROTATION")?, named("SCALE")?);
    let vec3 = [(Dimensions::Vec3, DataType::F32)];
    let quaternion = [
        (Dimensions::Vec4, DataType::F32),
        (Dimensions::Vec4, DataType::I8),
        (Dimensions::Vec4, DataType::I16),
    ];
    let mut count = None;
    for (accessor, allowed) in [
        (&translation, &vec3[..]),
        (&rotation, &quaternion[..]),
        (&scale, &vec3[..]),
    ] {
        if let Some(a) = accessor {
            check_accessor(a, allowed, buffers).map_err(|p| (a.index(), p))?;
            if *count.get_or_insert(a.count()) != a.count() {
                return Err((
                    a.index(),
                    format!(
                        "{} instances, where another attribute has {}",
                        a.count(),
                        count.unwrap_or(0)
                    ),
                ));
            }
        }
    }
    let Some(count) = count else {
        // No attribute (glTF asks at least one): the node's one place.
        return Ok(vec![DMat4::IDENTITY]);
    };
    let vectors = |a: &Option<gltf::Accessor>, default: DVec3| -> Vec<DVec3> {
        a.clone()
            .and_then(|a| Iter::<[f32; 3]>::new(a, get))
            .map_or_else(
                || vec![default; count],
                |it| it.map(|v| DVec3::from_array(v.map(f64::from))).collect(),
            )
    };
    let translations = vectors(&translation, DVec3::ZERO);
    let scales = vectors(&scale, DVec3::ONE);
    let rotations: Vec<glam::DQuat> = match rotation {
        None => vec![glam::DQuat::IDENTITY; count],
        Some(a) => {
            use gltf::animation::util::Rotations;
            let read = match a.data_type() {
                DataType::I8 => Iter::new(a, get).map(Rotations::I8),
                DataType::I16 => Iter::new(a, get).map(Rotations::I16),
                _ => Iter::new(a, get).map(Rotations::F32),
            };
            read.map(|r| {
                r.into_f32()
                    .map(|q| {
                        let q = glam::DQuat::from_array(q.map(f64::from));
                        // A zero quaternion (no rotation at all) stays one, which glam
                        // turns as the identity.
                        if q.length_squared() > 0.0 {
                            q.normalize()
                        } else {
                            q
                        }
                    })
                    .collect()
            })
            .unwrap_or_default()
        }
    };
    Ok((0..count)
        .map(|k| {
            let at = |v: &[DVec3], default| v.get(k).copied().unwrap_or(default);
            let turn = rotations.get(k).copied().unwrap_or(glam::DQuat::IDENTITY);
            DMat4::from_translation(at(&translations, DVec3::ZERO))
                * DMat4::from_quat(turn)
                * DMat4::from_scale(at(&scales, DVec3::ONE))
        })
        .collect())
}

/// Whether `uri`'s percent escapes (a `%` and two hex digits; any other `%` kept as it
/// is) decode to UTF-8.
fn percent_decodes(uri: &str) -> bool {
    let bytes = uri.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| char::from(b).to_digit(16);
        match (
            bytes[i],
            bytes.get(i + 1).copied().and_then(hex),
            bytes.get(i + 2).copied().and_then(hex),
        ) {
            (b'%', Some(high), Some(low)) => {
                decoded.push((high * 16 + low) as u8);
                i += 3;
            }
            (b, _, _) => {
                decoded.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8(decoded).is_ok()
}

/// A GLB file's JSON chunk and its binary chunk, if any, with every length checked
/// against the bytes there are (the `gltf` crate's own split subtracts a header's length
/// unchecked, which overflows on a short one).
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let word = |at: usize| -> Result<u32, String> {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .ok_or_else(|| {
                format!(
                    "it ends at byte {} inside its header or a chunk's",
                    bytes.len()
                )
            })
    };
    let (version, length) = (word(4)?, word(8)? as usize);
    if version != 2 {
        return Err(format!(
            "version {version}, where glTF 2.0 files are version 2"
        ));
    }
    if length > bytes.len() || length < 12 {
        return Err(format!(
            "a length of {length} bytes, in a file of {}",
            bytes.len()
        ));
    }
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < length {
        let (size, kind) = (word(at)? as usize, word(at + 4)?);
        let start = at + 8;
        let end = start
            .checked_add(size)
            .filter(|&end| end <= length)
            .ok_or_else(|| format!("a chunk of {size} bytes at byte {at} past the file's end"))?;
        chunks.push((kind, &bytes[start..end]));
        at = end;
    }
    match chunks[..] {
        [(0x4E4F_534A, json)] => Ok((json, None)),
        [(0x4E4F_534A, json), (0x004E_4942, bin), ..] => Ok((json, Some(bin))),
        _ => Err("its first chunk is not its JSON".into()),
    }
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

/// glTF's material `m` (number `i`) as hitkit reads it.
fn material(i: usize, m: &gltf::Material) -> GltfMaterial {
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
        base_color_texture: m
            .pbr_metallic_roughness()
            .base_color_texture()
            .map(|t| GltfTexture::of(&t.texture(), t.tex_coord())),
        emissive_texture: m
            .emissive_texture()
            .map(|t| GltfTexture::of(&t.texture(), t.tex_coord())),
        normal_texture: m
            .normal_texture()
            .map(|t| GltfTexture::of(&t.texture(), t.tex_coord())),
    }
}

/// The references the `gltf` crate's own checks follow before checking them: every
/// primitive's attributes and indices name an accessor of the file. (Its check of a
/// `POSITION` accessor's bounds indexes the accessors with the primitive's number.)
fn check_references(root: &gltf::json::Root, path: &Path) -> Result<(), LoadError> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let named = primitive
                .attributes
                .values()
                .chain(primitive.indices.as_ref());
            for accessor in named {
                if accessor.value() >= root.accessors.len() {
                    let mesh = mesh.name.clone().unwrap_or_else(|| format!("mesh {m}"));
                    return Err(LoadError::new(
                        path,
                        LoadErrorKind::Malformed {
                            mesh: format!("{mesh}#{p}"),
                            accessor: accessor.value(),
                            problem: format!(
                                "no such accessor (the file has {})",
                                root.accessors.len()
                            ),
                        },
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Whether `accessor` can be read as one of `allowed` (its element's dimensions and
/// component type) from `buffers` without reaching past its buffer view or the buffer,
/// which the `gltf` crate's reader does not check (it panics, or reads nothing); the
/// problem where it cannot.
fn check_accessor(
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
    if accessor.sparse().is_some() {
        return Err("sparse storage is not read".into());
    }
    let Some(view) = accessor.view() else {
        return Err("it has no buffer view (all zeros) and is not read".into());
    };
    let count = accessor.count();
    if count == 0 {
        return Err("it has no elements (glTF asks at least one)".into());
    }
    let element = accessor.size();
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "its stride, {stride} bytes, is shorter than its element, {element}"
        ));
    }
    let reach = (count - 1)
        .checked_mul(stride)
        .and_then(|r| r.checked_add(element))
        .and_then(|r| r.checked_add(accessor.offset()));
    if reach.is_none_or(|r| r > view.length()) {
        return Err(format!(
            "{count} elements from byte {} reach past its buffer view's {} bytes",
            accessor.offset(),
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
