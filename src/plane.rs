use glam::{DVec2, DVec3};

use crate::math::{gamma, unit_and_length};
use crate::{Aabb, GeometryError, HitRecord, Hittable, Interval, MaterialId, Ray};

/// Where a ray meets a plane: the ray parameter `t` and the plane coordinates of the point,
/// `q + alpha * u + beta * v`.
#[derive(Clone, Copy, Debug, PartialEq)]
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
/// let hit = ground.intersect(&ray, Interval::new(0.0, f64::INFINITY)).unwrap();
/// assert_eq!((hit.t, hit.alpha, hit.beta), (2.0, 1.0, 5.0)); // the point (5, 0, 1)
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    q: DVec3,
    u: DVec3,
    v: DVec3,
    /// The unit normal along `u x v`; unit length keeps `t` free of overflow for large
    /// edges and of underflow for small ones.
    normal: DVec3,
    /// `v x w` and `w x u`, with `w = (u x v) / |u x v|^2`: the plane coordinates of a
    /// point `p - q` are `alpha = w.(p x v) = p.(v x w)` and `beta = w.(u x p) = p.(w x u)`,
    /// two dot products per hit instead of two cross products and two dot products.
    to_alpha: DVec3,
    to_beta: DVec3,
    material: MaterialId,
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
        Ok(Self {
            q,
            u,
            v,
            normal,
            to_alpha: v.cross(normal / n_len),
            to_beta: (normal / n_len).cross(u),
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
        if !(finite && ray_t.contains(t)) {
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

    /// Bounds on the rounding errors of `hit.alpha` and `hit.beta` as [`Plane::intersect`]
    /// computed them for `ray`: the exact intersection of the ray with the plane has
    /// coordinates within `(x, y)` of them. Shapes widen their edges by it, so that a ray
    /// through an edge shared by two shapes finds at least one of them.
    ///
    /// Derivation (first order in the unit roundoff `u_r`, constants rounded up; `|.|_1`
    /// bounds the Euclidean norm from above, so no square roots are needed):
    /// `t = n.(q - o) / n.d` has relative error at most
    /// `(gamma(4) |q - o| + gamma(3) t |d|) / (t |d| c) + u_r`, `c` the cosine of incidence;
    /// `p = (o - q) + t d` adds `gamma(2) (|q - o| + t |d|)`; the computed normal is tilted
    /// by up to `1.5 gamma(2) / s + 2 u_r` (`s` the sine between `u` and `v`), which moves
    /// the hit by that times `|p| / c`; and `alpha = p.(v x w)` rounds by `gamma(3)` of
    /// `|p| |v x w|` while `v x w` itself carries `2 gamma(2) (1 + 1 / s) + 2 u_r` of
    /// relative error. An in-plane position error `e` is `e |v x w| = e / (|u| s)` in
    /// alpha. With `a = |q - o|`, `b = t |d|`, `P = |p|` and `1 / c <= |d|_1 / |n.d|`:
    /// `e = gamma(5) (a + b) (1 + 1/c) + P (3 gamma(4) + 2 gamma(2) / s + (2 gamma(2) / s + 2 u_r) / c)`.
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Interval, Plane, Ray};
    /// let plane = Plane::new(DVec3::splat(1e9), DVec3::X, DVec3::Y).unwrap();
    /// let ray = Ray::new(DVec3::new(1e9 + 0.5, 1e9 + 0.5, 1e9 + 1.0), DVec3::NEG_Z);
    /// let hit = plane.intersect(&ray, Interval::UNIVERSE).unwrap();
    /// let error = plane.coordinate_error(&ray, &hit);
    /// assert!(error.x > 0.0 && error.x < 1e-6 && error.y < 1e-6);
    /// ```
    #[must_use]
    pub fn coordinate_error(&self, ray: &Ray, hit: &PlaneHit) -> DVec2 {
        let l1 = |v: DVec3| v.abs().element_sum();
        let q_minus_o = self.q - ray.origin;
        let p = hit.t * ray.direction - q_minus_o;
        let d = l1(ray.direction);
        let (a, b, big_p) = (l1(q_minus_o), hit.t.abs() * d, l1(p));
        let inv_c = d / self.normal.dot(ray.direction).abs();
        // |v x w| = 1 / (|u| s) and |w x u| = 1 / (|v| s), so 1 / s = |u| |v x w|.
        let (inv_us, inv_vs) = (l1(self.to_alpha), l1(self.to_beta));
        let inv_s = l1(self.u) * inv_us;
        let e = gamma(5) * (a + b) * (1.0 + inv_c)
            + big_p
                * (3.0 * gamma(4)
                    + 2.0 * gamma(2) * inv_s
                    + (2.0 * gamma(2) * inv_s + 2.0 * gamma(1)) * inv_c);
        // The bound's own arithmetic rounds too: a few more ulps.
        e * (1.0 + gamma(8)) * DVec2::new(inv_us, inv_vs)
    }

    /// The hit record for a hit found by [`Plane::intersect`], with surface coordinates
    /// `uv`. The point is `q + alpha u + beta v`, which lies on the plane to within
    /// rounding whatever the error of `alpha` and `beta`; its error bound is that rounding.
    #[inline]
    #[must_use]
    pub fn hit_record(&self, ray: &Ray, hit: PlaneHit, uv: DVec2) -> HitRecord {
        let (au, bv) = (hit.alpha * self.u, hit.beta * self.v);
        let point = self.q + (au + bv);
        // Two products, one sum, one more sum: gamma(3) of the summed magnitudes.
        let point_error = gamma(3) * (self.q.abs() + au.abs() + bv.abs());
        HitRecord::new(
            ray,
            hit.t,
            point,
            point_error,
            self.normal,
            uv,
            self.material,
        )
    }
}

impl Hittable for Plane {
    /// `uv` is `(alpha, beta)`, unbounded.
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let hit = self.intersect(ray, ray_t)?;
        Some(self.hit_record(ray, hit, DVec2::new(hit.alpha, hit.beta)))
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
