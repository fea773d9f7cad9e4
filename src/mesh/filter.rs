//! [`Filtered`]: a mesh whose faces' crossings a predicate may turn away (cut-outs: leaves,
//! fences, cloth whose texture says "not here"), inside the search, so that the search
//! goes on past them.

use glam::DVec2;

use super::TriangleMesh;
use super::intersect::Crossing;
use crate::record::{Found, Made};
use crate::{Aabb, HitRecord, Hittable, Interval, Ray};

/// A crossing of a face that a [`Filtered`] mesh's filter is asked about: where along the
/// ray, and, computed when asked (a filter that needs less pays for less), which face, its
/// barycentrics and its texture coordinates.
#[derive(Clone, Copy, Debug)]
pub struct Candidate<'a> {
    /// The ray, in the mesh's own space (an instance's ray once moved into it).
    pub ray: &'a Ray,
    /// Where along the ray: as the hit would report it in `hit`; in `occluded`, within the
    /// crossing's rounding bound of that (a filter that decides by `t` to the ulp can
    /// answer the two queries apart).
    pub t: f64,
    mesh: &'a TriangleMesh,
    position: usize,
    crossing: &'a Crossing,
}

impl<'a> Candidate<'a> {
    /// The face, numbered as the caller's list of faces numbers it
    /// ([`HitRecord::primitive`]).
    #[inline]
    #[must_use]
    pub fn primitive(&self) -> u32 {
        self.mesh.tree.order[self.position]
    }

    /// The barycentric coordinates `(b1, b2)` of the crossing: the weights of the face's
    /// second and third vertices.
    #[inline]
    #[must_use]
    pub fn barycentric(&self) -> DVec2 {
        let b = self.crossing.barycentric();
        DVec2::new(b.y, b.z)
    }

    /// The texture coordinates there, as the hit would report them in `uv` (the
    /// barycentrics where the mesh has no texture coordinates): what a cut-out looks up.
    #[inline]
    #[must_use]
    pub fn uv(&self) -> DVec2 {
        self.mesh.uv_at(self.position, self.crossing.barycentric())
    }

    /// The face.
    #[cfg(feature = "gltf")]
    pub(crate) fn face(&self) -> super::Face<'a> {
        self.mesh.face_at(self.position)
    }

    /// Whether the ray crosses the face from its front, the side its corners wind
    /// counterclockwise around, as the hit would report it in `front_face` (through an
    /// instance too, a mirroring one included): what a single-sided surface (glTF's
    /// `doubleSided: false`) culls by.
    #[inline]
    #[must_use]
    pub fn front_face(&self) -> bool {
        let [p0, p1, p2] = self.mesh.corners_at(self.position);
        let (normal, _) = crate::math::unit_and_length((p1 - p0).cross(p2 - p0));
        self.ray.direction.dot(normal) < 0.0
    }
}

/// A [`TriangleMesh`] (or an `Arc`, `Box` or `&` of one) whose crossings `filter` may
/// reject: the filter sees each face the search crosses ([`Candidate`]: `t`, the ray, and
/// on asking the face, its barycentrics and texture coordinates) and answers whether it
/// counts.
/// A rejected crossing is passed over inside the search, which goes on to the faces
/// behind it: no record is made for it, and a ray spawned from a hit keeps its exact start
/// (no re-trace from the rejected point, no epsilon).
///
/// The filter is asked at most once per face and query, and only about a crossing that
/// would be the closest so far (or, in [`occluded`](Hittable::occluded), any crossing in
/// the range), so that a stochastic cut-out (alpha as a probability) stays unbiased: draw
/// its number from a hash of the ray and the face, not from a shared generator, so that
/// the answer is the same for the same question. For a filter that answers the same for
/// the same face and point, `occluded` answers as `hit(..).is_some()`.
///
/// Which to use when: a filter, where what is cut out comes from data the shape does not
/// own (a texture's alpha, a per-face flag) and the faces are a mesh's; a
/// [`Quad`](crate::Quad)'s [`Interior`](crate::Interior), where the cut-out is geometry in
/// the shape's `(alpha, beta)` coordinates (a disk, a ring, a window in a wall), which also
/// gives its area and samples for lighting.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Filtered, Hittable, Interval, Ray, TriangleMesh};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// // Two squares, one behind the other; the front one's texture is cut out left of u = 0.5.
/// let vertices = [
///     DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y,
///     DVec3::new(0.0, 0.0, -1.0), DVec3::new(1.0, 0.0, -1.0),
///     DVec3::new(1.0, 1.0, -1.0), DVec3::new(0.0, 1.0, -1.0),
/// ];
/// let faces = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
/// let uvs: Vec<_> = vertices.iter().map(|p| p.truncate()).collect();
/// let mesh = TriangleMesh::new(&vertices, &faces)?.with_uvs(&uvs)?;
/// let leaf = Filtered::new(mesh, |c: &hitkit::Candidate| c.primitive() >= 2 || c.uv().x >= 0.5);
///
/// let through_the_hole = Ray::new(DVec3::new(0.25, 0.5, 1.0), DVec3::NEG_Z);
/// let hit = leaf.hit(&through_the_hole, Interval::FORWARD).unwrap();
/// assert_eq!((hit.t, hit.primitive.is_some_and(|f| f >= 2)), (2.0, true));
/// let on_the_leaf = Ray::new(DVec3::new(0.75, 0.5, 1.0), DVec3::NEG_Z);
/// assert_eq!(leaf.hit(&on_the_leaf, Interval::FORWARD).unwrap().t, 1.0);
/// // A shadow ray through the hole finds the square behind; one that stops short does not.
/// assert!(leaf.occluded(&through_the_hole, Interval::FORWARD));
/// assert!(!leaf.occluded(&through_the_hole, Interval::new(0.0, 1.5)));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Filtered<M, F> {
    mesh: M,
    filter: F,
}

impl<M, F> Filtered<M, F>
where
    M: AsRef<TriangleMesh>,
    F: Fn(&Candidate) -> bool,
{
    /// `mesh`, its crossings asked of `filter`.
    pub fn new(mesh: M, filter: F) -> Self {
        Self { mesh, filter }
    }
}

impl<M, F> Filtered<M, F> {
    /// The mesh.
    #[inline]
    #[must_use]
    pub fn mesh(&self) -> &M {
        &self.mesh
    }
}

impl AsRef<TriangleMesh> for TriangleMesh {
    #[inline]
    fn as_ref(&self) -> &TriangleMesh {
        self
    }
}

impl<M, F> Filtered<M, F>
where
    M: AsRef<TriangleMesh>,
    F: Fn(&Candidate) -> bool,
{
    /// Whether the filter takes the crossing `c` of the face at `position`.
    #[inline]
    fn accepts(&self, ray: &Ray, position: usize, c: &Crossing) -> bool {
        (self.filter)(&Candidate {
            ray,
            t: c.t,
            mesh: self.mesh.as_ref(),
            position,
            crossing: c,
        })
    }

    #[inline]
    fn closest(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, Crossing)> {
        let mesh = self.mesh.as_ref();
        kernel!(mesh, |lanes, L| mesh.closest::<L>(
            lanes,
            ray,
            ray_t,
            &mut (),
            |p, c| self.accepts(ray, p, c)
        ))
    }
}

impl<M, F> Hittable for Filtered<M, F>
where
    M: AsRef<TriangleMesh> + Send + Sync,
    F: Fn(&Candidate) -> bool + Send + Sync,
{
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let (position, crossing) = self.closest(ray, ray_t)?;
        self.mesh
            .as_ref()
            .record_at(ray, position, crossing.t, crossing.barycentric())
    }

    /// As the mesh's: the face's barycentrics in `coords`, its position in `part`.
    fn find(&self, ray: &Ray, ray_t: Interval, _: &mut Made) -> Option<Found> {
        let (position, crossing) = self.closest(ray, ray_t)?;
        Some(Found::new(
            crossing.t,
            crossing.barycentric(),
            position as u32,
        ))
    }

    fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
        self.mesh.as_ref().record(ray, ray_t, found)
    }

    /// The mesh's box: a filter can only remove hits.
    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.mesh.as_ref().bounding_box()
    }

    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        let mesh = self.mesh.as_ref();
        kernel!(mesh, |lanes, L| mesh.any::<L>(
            lanes,
            ray,
            ray_t,
            &mut (),
            |p, c| self.accepts(ray, p, c)
        ))
    }
}
