//! What shading asks of a glTF scene at a hit or a light's sample: the material, the face,
//! its barycentrics and every set of texture coordinates there; and the instances as glTF
//! asks a renderer to draw them (alpha cut-outs, single-sided surfaces).

use std::boxed::Box;
use std::sync::Arc;
use std::vec::Vec;

use glam::{DVec2, DVec3, DVec4};

use super::{Alpha, GltfImage, GltfMaterial, GltfMesh, GltfScene, GltfTexture};
use crate::mesh::Face;
use crate::{Candidate, Filtered, GeometryError, HitRecord, Hittable, Transformed};

/// The surface of a [`GltfScene`] at a hit or a light's sample ([`GltfScene::surface`]).
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct GltfSurface<'a> {
    /// The instance's place in [`GltfScene::instances`].
    pub instance: usize,
    /// Its mesh.
    pub mesh: &'a GltfMesh,
    /// Its material (glTF's default material where the file names none).
    pub material: &'a GltfMaterial,
    /// The face.
    pub face: Face<'a>,
    /// The point's barycentrics: the weights of the face's corners, in the order of
    /// [`Face::corners`], each in `[0, 1]`, summing to 1 to within rounding.
    pub weights: DVec3,
}

impl GltfSurface<'_> {
    /// The texture coordinates of set `set` (`TEXCOORD_set`) here; `None` where the mesh
    /// has no such set.
    #[must_use]
    pub fn uv(&self, set: u32) -> Option<DVec2> {
        self.mesh.uv(&self.face, self.weights, set)
    }

    /// The coordinates `texture` reads here: its set's, under its transform (the
    /// origin's where the mesh lacks the set, as glTF leaves a texture without
    /// coordinates undefined).
    #[must_use]
    pub fn coordinates(&self, texture: &GltfTexture) -> DVec2 {
        texture.coordinates(self.uv(texture.tex_coord).unwrap_or(DVec2::ZERO))
    }
}

impl GltfScene {
    /// The surface at `hit`, a hit of the instances of [`GltfScene::transformed`] or
    /// [`GltfScene::objects`] (whose `instance` and `primitive` name the instance and the
    /// face), or the record of a [`GltfLights`](super::GltfLights) sample: the material,
    /// the face and the point's barycentrics, from which every set of texture coordinates.
    /// `None` where the record names no instance or face of this scene.
    ///
    /// The barycentrics are the hit point's, moved into the mesh's space and projected on
    /// the face's plane: exact but for rounding (a few ulps of the point's magnitude over
    /// the face's size), which a texture lookup does not see.
    #[must_use]
    pub fn surface(&self, hit: &HitRecord) -> Option<GltfSurface<'_>> {
        let instance = hit.instance? as usize;
        let placed = self.instances.get(instance)?;
        let mesh = &self.meshes[placed.mesh];
        let face = mesh.face(hit.primitive?)?;
        let point = placed.transform.inverse().transform_point3(hit.point);
        Some(GltfSurface {
            instance,
            mesh,
            material: &self.materials[mesh.material],
            face,
            weights: weights(face.corners(), point),
        })
    }

    /// `texture`'s texel at `uv` (already under its transform:
    /// [`GltfSurface::coordinates`]), with its sampler, colour decoded from sRGB to linear
    /// values (alpha is linear); white where its image is not decoded.
    #[must_use]
    pub fn texel(&self, texture: &GltfTexture, uv: DVec2) -> DVec4 {
        match self.images.get(texture.image).and_then(Option::as_ref) {
            Some(image) => image.sample(uv, texture),
            None => DVec4::ONE,
        }
    }

    /// `texture` at `surface`: [`GltfScene::texel`] at [`GltfSurface::coordinates`].
    #[must_use]
    pub fn texture_at(&self, texture: &GltfTexture, surface: &GltfSurface<'_>) -> DVec4 {
        self.texel(texture, surface.coordinates(texture))
    }

    /// Every instance as glTF asks a renderer to draw it, for a [`Bvh`](crate::Bvh): as in
    /// [`GltfScene::transformed`] (its instance id its place in
    /// [`GltfScene::instances`]), with, inside the search, a material's `MASK` cut-out
    /// (where its alpha, the base colour factor's times its texture's where the image is
    /// decoded, is below the cutoff, the surface is not there) and a single-sided
    /// material's back turned away (glTF's `doubleSided: false`: a ray meets only its
    /// front).
    ///
    /// # Errors
    /// As [`GltfScene::transformed`].
    pub fn objects(&self) -> Result<Vec<Box<dyn Hittable>>, GeometryError> {
        self.instances
            .iter()
            .zip(0u32..)
            .map(|(instance, id)| {
                let mesh = &self.meshes[instance.mesh];
                let material = &self.materials[mesh.material];
                let object: Box<dyn Hittable> = match self.cut(mesh, material) {
                    Some(cut) => Box::new(
                        Transformed::affine(Arc::new(cut), instance.transform)?
                            .with_instance_id(id),
                    ),
                    None => Box::new(
                        Transformed::affine(mesh.mesh.clone(), instance.transform)?
                            .with_instance_id(id),
                    ),
                };
                Ok(object)
            })
            .collect()
    }

    /// `mesh` behind the filter its material asks, if it asks one.
    fn cut(
        &self,
        mesh: &GltfMesh,
        material: &GltfMaterial,
    ) -> Option<Filtered<Arc<crate::TriangleMesh>, impl Fn(&Candidate) -> bool + use<>>> {
        let cutoff = match material.alpha {
            Alpha::Mask { cutoff } => Some(cutoff),
            Alpha::Opaque | Alpha::Blend => None,
        };
        let single_sided = !material.double_sided;
        if cutoff.is_none() && !single_sided {
            return None;
        }
        let factor = material.base_color[3];
        let texture: Option<(GltfTexture, Arc<GltfImage>)> =
            material.base_color_texture.and_then(|t| {
                let image = self.images.get(t.image)?.clone()?;
                Some((t, image))
            });
        let more_uvs = mesh.more_uvs.clone();
        Some(Filtered::new(mesh.mesh.clone(), move |c: &Candidate| {
            if single_sided && !c.front_face() {
                return false;
            }
            let Some(cutoff) = cutoff else { return true };
            let alpha = match &texture {
                Some((texture, image)) => {
                    let b = c.barycentric();
                    let uv = super::corner_uvs(&more_uvs, &c.face(), texture.tex_coord)
                        .map(|[p, q, r]| p * (1.0 - b.x - b.y) + q * b.x + r * b.y);
                    let uv = texture.coordinates(uv.unwrap_or(DVec2::ZERO));
                    factor * image.sample(uv, texture).w
                }
                None => factor,
            };
            alpha >= cutoff
        }))
    }
}

/// The barycentrics of `point` on the triangle of `corners`: of its projection on the
/// triangle's plane, clamped into the triangle (a point on an edge may round a hair
/// outside); the centre's for a triangle with no area.
fn weights([p0, p1, p2]: [DVec3; 3], point: DVec3) -> DVec3 {
    let (e1, e2, d) = (p1 - p0, p2 - p0, point - p0);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1, d2) = (d.dot(e1), d.dot(e2));
    let area = d11 * d22 - d12 * d12;
    let b1 = (d22 * d1 - d12 * d2) / area;
    let b2 = (d11 * d2 - d12 * d1) / area;
    let b = DVec3::new(1.0 - b1 - b2, b1, b2).max(DVec3::ZERO);
    let sum = b.x + b.y + b.z;
    if sum > 0.0 && b.is_finite() {
        b / sum
    } else {
        DVec3::splat(1.0 / 3.0)
    }
}

#[cfg(test)]
mod tests {
    use super::weights;
    use glam::DVec3;

    #[test]
    fn weights_recover_the_point_and_stay_in_the_triangle() {
        let corners = [
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(4.0, 1.0, 2.0),
            DVec3::new(0.0, 3.0, 2.5),
        ];
        let b = DVec3::new(0.2, 0.5, 0.3);
        let point = corners[0] * b.x + corners[1] * b.y + corners[2] * b.z;
        // The 2x2 system's condition here is small: a few ulps of 1 each.
        assert!((weights(corners, point) - b).abs().max_element() < 1e-14);
        // Off the plane, it projects; past an edge, it clamps.
        let above = point + (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        assert!((weights(corners, above) - b).abs().max_element() < 1e-14);
        let outside = corners[1] * 2.0 - corners[0];
        assert_eq!(weights(corners, outside), DVec3::new(0.0, 1.0, 0.0));
        assert_eq!(weights([DVec3::ZERO; 3], point), DVec3::splat(1.0 / 3.0));
    }
}
