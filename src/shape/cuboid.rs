//! [`Cuboid`]: the axis-aligned box as six quads (the book's `box`), watertight along its
//! edges because neighbouring faces share their corners bitwise.

use glam::DVec3;

use crate::record::{Found, Made};
use crate::{Aabb, GeometryError, HitRecord, Hittable, Interval, MaterialId, Quad, Ray};

/// The axis-aligned box with opposite corners `a` and `b`, as six [`Quad`]s with outward
/// normals (the book's `box(a, b, mat)`): a ray from outside hits it with `front_face`
/// true, a ray from inside with `front_face` false.
///
/// Turn or move it with [`Transformed`](crate::Transformed).
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Cuboid, Hittable, Interval, MaterialId, Ray};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// let block = Cuboid::new(DVec3::new(1.0, 0.0, -1.0), DVec3::new(-1.0, 2.0, 1.0))?
///     .with_material(MaterialId(3));
/// let down = Ray::new(DVec3::new(0.5, 5.0, 0.5), DVec3::new(0.0, -1.0, 0.0));
/// let hit = block.hit(&down, Interval::FORWARD).unwrap();
/// assert_eq!((hit.t, hit.normal, hit.front_face), (3.0, DVec3::Y, true));
/// assert_eq!(hit.material, MaterialId(3));
///
/// let out = Ray::new(DVec3::new(0.0, 1.0, 0.0), DVec3::X);
/// let hit = block.hit(&out, Interval::FORWARD).unwrap();
/// assert_eq!((hit.t, hit.normal, hit.front_face), (1.0, -DVec3::X, false));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    faces: [Quad; 6],
    bbox: Aabb,
    /// Whether a face's record could overflow (a box near `f64::MAX`): `find` then asks
    /// `hit`, which passes over such a face as the list of faces does.
    near_overflow: bool,
}

impl Cuboid {
    /// The box with opposite corners `a` and `b`, in any order.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite corner;
    /// [`GeometryError::InvalidParameter`] when `a` and `b` share a coordinate (a flat box:
    /// use a [`Quad`]); [`GeometryError::OutOfRange`] when an extent overflows, or when two
    /// are so small that a face's area underflows.
    pub fn new(a: DVec3, b: DVec3) -> Result<Self, GeometryError> {
        for (what, x) in [("a", a), ("b", b)] {
            if !x.is_finite() {
                return Err(GeometryError::NonFinite { what });
            }
        }
        let (min, max) = (a.min(b), a.max(b));
        let size = max - min;
        // Distinct floats never subtract to 0: only a shared coordinate gives a zero extent.
        if let Some(axis) = (0..3).find(|&axis| size[axis] == 0.0) {
            return Err(GeometryError::InvalidParameter {
                what: [
                    "cuboid extent along x",
                    "cuboid extent along y",
                    "cuboid extent along z",
                ][axis],
                value: 0.0,
                domain: "(0, inf)",
            });
        }
        if !size.is_finite() {
            return Err(GeometryError::OutOfRange);
        }
        let (dx, dy, dz) = (size * DVec3::X, size * DVec3::Y, size * DVec3::Z);
        let faces = [
            Quad::new(DVec3::new(min.x, min.y, max.z), dx, dy)?, // front, +z
            Quad::new(DVec3::new(max.x, min.y, max.z), -dz, dy)?, // right, +x
            Quad::new(DVec3::new(max.x, min.y, min.z), -dx, dy)?, // back, -z
            Quad::new(min, dz, dy)?,                             // left, -x
            Quad::new(DVec3::new(min.x, max.y, max.z), dx, -dz)?, // top, +y
            Quad::new(min, dx, dz)?,                             // bottom, -y
        ];
        // The faces' own boxes hold their corners' rounding (`min + size` need not be `max`).
        let bbox = faces
            .iter()
            .fold(Aabb::new(min, max), |b, f| b.union(&f.bounding_box()));
        Ok(Self {
            faces,
            bbox,
            near_overflow: bbox.near_overflow(),
        })
    }

    /// The same box with material `material` on every face.
    #[inline]
    #[must_use]
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.faces = self.faces.map(|f| f.with_material(material));
        self
    }

    /// The faces, outward normals `+z, +x, -z, -x, +y, -y` in that order (the book's).
    #[inline]
    #[must_use]
    pub fn faces(&self) -> &[Quad; 6] {
        &self.faces
    }
}

impl Hittable for Cuboid {
    /// The closest hit of the six faces (where faces meet, the earlier face's). Rays that
    /// miss the bounding box (which holds every face's own box, so it accepts whatever a
    /// face would) skip the six face tests.
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        if !self.bbox.hit(ray, ray_t) {
            return None;
        }
        self.faces.as_slice().hit(ray, ray_t)
    }

    /// The box of `a` and `b`, grown by the rounding of the faces' corners.
    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    #[inline]
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.bbox.hit(ray, ray_t) && self.faces.as_slice().occluded(ray, ray_t)
    }

    /// The closest face's crossing, that face's number (in [`Cuboid::faces`]'s order) in
    /// `part`.
    fn find(&self, ray: &Ray, ray_t: Interval, made: &mut Made) -> Option<Found> {
        if self.near_overflow {
            return self.hit(ray, ray_t).map(|hit| made.keep(hit));
        }
        if !self.bbox.hit(ray, ray_t) {
            return None;
        }
        // (Tried: the faces the ray enters by first, so that those it leaves by are
        // rejected as past the entry; more instructions in the port.)
        let mut closest: Option<Found> = None;
        for (face, quad) in self.faces.iter().enumerate() {
            let max = closest.map_or(ray_t.max, |c| c.t);
            if let Some(mut found) = quad.find(ray, Interval::new(ray_t.min, max), made)
                // Of crossings at exactly the same t, the earlier face's stands.
                && closest.is_none_or(|c| found.t < c.t)
            {
                found.part = face as u32;
                closest = Some(found);
            }
        }
        closest
    }

    /// `None` for a `found` naming no face.
    #[inline]
    fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
        self.faces
            .get(found.part as usize)?
            .record(ray, ray_t, found)
    }
}
