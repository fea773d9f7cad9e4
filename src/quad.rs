use glam::DVec3;

use crate::{
    Aabb, GeometryError, HitRecord, Hittable, Interior, Interval, MaterialId, Parallelogram, Plane,
    Ray, Sampling,
};

/// A planar shape: a [`Plane`] finds `(t, alpha, beta)`, an [`Interior`] predicate decides
/// whether the point belongs to the shape. With the default [`Parallelogram`] it is the
/// book's quad, with corners `q`, `q + u`, `q + v`, `q + u + v`.
///
/// Edges are inclusive and watertight: the built-in shapes also accept points whose
/// computed coordinates fall outside by less than their rounding-error bound
/// ([`Plane::coordinate_error`]), so a ray through an edge shared by two shapes hits at
/// least one of them. Wrap a shape in [`Exact`](crate::Exact) to test it exactly instead.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Hittable, Interval, MaterialId, Quad, Ray, Ring, Triangle};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// let wall = Quad::new(DVec3::new(-2.0, -2.0, 0.0), DVec3::new(4.0, 0.0, 0.0), DVec3::new(0.0, 4.0, 0.0))?
///     .with_material(MaterialId(1));
/// let tri = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, Triangle)?;
/// let ring = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, Ring::new(0.5)?)?;
///
/// let ray = Ray::new(DVec3::new(0.1, 0.1, 5.0), DVec3::new(0.0, 0.0, -1.0));
/// let hit = wall.hit(&ray, Interval::new(0.0, f64::INFINITY)).unwrap();
/// assert_eq!((hit.t, hit.material), (5.0, MaterialId(1)));
/// assert!(tri.hit(&ray, Interval::new(0.0, f64::INFINITY)).is_some());
/// assert!(ring.hit(&ray, Interval::new(0.0, f64::INFINITY)).is_none()); // in the hole
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad<S = Parallelogram> {
    plane: Plane,
    shape: S,
    bbox: Aabb,
    sampling: Sampling,
}

impl Quad<Parallelogram> {
    /// The parallelogram with corner `q` and edges `u`, `v`.
    ///
    /// # Errors
    /// As [`Plane::new`].
    pub fn new(q: DVec3, u: DVec3, v: DVec3) -> Result<Self, GeometryError> {
        Self::with_interior(q, u, v, Parallelogram)
    }
}

impl<S: Interior> Quad<S> {
    /// The part of the plane through `q` spanned by `u`, `v` that `shape` accepts.
    ///
    /// # Errors
    /// As [`Plane::new`].
    pub fn with_interior(q: DVec3, u: DVec3, v: DVec3, shape: S) -> Result<Self, GeometryError> {
        let plane = Plane::new(q, u, v)?;
        let bbox = shape.bounding_box(&plane);
        Ok(Self {
            plane,
            shape,
            bbox,
            sampling: Sampling::default(),
        })
    }

    /// The same shape with material `material`.
    #[inline]
    #[must_use]
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.plane = self.plane.with_material(material);
        self
    }

    /// The same shape, sampled as a light by `sampling` (see [`Sampling`]; the default
    /// samples rectangles and triangles by solid angle where that is accurate).
    #[inline]
    #[must_use]
    pub fn with_sampling(mut self, sampling: Sampling) -> Self {
        self.sampling = sampling;
        self
    }

    /// How the shape is sampled as a light.
    #[inline]
    #[must_use]
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// The plane the shape lies on.
    #[inline]
    #[must_use]
    pub fn plane(&self) -> &Plane {
        &self.plane
    }

    /// The interior predicate.
    #[inline]
    #[must_use]
    pub fn shape(&self) -> &S {
        &self.shape
    }
}

impl<S: Interior> Hittable for Quad<S> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let hit = self.plane.intersect(ray, ray_t)?;
        // Outside by the computed coordinates: a hit all the same if the exact ones could be
        // inside (watertight edges), for shapes that widen.
        if !self.shape.contains(hit.alpha, hit.beta) {
            if !self.shape.widens() {
                return None;
            }
            // An error bound that overflows says nothing: such a point (coordinates near
            // f64::MAX) is no hit.
            let error = self.plane.coordinate_error(ray, &hit);
            if !error.is_finite()
                || !self
                    .shape
                    .contains_within(hit.alpha, hit.beta, error.x, error.y)
            {
                return None;
            }
        }
        Some(
            self.plane
                .hit_record(ray, hit, self.shape.uv(hit.alpha, hit.beta)),
        )
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }
}
