//! glTF 2.0 files through `gltf`, read in stages (each a module): the file checked and its
//! buffers read ([`read`]), every mesh primitive once from its checked accessors
//! ([`accessors`]), the materials and their textures ([`materials`]), every node that
//! holds a mesh placed as instances of it under the node's composed transform, and the
//! cameras ([`nodes`]); then what a renderer asks of the result: the emitters as lights
//! ([`lights`]), the surface at a hit ([`surface`]), and, behind `gltf-images`, the images
//! decoded and looked up ([`images`]).

mod accessors;
mod images;
mod lights;
mod materials;
mod nodes;
mod read;
mod surface;

use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::sync::Arc;
use std::vec::Vec;

use glam::{DAffine3, DVec2, DVec3};

use super::load::{LoadError, LoadErrorKind};
use crate::mesh::Face;
use crate::{Affine, GeometryError, Transformed, TriangleMesh};

pub use images::GltfImage;
pub use lights::{Emitter, GltfLights};
pub use materials::{Filter, Sampler, TextureTransform, Wrap};
pub use surface::GltfSurface;

/// A glTF file's meshes, instances and materials, as [`load_gltf`] reads them.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GltfScene {
    /// Every triangle primitive of every mesh, once, in the file's order.
    pub meshes: Vec<GltfMesh>,
    /// Every primitive of every node of the scene that holds a mesh (the default scene,
    /// else the first), under the node's transform composed with its parents'.
    pub instances: Vec<GltfInstance>,
    /// The materials, in the file's order, then glTF's default material (white, opaque,
    /// single-sided; its [`GltfMaterial::index`] `None`) where a primitive names none: a
    /// mesh's [`MaterialId`](crate::MaterialId) is its material's place here, so a hit's
    /// `material` always names one.
    pub materials: Vec<GltfMaterial>,
    /// What the file holds that the scene leaves out, and why (the file loads without it).
    pub left_out: Vec<LeftOut>,
    /// The cameras of the scene's nodes, in the order the walk meets them.
    pub cameras: Vec<GltfCamera>,
    /// The file's images, in its order, decoded where a material's base colour or
    /// emissive texture reads them, with the `gltf-images` feature (`None` for the rest,
    /// and for all of them without it). [`GltfScene::texel`] looks one up.
    pub images: Vec<Option<Arc<GltfImage>>>,
    /// The file's scenes, by name (or `scene N`), and which of them was read.
    pub scenes: Scenes,
    /// The lights of `KHR_lights_punctual` on the scene's nodes, in the order the walk
    /// meets them, in world space.
    pub punctual: Vec<GltfPunctual>,
}

/// The scenes a glTF file holds, and which one [`load_gltf`] read (the file's default
/// scene, else its first; [`GltfOptions::scene`] picks another).
#[derive(Clone, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct Scenes {
    /// Every scene's name (or `scene N`), in the file's order.
    pub names: Vec<String>,
    /// The one read, if the file has any.
    pub read: Option<usize>,
}

/// What [`load_gltf_with`] reads beyond the defaults.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct GltfOptions {
    /// The scene to read, by its place in the file (the default scene, else the first,
    /// where `None`); one past the file's scenes is a [`LoadErrorKind::Unsupported`].
    pub scene: Option<usize>,
}

impl GltfOptions {
    /// Reads scene `scene` (its place in the file).
    #[must_use]
    pub fn with_scene(mut self, scene: usize) -> Self {
        self.scene = Some(scene);
        self
    }
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

/// A light of glTF's `KHR_lights_punctual` (a point, spot or directional light) where its
/// node puts it: the [`PunctualLight`](crate::PunctualLight) in world space (glTF's lights
/// shine along their node's `-z`; a directional one is a sun), with what it emits.
///
/// Its light's [`MaterialId`](crate::MaterialId) is numbered after the scene's materials,
/// `materials.len()` for the first light, one more for each next, so that a renderer's
/// table of materials by id takes one emitter a light after its own
/// ([`GltfPunctual::emitted`]).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct GltfPunctual {
    /// The node's name (or `node N`).
    pub node: String,
    /// The light's name (or `light N`).
    pub name: String,
    /// The light, in world space.
    pub light: crate::PunctualLight,
    /// Its linear RGB colour.
    pub color: DVec3,
    /// Its intensity: candela for a point or spot light, lux for a directional one.
    pub intensity: f64,
    /// Where the file gives one, the distance past which glTF lets a viewer treat the
    /// light as out (a hint: the light itself falls off as the inverse square alone).
    pub range: Option<f64>,
}

impl GltfPunctual {
    /// What it emits, `color * intensity`: the value its samples' `pdf` divides (see
    /// [`PunctualLight`](crate::PunctualLight)).
    #[must_use]
    pub fn emitted(&self) -> DVec3 {
        self.color * self.intensity
    }

    /// Its power, for a [`LightTree`](crate::LightTree) beside the scene's emitting faces:
    /// [`PunctualLight::power`](crate::PunctualLight::power) of its intensity times its
    /// colour's Rec. 709 luminance.
    #[must_use]
    pub fn power(&self) -> f64 {
        let luminance = self.color.dot(DVec3::new(0.2126, 0.7152, 0.0722));
        self.light.power(luminance * self.intensity)
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
    /// part), or past what [`Transformed::affine`] takes (its primitives are left out, its
    /// children are not); or turned by a quaternion that is no rotation (a zero one, say:
    /// it is left out with its children).
    Node {
        /// The node's name (or `node N`).
        node: String,
        /// Why [`Transformed::affine`] refused its transform.
        error: GeometryError,
    },
    /// An extension the file uses (or requires) that changes only textures, shading or
    /// lights, which the loader does not interpret: a renderer may read it from the file.
    Extension(String),
    /// A light of `KHR_lights_punctual` that cannot be placed: a spot's cone outside
    /// glTF's bounds, an intensity or colour that is negative or not finite, a node whose
    /// transform leaves it no position or direction.
    Light {
        /// The light's node's name (or `node N`).
        node: String,
        /// What is wrong.
        error: GeometryError,
    },
    /// An image a texture reads that is not decoded (a format the `image` crate does not
    /// read, KTX2 say, or a file that cannot be read), with the `gltf-images` feature; or
    /// a texture that names none. Lookups of it give white.
    Image {
        /// Its place in the file's images.
        image: usize,
        /// Why.
        reason: String,
    },
}

/// One primitive of a glTF mesh.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GltfMesh {
    /// The mesh's name (or `mesh N`), and the primitive's number after `#`.
    pub name: String,
    /// Its triangles in the mesh's own space, with the file's normals and first texture
    /// coordinates (`TEXCOORD_0`) where it has them, and its material's id: its material's
    /// place in [`GltfScene::materials`].
    pub mesh: Arc<TriangleMesh>,
    /// Its material's place in [`GltfScene::materials`] (glTF's default material where
    /// the file names none).
    pub material: usize,
    /// `TEXCOORD_1` onward, each for every vertex in the file's numbering (shared with
    /// the filters of [`GltfScene::objects`]).
    more_uvs: Arc<Vec<Vec<DVec2>>>,
    /// For each face number, its place in the mesh's own order (`u32::MAX` for a face
    /// with no area, which is never hit).
    places: Vec<u32>,
}

impl GltfMesh {
    fn new(
        name: String,
        mesh: Arc<TriangleMesh>,
        material: usize,
        more_uvs: Vec<Vec<DVec2>>,
    ) -> Self {
        let mut places = vec![u32::MAX; mesh.face_count()];
        for (place, number) in mesh.face_numbers().iter().enumerate() {
            places[*number as usize] = place as u32;
        }
        Self {
            name,
            mesh,
            material,
            more_uvs: Arc::new(more_uvs),
            places,
        }
    }

    /// Face `number` (as the file numbers its triangles, and a hit's `primitive` does),
    /// in constant time (a table made at load; a mesh rebuilt since is searched); `None`
    /// past the faces, and for a face with no area (never hit).
    ///
    /// ```no_run
    /// # fn main() -> Result<(), hitkit::load::LoadError> {
    /// use hitkit::load::load_gltf;
    ///
    /// let scene = load_gltf("Box.gltf")?;
    /// let face = scene.meshes[0].face(0).expect("a face with area");
    /// assert_eq!(face.index(), 0);
    /// # Ok(())
    /// # }
    /// ```
    #[must_use]
    pub fn face(&self, number: u32) -> Option<Face<'_>> {
        let place = *self.places.get(number as usize)? as usize;
        let numbers = self.mesh.face_numbers();
        if numbers.get(place) == Some(&number) {
            return Some(self.mesh.face_at(place));
        }
        // A face with no area; or the mesh was rebuilt since it was loaded (through
        // `Arc::get_mut`), which reorders its faces: found by a search, never wrong.
        let place = numbers.iter().position(|&n| n == number)?;
        Some(self.mesh.face_at(place))
    }

    /// How many sets of texture coordinates (`TEXCOORD_0` to `TEXCOORD_n-1`) it has.
    #[must_use]
    pub fn uv_sets(&self) -> usize {
        if self.mesh.uvs().is_empty() {
            0
        } else {
            1 + self.more_uvs.len()
        }
    }

    /// The texture coordinates of set `set` (`TEXCOORD_set`) at `face`'s corners, in the
    /// order of [`Face::corners`]; `None` where the mesh has no such set.
    #[must_use]
    pub fn face_uvs(&self, face: &Face<'_>, set: u32) -> Option<[DVec2; 3]> {
        corner_uvs(&self.more_uvs, face, set)
    }

    /// The texture coordinates of set `set` at the point of `face` whose barycentrics
    /// (the weights of its corners, in the order of [`Face::corners`]) are `weights`.
    #[must_use]
    pub fn uv(&self, face: &Face<'_>, weights: DVec3, set: u32) -> Option<DVec2> {
        let [a, b, c] = self.face_uvs(face, set)?;
        Some(a * weights.x + b * weights.y + c * weights.z)
    }
}

/// Set `set`'s texture coordinates at `face`'s corners: the mesh's own for set 0, `more`'s
/// (set 1 on, by the file's vertex numbers) for the rest.
fn corner_uvs(more: &[Vec<DVec2>], face: &Face<'_>, set: u32) -> Option<[DVec2; 3]> {
    if set == 0 {
        return face.uvs();
    }
    let uvs = more.get(set as usize - 1)?;
    let [a, b, c] = face.indices().map(|i| uvs.get(i as usize).copied());
    Some([a?, b?, c?])
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
    /// Its place in the file's materials; `None` for glTF's default material.
    pub index: Option<usize>,
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

/// A texture a glTF material uses: which of the file's textures and images, which texture
/// coordinates it reads and how it transforms them, its sampler, and whether its texels
/// are colour (sRGB-encoded: base colour, emission) or data (normals).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct GltfTexture {
    /// The texture's place in the file's `textures`.
    pub texture: usize,
    /// Its image's place in the file's `images` (and in [`GltfScene::images`]).
    pub image: usize,
    /// Which `TEXCOORD_n` it reads (its `KHR_texture_transform`'s `texCoord` where that
    /// overrides the material's).
    pub tex_coord: u32,
    /// Its `KHR_texture_transform`, if any: [`GltfTexture::coordinates`] applies it.
    pub transform: Option<TextureTransform>,
    /// How it wraps and filters.
    pub sampler: Sampler,
    /// Whether its texels are sRGB-encoded colour, decoded to linear values on lookup.
    pub colour: bool,
}

impl GltfScene {
    /// Every instance as a [`Transformed`] of its shared mesh, its instance id its place
    /// in [`GltfScene::instances`] (so that a hit's `instance` names it, and its
    /// `primitive` the face): for a [`Bvh`](crate::Bvh). Nothing is cut: see
    /// [`GltfScene::objects`] for the instances as glTF asks a renderer to draw them.
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
}

/// The glTF file (`.gltf` with its buffers beside it or inline, or `.glb`) at `path`, as
/// meshes, instances and materials ([`GltfScene`]); with the `gltf-images` feature, the
/// images its materials' base colour and emissive textures read, decoded.
///
/// Nodes instanced by `EXT_mesh_gpu_instancing` give one instance for each of their
/// instances. Triangle strips and fans are read as triangles (their winding kept); sparse
/// accessors as glTF says (on a buffer view or on zeros). Primitives of points or lines,
/// nodes scaled to zero or turned by a quaternion that is no rotation, images that cannot
/// be decoded and extensions that change only textures, shading or lights are left out
/// and listed in [`GltfScene::left_out`].
///
/// # Errors
/// A [`LoadError`] naming the file: it or a buffer it names cannot be read
/// ([`LoadErrorKind::Io`], naming the buffer's own file), it is not glTF
/// ([`LoadErrorKind::Parse`]: a GLB's header or magic that is wrong is named as such), an
/// accessor a primitive reads reaches past its buffer, has a stride shorter than its
/// element, a type a primitive cannot take, no elements, or sparse indices out of order or
/// past its count ([`LoadErrorKind::Malformed`], naming the mesh and the accessor), it
/// requires an extension that changes geometry and is not read (Draco or meshopt
/// compression, quantized positions: named in [`LoadErrorKind::Unsupported`]), it holds no
/// triangles, or a mesh cannot be built.
pub fn load_gltf(path: impl AsRef<Path>) -> Result<GltfScene, LoadError> {
    load_gltf_with(path, GltfOptions::default())
}

/// [`load_gltf`] with [`GltfOptions`]: another scene than the file's default, say.
///
/// ```no_run
/// use hitkit::load::{GltfOptions, load_gltf_with};
///
/// # fn main() -> Result<(), hitkit::load::LoadError> {
/// let scene = load_gltf_with("Scenes.gltf", GltfOptions::default().with_scene(1))?;
/// assert_eq!(scene.scenes.read, Some(1));
/// # Ok(())
/// # }
/// ```
///
/// # Errors
/// As [`load_gltf`]; a scene the file does not have is [`LoadErrorKind::Unsupported`].
pub fn load_gltf_with(
    path: impl AsRef<Path>,
    options: GltfOptions,
) -> Result<GltfScene, LoadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| LoadError::new(path, LoadErrorKind::Io(e)))?;
    load(&bytes, path, path.parent(), options)
}

/// [`load_gltf`] of a file held in memory: a `.glb`, or a `.gltf` whose buffers are inline
/// (`data:` URIs). Its errors name the file `(memory)`.
///
/// # Errors
/// As [`load_gltf`]; a buffer in another file is [`LoadErrorKind::Io`].
pub fn load_gltf_slice(bytes: &[u8]) -> Result<GltfScene, LoadError> {
    load(bytes, Path::new("(memory)"), None, GltfOptions::default())
}

/// The stages in order, each its module's.
fn load(
    bytes: &[u8],
    path: &Path,
    base: Option<&Path>,
    options: GltfOptions,
) -> Result<GltfScene, LoadError> {
    let mut left_out = Vec::new();
    let (document, buffers) = read::document(bytes, path, base, &mut left_out)?;
    let mut materials = document
        .materials()
        .filter_map(|m| m.index().map(|i| (i, m)))
        .map(|(i, m)| materials::material(i, &m))
        .collect::<Vec<_>>();
    let default = materials.len();
    let (meshes, placed) = accessors::meshes(&document, &buffers, path, default, &mut left_out)?;
    if meshes.iter().any(|m| m.material == default) {
        materials.push(materials::default_material());
    }
    let scenes = Scenes {
        names: document
            .scenes()
            .map(|s| {
                s.name()
                    .map_or_else(|| format!("scene {}", s.index()), ToString::to_string)
            })
            .collect(),
        read: None,
    };
    let scene = match options.scene {
        Some(n) => Some(document.scenes().nth(n).ok_or_else(|| {
            let what = format!("scene {n} (the file has {})", scenes.names.len());
            LoadError::new(path, LoadErrorKind::Unsupported(what))
        })?),
        None => document
            .default_scene()
            .or_else(|| document.scenes().next()),
    };
    let scenes = Scenes {
        read: scene.as_ref().map(gltf::Scene::index),
        ..scenes
    };
    let (instances, cameras, punctual) = nodes::place(
        &document,
        &buffers,
        (&meshes, &placed),
        materials.len(),
        scene,
        path,
        &mut left_out,
    )?;
    if meshes.iter().all(|m| m.mesh.face_count() == 0) {
        return Err(LoadError::new(path, LoadErrorKind::Empty));
    }
    let images = images::decode(&document, &buffers, base, &materials, &mut left_out);
    Ok(GltfScene {
        meshes,
        instances,
        materials,
        left_out,
        cameras,
        images,
        scenes,
        punctual,
    })
}
