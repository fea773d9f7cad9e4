//! What a renderer lights a glTF scene with: the faces of its emitting materials as the
//! lights of a [`LightTree`], weighed by their emissive textures where the images are
//! decoded, and the surface at a light's sample for the texture lookup there.

use std::vec::Vec;

use glam::{DVec2, DVec3};

use super::{GltfMaterial, GltfPunctual, GltfScene};
use crate::light::Emitters;
use crate::{
    Aabb, Emission, GeometryError, HitRecord, Hittable, Interval, Light, LightSample, LightTree,
    PdfHittable, PunctualLight, Quad, Ray, ShadingContext, Triangle,
};
use std::string::ToString;

impl GltfScene {
    /// The faces of every instance whose material emits, in world space, as the lights
    /// of a [`LightTree`]: each face of power `PI * luminance * area` (the flux of a
    /// diffuse emitter of that radiance, `luminance` the Rec. 709 weighting of the
    /// emissive factor; twice that where the material is double-sided), facing the mesh's
    /// front side (the one its corners wind counterclockwise around in the mesh's own
    /// space, under a mirroring node too, as glTF says and [`Transformed`](crate::Transformed) reports it), or
    /// both. `None` where nothing emits.
    ///
    /// An emissive texture is not read here: a face emits as if its texture were white,
    /// by the factor alone, which is right for untextured emitters and too bright (and
    /// too many lights) for a textured one, whose factor is often `[1, 1, 1]` over a
    /// texture dark but for a few lamps. [`GltfScene::textured_lights`] weighs each face
    /// by its texture, [`GltfScene::lights_with`] by what the renderer says.
    ///
    /// # Errors
    /// As [`LightTree::new`].
    pub fn lights(&self) -> Result<Option<LightTree<Quad<Triangle>>>, GeometryError> {
        let (emitters, ..) = self.faces_with(|_| 1.0);
        if emitters.is_empty() {
            return Ok(None);
        }
        emitters.tree().map(Some)
    }

    /// [`GltfScene::lights`], each face weighed by the mean luminance of its emissive
    /// texture over it, as [`GltfScene::images`] holds it ([`GltfImage::mean_luminance`](super::GltfImage::mean_luminance):
    /// a face the texture leaves black is no light), white where the image is not decoded
    /// (without the `gltf-images` feature, this is [`GltfScene::lights`] as a
    /// [`GltfLights`]).
    ///
    /// # Errors
    /// As [`LightTree::new`].
    pub fn textured_lights(&self) -> Result<Option<GltfLights>, GeometryError> {
        self.lights_with(|face| {
            let Some(texture) = face.material.emissive_texture else {
                return 1.0;
            };
            let image = self.images.get(texture.image).and_then(Option::as_ref);
            let mesh = &self.meshes[self.instances[face.instance].mesh];
            let uvs = mesh
                .face(face.face)
                .and_then(|f| mesh.face_uvs(&f, texture.tex_coord));
            match (image, uvs) {
                (Some(image), Some(uvs)) => {
                    image.mean_luminance(uvs.map(|uv| texture.coordinates(uv)), &texture)
                }
                _ => 1.0,
            }
        })
    }

    /// [`GltfScene::lights`], each face's power times `weight` of it (for a textured
    /// emitter, the mean of the texture's luminance over the face, which the renderer's
    /// own texture lookup gives from the face's `uvs`): a face of weight 0 (or negative,
    /// or NaN) is not a light. With the tree, which instance and face each light is, for
    /// the texture lookup at a sampled point ([`GltfLights`] names them in its samples).
    /// The scene's [`punctual`](GltfScene::punctual) lights follow the faces in the tree,
    /// each of [`GltfPunctual::power`] (a sun among the tree's infinite lights); `None`
    /// where no face emits and no such light has power.
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
        weight: impl FnMut(&Emitter) -> f64,
    ) -> Result<Option<GltfLights>, GeometryError> {
        let (emitters, sources, uvs) = self.faces_with(weight);
        // Lights of intensity 0 (valid glTF) alone light nothing: no tree, not an error.
        if emitters.is_empty() && !self.punctual.iter().any(|p| p.power() > 0.0) {
            return Ok(None);
        }
        let (faces, mut powers, mut emission) = emitters.into_parts();
        let mut lights: Vec<Light<Quad<Triangle>>> =
            faces.into_iter().map(Light::Surface).collect();
        for p in &self.punctual {
            lights.push(Light::Punctual(p.light));
            powers.push(p.power());
            emission.push(p.light.emission());
        }
        Ok(Some(GltfLights {
            tree: LightTree::new(lights, &powers, &emission)?,
            sources,
            uvs,
        }))
    }

    /// The emitting faces of [`GltfScene::lights_with`], each weighed, with the instance
    /// and face each is and its face's `TEXCOORD_0` in the order of its corners.
    #[allow(clippy::type_complexity)]
    fn faces_with(
        &self,
        mut weight: impl FnMut(&Emitter) -> f64,
    ) -> (Emitters, Vec<(usize, u32)>, Vec<Option<[DVec2; 3]>>) {
        let mut emitters = Emitters::default();
        let (mut sources, mut uvs) = (Vec::new(), Vec::new());
        for (i, instance) in self.instances.iter().enumerate() {
            let mesh = &self.meshes[instance.mesh];
            let material = &self.materials[mesh.material];
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
                    uvs.push(
                        face.uvs()
                            .map(|[a, b, c]| if mirrored { [a, c, b] } else { [a, b, c] }),
                    );
                }
            }
        }
        (emitters, sources, uvs)
    }
}

/// Light `light` of `KHR_lights_punctual` on a node whose transform composed with its
/// parents' is `world`: at the node's origin, shining along its `-z` (scale ignored, as
/// glTF says), with material `material`.
pub(super) fn punctual_at(
    light: &gltf::khr_lights_punctual::Light,
    node: String,
    world: glam::DMat4,
    material: crate::MaterialId,
) -> Result<GltfPunctual, GeometryError> {
    let position = world.transform_point3(DVec3::ZERO);
    let direction = world.transform_vector3(DVec3::NEG_Z);
    let placed = match light.kind() {
        gltf::khr_lights_punctual::Kind::Point => PunctualLight::point(position),
        gltf::khr_lights_punctual::Kind::Directional => PunctualLight::sun(direction),
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => PunctualLight::spot(
            position,
            direction,
            f64::from(inner_cone_angle),
            f64::from(outer_cone_angle),
        ),
    }?;
    let [r, g, b] = light.color().map(f64::from);
    let color = DVec3::new(r, g, b);
    let intensity = f64::from(light.intensity());
    if !color.is_finite() || !intensity.is_finite() {
        return Err(GeometryError::NonFinite {
            what: "light colour or intensity",
        });
    }
    if intensity < 0.0 || color.min_element() < 0.0 {
        return Err(GeometryError::InvalidParameter {
            what: "light colour or intensity",
            value: intensity.min(color.min_element()),
            domain: "[0, infinity)",
        });
    }
    Ok(GltfPunctual {
        node,
        name: light.name().map_or_else(
            || std::format!("light {}", light.index()),
            ToString::to_string,
        ),
        light: placed.with_material(material),
        color,
        intensity,
        range: light.range().map(f64::from),
    })
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

/// A glTF scene's emitters as [`GltfScene::lights_with`] gathers them: a [`PdfHittable`]
/// (the tree's) whose hits and samples name the instance (`instance`) and face
/// (`primitive`) they are on, with `uv` the face's `TEXCOORD_0` there where its mesh has
/// them, so that [`GltfScene::surface`] finds the material and every texture coordinate
/// at a light's sample as at a hit.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GltfLights {
    /// The lights: the emitting faces, then the scene's punctual lights.
    pub tree: LightTree<Light<Quad<Triangle>>>,
    /// For each face of `tree.lights()`, in order: the instance (its place in
    /// [`GltfScene::instances`]) and the face (its number in the instance's mesh) it is.
    /// The punctual lights follow: light `sources.len() + k` is
    /// [`GltfScene::punctual`]`[k]`.
    pub sources: Vec<(usize, u32)>,
    /// For each light, its face's `TEXCOORD_0` in the order of the light's corners.
    uvs: Vec<Option<[DVec2; 3]>>,
}

impl GltfLights {
    /// `record` (the tree's, on light `light`) named as the scene's surface: its instance,
    /// its face, and where the mesh has them, its texture coordinates (a triangle light's
    /// `uv` is the weights of its second and third corners).
    fn named(&self, uvs: Option<[DVec2; 3]>, light: usize, mut record: HitRecord) -> HitRecord {
        if let Some(&(instance, face)) = self.sources.get(light) {
            record.instance = u32::try_from(instance).ok();
            record.primitive = Some(face);
            if let Some([a, b, c]) = uvs {
                let (alpha, beta) = (record.uv.x, record.uv.y);
                record.uv = a * (1.0 - alpha - beta) + b * alpha + c * beta;
            }
        }
        record
    }
}

impl Hittable for GltfLights {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        // The tree holds no `Masked` light: its light hit is its hit.
        self.light_hit(ray, ray_t).map(|(_, record)| record)
    }
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.tree.occluded(ray, ray_t)
    }
    fn bounding_box(&self) -> Aabb {
        self.tree.bounding_box()
    }
}

impl PdfHittable for GltfLights {
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.tree.pdf_value(origin, direction)
    }
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.tree.sample_direction(origin, u)
    }
    fn light_pdf(&self, at: &ShadingContext, direction: DVec3) -> f64 {
        self.tree.light_pdf(at, direction)
    }
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        let mut sample = self.tree.sample_light(at, u)?;
        let uvs = self.uvs.get(sample.light).copied().flatten();
        sample.record = self.named(uvs, sample.light, sample.record);
        Some(sample)
    }
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        let (light, record) = self.tree.light_hit(ray, ray_t)?;
        let uvs = self.uvs.get(light).copied().flatten();
        Some((light, self.named(uvs, light, record)))
    }
    fn emission(&self) -> Emission {
        self.tree.emission()
    }
}
