//! [`Plane`]: the infinite plane through `q` spanned by `u` and `v`, its ray crossing as
//! `(t, alpha, beta)` ([`PlaneHit`]), and the region where the exact crossing can be
//! ([`CrossingRegion`]), which the planar shapes decide by.

use glam::{DVec2, DVec3};

use crate::math::{UNIT_ROUNDOFF, gamma, l1, unit_and_length};
use crate::{Aabb, GeometryError, HitRecord, Hittable, Interval, MaterialId, Ray};

/// The least `|n.d|` taken as it is: below it, a direction of extreme length is rescaled
/// first. `n.d` sums three products, and one of them may have underflowed (losing bits)
/// where `d` is tiny, though the sum is a normal number: found by the direction-length
/// property test, a plane's `t` one ulp off along `d * 2^-1016`. Each lost product is off
/// by at most `2^-1075`; a sum of at least `2^-960` has ulps of `2^-1012` and more, so
/// such an error cannot move its rounding (but for a tie within `2^-1075`), and the `t`
/// is the one the rescaled ray gives, times the power of two, exactly.
const DENOM_NORMAL: f64 = f64::from_bits((1023 - 960) << 52); // 2^-960

/// The plane's [`tolerance`](Plane::tolerance), relative to its corners' magnitude `M`:
/// 2^-48, that is `32 u_r M`. A corner computed as a user computes it, `offset + R * c` (a
/// product of a matrix and a vector, then a sum) or `q + u`, is off by at most `gamma(4)`
/// of `|offset_i| + |c|_1` per coordinate; two copies of one corner computed apart differ by
/// twice that, `sqrt(3)` times that in distance: `8 sqrt(3) u_r` (about `14 u_r`) of a
/// magnitude that can reach twice `M` (the sum of magnitudes against the largest
/// coordinate), `28 u_r M` in all, within the tolerance.
const TOLERANCE: f64 = 1.0 / (1u64 << 48) as f64;

/// Where a ray meets a plane: the ray parameter `t` and the plane coordinates of the point,
/// `q + alpha * u + beta * v`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PlaneHit {
    /// Ray parameter, in units of the ray's direction.
    pub t: f64,
    /// Coordinate along `u`.
    pub alpha: f64,
    /// Coordinate along `v`.
    pub beta: f64,
}

/// The infinite plane through `q` spanned by `u` and `v`; its outward normal is along
/// `u x v`. The ground the planar shapes ([`Quad`](crate::Quad)) stand on, and a
/// [`Hittable`] itself.
///
/// ```
/// use hitkit::{glam::DVec3, Interval, Plane, Ray};
/// let ground = Plane::new(DVec3::ZERO, DVec3::Z, DVec3::X).unwrap(); // normal +y
/// let ray = Ray::new(DVec3::new(3.0, 2.0, 1.0), DVec3::new(1.0, -1.0, 0.0));
/// let hit = ground.intersect(&ray, Interval::FORWARD).unwrap();
/// assert_eq!((hit.t, hit.alpha, hit.beta), (2.0, 1.0, 5.0)); // the point (5, 0, 1)
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub(super) q: DVec3,
    pub(super) u: DVec3,
    pub(super) v: DVec3,
    /// The unit normal along `u x v`; unit length keeps `t` free of overflow for large
    /// edges and of underflow for small ones.
    pub(super) normal: DVec3,
    /// `v x w` and `w x u`, with `w = (u x v) / |u x v|^2`: the plane coordinates of a
    /// point `p - q` are `alpha = w.(p x v) = p.(v x w)` and `beta = w.(u x p) = p.(w x u)`,
    /// two dot products per hit instead of two cross products and two dot products.
    pub(super) to_alpha: DVec3,
    pub(super) to_beta: DVec3,
    /// `(|to_alpha|_1, |to_beta|_1)`: what a world-space distance is at most in `alpha`
    /// and `beta`.
    pub(super) coordinate_scale: DVec2,
    /// The relative error of the computed `to_alpha`, `to_beta` (and of the direction of
    /// the computed normal, which is smaller): `2 gamma(2) (1 + 1/s) + 2 u`, `s` the sine
    /// between `u` and `v` (bounded from below by `|u x v|_2 / (|u|_1 |v|_1)`).
    pub(super) frame_error: f64,
    /// The world-space distance shapes on this plane are widened by ([`Plane::tolerance`]).
    pub(super) tolerance: f64,
    /// `|u|_1 + |v|_1`: how far from `q` the points of the built-in shapes lie, at most.
    pub(super) extent: f64,
    /// The constants of the quick clear decision ([`Plane::clearly_quick`]).
    pub(super) quick: Quick,
    pub(super) material: MaterialId,
}

impl Plane {
    /// The plane through `q` spanned by `u` and `v`.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite input,
    /// [`GeometryError::ZeroVector`] for a zero `u` or `v`, [`GeometryError::ParallelEdges`]
    /// when `u` and `v` are parallel to within rounding, and [`GeometryError::OutOfRange`]
    /// when their lengths are so large or small that `u x v` overflows or underflows.
    pub fn new(q: DVec3, u: DVec3, v: DVec3) -> Result<Self, GeometryError> {
        for (what, x) in [("q", q), ("u", u), ("v", v)] {
            if !x.is_finite() {
                return Err(GeometryError::NonFinite { what });
            }
        }
        for (what, x) in [("u", u), ("v", v)] {
            if x == DVec3::ZERO {
                return Err(GeometryError::ZeroVector { what });
            }
        }
        let (u_len, v_len) = (unit_and_length(u).1, unit_and_length(v).1);
        let n = u.cross(v);
        if !((u_len * v_len).is_normal() && n.is_finite()) {
            return Err(GeometryError::OutOfRange);
        }
        let (normal, n_len) = unit_and_length(n);
        // Each component of the computed u x v is off by at most gamma(2) (|u_j v_k| +
        // |u_k v_j|), so by at most sqrt(2) gamma(2) |u| |v| in length. When the whole cross
        // product is within twice that, rounding may account for half of it: its direction,
        // the plane's normal, is not known, and u and v count as parallel.
        if n_len <= 2.0 * core::f64::consts::SQRT_2 * gamma(2) * u_len * v_len {
            return Err(GeometryError::ParallelEdges);
        }
        if !n_len.is_normal() {
            return Err(GeometryError::OutOfRange);
        }
        let (to_alpha, to_beta) = (v.cross(normal / n_len), (normal / n_len).cross(u));
        // 1/s = |u| |v| / |u x v| <= |u|_1 |v|_1 / |u x v|_2.
        let inv_s = (unit_and_length(u).1 / n_len) * unit_and_length(v).1;
        let frame_error = (2.0 * gamma(2) * (1.0 + inv_s) + 2.0 * UNIT_ROUNDOFF) * (1.0 + gamma(4));
        let coordinate_scale = DVec2::new(l1(to_alpha), l1(to_beta));
        // Every corner (or a disk's extreme point) is q + (+-1 or 0) u + (+-1 or 0) v.
        let magnitude = q.abs().max_element() + u.abs().max_element() + v.abs().max_element();
        let tolerance = TOLERANCE * magnitude;
        let extent = l1(u) + l1(v);
        if !(coordinate_scale.is_finite()
            && frame_error.is_finite()
            && tolerance.is_finite()
            && extent.is_finite())
        {
            return Err(GeometryError::OutOfRange);
        }
        Ok(Self {
            q,
            u,
            v,
            normal,
            to_alpha,
            to_beta,
            coordinate_scale,
            frame_error,
            tolerance,
            extent,
            quick: Quick::new(frame_error, frame_error * extent, tolerance),
            material: MaterialId::default(),
        })
    }

    /// The same plane with material `material`.
    #[inline]
    #[must_use]
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.material = material;
        self
    }

    /// The corner (or centre, for disks) `q`.
    #[inline]
    #[must_use]
    pub fn q(&self) -> DVec3 {
        self.q
    }

    /// The first edge vector.
    #[inline]
    #[must_use]
    pub fn u(&self) -> DVec3 {
        self.u
    }

    /// The second edge vector.
    #[inline]
    #[must_use]
    pub fn v(&self) -> DVec3 {
        self.v
    }

    /// The unit normal along `u x v`.
    #[inline]
    #[must_use]
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// `|u x v|`: the area of the parallelogram spanned by `u` and `v`, which is what a unit
    /// of area in `(alpha, beta)` space covers on the plane. Computed on each call, as
    /// `normal . (u x v)`, to within a few ulps; positive for every plane [`Plane::new`]
    /// accepts.
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Plane};
    /// let plane = Plane::new(DVec3::ZERO, DVec3::X * 2.0, DVec3::new(1.0, 3.0, 0.0)).unwrap();
    /// assert_eq!(plane.uv_area(), 6.0);
    /// ```
    #[inline]
    #[must_use]
    pub fn uv_area(&self) -> f64 {
        self.normal.dot(self.u.cross(self.v))
    }

    /// The material id carried into hit records.
    #[inline]
    #[must_use]
    pub fn material(&self) -> MaterialId {
        self.material
    }

    /// Where the ray meets the plane with `t` in the closed interval `ray_t`, or `None`
    /// (parallel ray, out of range, or an invalid ray).
    ///
    /// There is no parallel-ray epsilon: a ray is parallel only when `n . d` is exactly 0,
    /// and a grazing ray hits wherever its `t` is finite and in range. The forms used are
    /// the well-conditioned ones, `t = n.(q - o) / n.d` (`n` the unit normal) and
    /// `p - q = (o - q) + t d`, so a
    /// scene far from the origin loses no more accuracy than its own size demands.
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray, ray_t: Interval) -> Option<PlaneHit> {
        self.intersect_as::<true>(ray, ray_t)
    }

    /// [`Plane::intersect`], which rescales a direction of extreme length where `RESCALE`
    /// (the rescaled ray is taken as it is: no recursion, so the common path inlines).
    #[inline(always)]
    pub(super) fn intersect_as<const RESCALE: bool>(
        &self,
        ray: &Ray,
        ray_t: Interval,
    ) -> Option<PlaneHit> {
        let numerator = self.normal.dot(self.q - ray.origin);
        let denom = self.normal.dot(ray.direction);
        // The quotient is negative exactly when the signs differ: a plane behind a ray whose
        // range starts at 0 or later is rejected before the (slow) division.
        if ray_t.min >= 0.0 && numerator * denom < 0.0 {
            return None;
        }
        let t = numerator / denom;
        // denom == 0 (parallel) gives an infinite or NaN t; an overflowed denom a false 0.
        // (Float comparisons, not `is_finite`: this is the hottest branch of a render.)
        let finite = (t.abs() < f64::INFINITY) & (denom.abs() < f64::INFINITY);
        if !(finite && denom.abs() >= DENOM_NORMAL) {
            // Where `n.d` or `t` left the normal range, a direction of extreme length is
            // taken along the same ray with an ordinary one (the scaling is exact).
            if RESCALE && let Some(rescaled) = ray.rescaled() {
                return self.intersect_rescaled(rescaled, ray_t);
            }
            if !finite {
                return None;
            }
        }
        if !ray_t.contains(t) {
            return None;
        }
        let p = (ray.origin - self.q) + t * ray.direction;
        let alpha = p.dot(self.to_alpha);
        let beta = p.dot(self.to_beta);
        // Non-finite coordinates mean a non-finite ray (or an overflow): no hit, no NaN.
        ((alpha.abs() < f64::INFINITY) & (beta.abs() < f64::INFINITY)).then_some(PlaneHit {
            t,
            alpha,
            beta,
        })
    }

    /// The world-space distance by which shapes on this plane widen, so that neighbours
    /// whose shared corners were rounded separately (a rotated box built face by face in
    /// world coordinates, say) leave no crack between them: `2^-48` (32 units of roundoff)
    /// of `|q|_inf + |u|_inf + |v|_inf`, which bounds every corner's largest coordinate.
    /// Computing a corner such as `offset + R * corner` rounds each coordinate by a few
    /// units of roundoff of that magnitude, so two separately computed copies of a corner
    /// stay well within it.
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Plane};
    /// let plane = Plane::new(DVec3::new(1e6, 0.0, 0.0), DVec3::X, DVec3::Y).unwrap();
    /// assert_eq!(plane.tolerance(), (1e6 + 2.0) / 2f64.powi(48));
    /// ```
    #[inline]
    #[must_use]
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The hit record for a hit found by [`Plane::intersect`], with surface coordinates
    /// `uv`. The point is `q + alpha u + beta v`, which lies on the plane to within
    /// rounding whatever the error of `alpha` and `beta`; its error bound is that rounding.
    /// `None` where the point overflows (coordinates near `f64::MAX`).
    #[inline(always)]
    #[must_use]
    pub fn hit_record(&self, ray: &Ray, hit: PlaneHit, uv: DVec2) -> Option<HitRecord> {
        let (au, bv) = (hit.alpha * self.u, hit.beta * self.v);
        let point = self.q + (au + bv);
        // Two products, one sum, one more sum: gamma(3) of the summed magnitudes. And the
        // point is on the exact plane, which the computed normal (that `intersect` and
        // `spawn_ray` go by) is tilted from by up to the frame error: at `au + bv` from `q`,
        // a height of that times `|au + bv|`, which every coordinate's bound covers.
        let tilt = self.frame_error * (au.abs() + bv.abs()).element_sum();
        let point_error = gamma(3) * (self.q.abs() + au.abs() + bv.abs()) + DVec3::splat(tilt);
        (point.is_finite() && point_error.is_finite()).then(|| {
            HitRecord::new(ray, hit.t, point, self.normal)
                .with_point_error(point_error)
                .with_uv(uv)
                .with_material(self.material)
        })
    }
}

impl Hittable for Plane {
    /// `uv` is `(alpha, beta)`, unbounded.
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        // As for a quad: t kept in the box's span along the whole ray, then compared with
        // ray_t, so that it never depends on ray_t.max.
        let mut hit = self.intersect(ray, Interval::new(ray_t.min, f64::INFINITY))?;
        hit.t = self.bounding_box().clamp_hit(ray, hit.t)?;
        if !ray_t.contains(hit.t) {
            return None;
        }
        self.hit_record(ray, hit, DVec2::new(hit.alpha, hit.beta))
    }

    /// A thin slab, infinite along the other two axes, when the normal is exactly an axis
    /// (as for any plane spanned by two axis-aligned vectors); otherwise
    /// [`Aabb::UNIVERSE`]. A normal even slightly off an axis makes the plane climb
    /// through every coordinate of that axis far enough out, so no slab could hold it.
    fn bounding_box(&self) -> Aabb {
        let axis = match (
            self.normal.x != 0.0,
            self.normal.y != 0.0,
            self.normal.z != 0.0,
        ) {
            (true, false, false) => 0,
            (false, true, false) => 1,
            (false, false, true) => 2,
            _ => return Aabb::UNIVERSE,
        };
        let (mut min, mut max) = (Aabb::UNIVERSE.min(), Aabb::UNIVERSE.max());
        min[axis] = self.q[axis];
        max[axis] = self.q[axis];
        Aabb::new(min, max)
    }
}

/// The constants of [`Plane::clearly_quick`], which bounds a crossing's error terms by
/// multiples of `m = |q - o|_1 + |t| |d|_1` alone: `height` bounds the reach's numerator
/// and its `t` term (`numerator + gamma(2) |t| c`, the tolerance left out) per unit of
/// `m`; the region's reach from its centre, times the slack and over `|d|_1 s` (`s` the
/// coordinate scale), is at most `rate m + fixed`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Quick {
    pub(super) height: f64,
    pub(super) rate: f64,
    pub(super) fixed: f64,
    /// `gamma(3) + e`: the slack is `c - slope d1`.
    pub(super) slope: f64,
}

impl Quick {
    /// Derivation, against [`Plane::clearly`]'s terms (see [`Parts`](super::crossing::Parts)): `P = |p|_1` is at
    /// most `(1 + gamma(8)) m` (`p = t d - (q - o)` rounds twice per coordinate, its
    /// norm twice more, and the computed `m` is within `gamma(3)` of `a + b`), and
    /// `|t| c <= (1 + gamma(5)) b` (`c = |n.d|` with `|n| = 1` to within rounding). So
    /// the numerator with its `t` term is at most `(gamma(4) + gamma(3) + 2 e)` of `m`,
    /// and `world` at most `gamma(6) m + frame_reach + tolerance`; `height` is the first,
    /// grown by `1 + gamma(8)`. `clearly` asks `(dist - fixed') slack > rate'` with
    /// `rate' = 2 (1 + gamma(10)) d1 s (height m + T)` and a term `2 world s slack` in
    /// `fixed'`, where `slack <= c <= (1 + gamma(10)) d1`: both fit in
    /// `2 (1 + gamma(10)) d1 s ((height + gamma(6)) m + frame_reach + 2 T)`.
    pub(super) fn new(frame_error: f64, frame_reach: f64, tolerance: f64) -> Self {
        let height = (gamma(4) + gamma(3) + 2.0 * frame_error) * (1.0 + gamma(8));
        let grow = 2.0 * (1.0 + gamma(10));
        Self {
            height,
            rate: grow * (height + gamma(6)),
            fixed: grow * (frame_reach + 2.0 * tolerance),
            slope: gamma(3) + frame_error,
        }
    }
}
