use glam::DVec3;

use crate::math::gamma;

use crate::{
    Aabb, GeometryError, HitRecord, Hittable, Interior, Interval, MaterialId, Meets, Parallelogram,
    Plane, PlaneHit, Ray, Sampling,
};

/// A planar shape: a [`Plane`] finds `(t, alpha, beta)`, an [`Interior`] predicate decides
/// whether the point belongs to the shape. With the default [`Parallelogram`] it is the
/// book's quad, with corners `q`, `q + u`, `q + v`, `q + u + v`.
///
/// Edges are inclusive and watertight. The built-in shapes decide by the region where the
/// ray's exact crossing with the plane can be ([`Plane::crossing_region`]): narrow across
/// the ray whatever its angle, long only along it. A shape wholly around the region is hit,
/// one clear of it is not, and only a ray that passes within rounding of an edge is decided
/// again, in double-double arithmetic. The shapes also widen by the plane's
/// [tolerance](Plane::tolerance) (a few ulps of the corners' magnitude, in world space), so
/// that a ray through an edge shared by two shapes hits one of them even where their
/// corners were rounded apart; and every hit's `t` lies within the quad's box's span, so a
/// [`Bvh`](crate::Bvh) finds exactly what a loop finds. See the crate's contract. Wrap a
/// shape in [`Exact`](crate::Exact) to decide at the computed crossing alone.
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
        let shape_box = shape.bounding_box(&plane);
        let bbox = shape_box.grown(DVec3::splat(reach_beyond(&plane)));
        if shape_box.is_bounded() && !bbox.is_bounded() {
            return Err(GeometryError::OutOfRange);
        }
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

/// How far the box of a quad reaches beyond its shape, per coordinate: the plane's
/// [tolerance](Plane::tolerance) and the frame's own error at the shape (a world-space
/// distance, so per coordinate too), and a few ulps of itself. A ray that passes
/// within the tolerance of the shape (the widening that closes gaps between neighbours
/// whose corners were rounded apart, across the ray or along it) meets that box; what the
/// region's widening in `(alpha, beta)` would accept beyond it (at the acute corners of a
/// sliver, say) the box cuts off, since every hit is kept within the box's span.
fn reach_beyond(plane: &Plane) -> f64 {
    (plane.tolerance() + plane.frame_reach()) * (1.0 + gamma(4))
}

impl<S: Interior> Hittable for Quad<S> {
    /// The reported `t` depends on the ray alone, never on `ray_t.max` (which a `Bvh` or a
    /// list lowers as it finds hits): it is decided, moved into the box's span along the
    /// whole ray, and only then compared with `ray_t`.
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let plane = &self.plane;
        // Whatever the decision below, the reported t is at least t - 3 reach (the refined
        // crossing's own reach is no larger than this one's): `crossing` rejects a t past
        // ray_t.max by more, and only that.
        let (mut hit, region) = plane.crossing(ray, ray_t)?;
        match self.shape.meets(&region) {
            Meets::Inside => {}
            Meets::Outside => return None,
            // Rounding in f64 cannot tell: ask again of the double-double crossing, whose
            // region is as narrow as the shape's own corners allow.
            Meets::Near(_) => {
                let (precise, region) = plane.refine(ray)?;
                hit = match self.shape.meets(&region) {
                    Meets::Inside => precise,
                    Meets::Near(s) => {
                        let at = region.at(s);
                        PlaneHit {
                            t: precise.t + s,
                            alpha: at.x,
                            beta: at.y,
                        }
                    }
                    Meets::Outside => return None,
                };
            }
        }
        // A t that rounding put before or past the box moves onto it, so that a Bvh (whose
        // boxes contain this one) finds every hit a loop over the shapes finds.
        hit.t = self.bbox.clamp_hit(ray, Interval::UNIVERSE, hit.t)?;
        if !ray_t.contains(hit.t) {
            return None;
        }
        plane.hit_record(ray, hit, self.shape.uv(hit.alpha, hit.beta))
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }
}
