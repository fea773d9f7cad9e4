//! [`Face`]: one triangle of a mesh, borrowed, as a [`Hittable`] of its own.

use glam::{DVec2, DVec3};

use super::intersect::Sheared;
use super::{TriangleMesh, face_box};
use crate::{Aabb, HitRecord, Hittable, Interval, Ray};

/// One face of a [`TriangleMesh`], as a [`Hittable`] of its own: exactly the decision and
/// the hit the mesh makes for that face, so that a loop over the faces finds what the
/// mesh's tree finds.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Hittable, Interval, Ray, TriangleMesh};
///
/// let mesh = TriangleMesh::new(&[DVec3::ZERO, DVec3::X, DVec3::Y], &[[0, 1, 2]]).unwrap();
/// let face = mesh.faces().next().unwrap();
/// let ray = Ray::new(DVec3::new(0.25, 0.5, 1.0), DVec3::NEG_Z);
/// let (hit, b) = face.hit_barycentric(&ray, Interval::FORWARD).unwrap();
/// assert_eq!((face.index(), hit.t), (0, 1.0));
/// assert_eq!(b, DVec3::new(0.25, 0.25, 0.5)); // the weights of the three corners
/// assert_eq!(hit.point, DVec3::new(0.25, 0.5, 0.0));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Face<'a> {
    pub(super) mesh: &'a TriangleMesh,
    pub(super) position: usize,
}

impl Face<'_> {
    /// The face's number in the list the mesh was built from.
    #[inline]
    #[must_use]
    pub fn index(&self) -> u32 {
        self.mesh.tree.order[self.position]
    }

    /// The face's three vertex indices, as the caller numbered the vertices.
    #[inline]
    #[must_use]
    pub fn indices(&self) -> [u32; 3] {
        self.mesh.triangles[self.position].map(|i| self.mesh.source[i as usize])
    }

    /// The face's three corners.
    #[inline]
    #[must_use]
    pub fn corners(&self) -> [DVec3; 3] {
        self.mesh.corners_at(self.position)
    }

    /// The normals given for the face's corners ([`TriangleMesh::with_normals`]), in the
    /// order of [`Face::corners`]; `None` for a mesh without them.
    #[inline]
    #[must_use]
    pub fn normals(&self) -> Option<[DVec3; 3]> {
        let normals = &self.mesh.normals;
        (!normals.is_empty())
            .then(|| self.mesh.triangles[self.position].map(|i| normals[i as usize]))
    }

    /// The texture coordinates given for the face's corners ([`TriangleMesh::with_uvs`]),
    /// in the order of [`Face::corners`]; `None` for a mesh without them.
    ///
    /// ```
    /// use hitkit::glam::{DVec2, DVec3};
    /// use hitkit::TriangleMesh;
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// let mesh = TriangleMesh::new(&[DVec3::ZERO, DVec3::X, DVec3::Y], &[[2, 0, 1]])?
    ///     .with_uvs(&[DVec2::ZERO, DVec2::X, DVec2::Y])?
    ///     .with_normals(&[DVec3::Z; 3])?;
    /// let face = mesh.faces().next().unwrap();
    /// assert_eq!(face.corners(), [DVec3::Y, DVec3::ZERO, DVec3::X]);
    /// assert_eq!(face.uvs(), Some([DVec2::Y, DVec2::ZERO, DVec2::X]));
    /// assert_eq!(face.normals(), Some([DVec3::Z; 3]));
    /// assert_eq!(mesh.uvs().len(), mesh.vertices().len());
    /// # Ok(())
    /// # }
    /// ```
    #[inline]
    #[must_use]
    pub fn uvs(&self) -> Option<[DVec2; 3]> {
        let uvs = &self.mesh.uvs;
        (!uvs.is_empty()).then(|| self.mesh.triangles[self.position].map(|i| uvs[i as usize]))
    }

    /// The hit and its barycentric coordinates: the weights of the three corners, each at
    /// least 0, summing to 1 to within rounding.
    #[must_use]
    pub fn hit_barycentric(&self, ray: &Ray, ray_t: Interval) -> Option<(HitRecord, DVec3)> {
        let sheared = Sheared::new(ray)?;
        let crossing = self
            .mesh
            .cross::<false>(&sheared, &mut None, ray, ray_t, self.position)?;
        let record = self
            .mesh
            .record_at(ray, self.position, crossing.t, crossing.barycentric())?;
        Some((record, crossing.barycentric()))
    }
}

impl Hittable for Face<'_> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.hit_barycentric(ray, ray_t).map(|(hit, _)| hit)
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        face_box(self.mesh.corners_at(self.position))
    }
}
