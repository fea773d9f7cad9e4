//! hitkit 0.1.0's default quad test (commit 2a10e80), kept here only to be measured: the
//! library no longer has it. A point whose computed `(alpha, beta)` fell outside the shape
//! was accepted all the same if it lay within `Plane::coordinate_error` of it, a bound on
//! the rounding of the coordinates that grows as `1 / |n.d|`: grazing rays beside a shape
//! were hit, far out of it, and shapes accepted points their own bounding box rejected.
//!
//! The formulas are 0.1.0's, unchanged: `coordinate_error` from `src/plane.rs`,
//! `contains_within` of `Parallelogram` and `Triangle` and their bounding boxes from
//! `src/interior.rs`, and `Quad::hit` from `src/quad.rs`, on top of today's public
//! `hitkit::Plane` (whose `intersect` is 0.1.0's). The plane's private `to_alpha` and
//! `to_beta` are recomputed as 0.1.0's `Plane::new` computed them. One difference: the
//! record comes from today's `Plane::hit_record`, whose point is 0.1.0's
//! `q + (alpha u + beta v)` but whose error bound also covers the tilt of the computed
//! normal (which only moves the origins of spawned rays, by a few ulps more).

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Aabb, GeometryError, HitRecord, Hittable, Interval, Plane, PlaneHit, Ray};

/// Unit roundoff of `f64`.
const UNIT_ROUNDOFF: f64 = f64::EPSILON * 0.5;

/// `gamma(n) = n u / (1 - n u)` (0.1.0's `math::gamma`).
const fn gamma(n: u32) -> f64 {
    let nu = n as f64 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

/// `|v|`, computed as 0.1.0's `unit_and_length` did: scaled by the power of two that brings
/// the largest component into `[1, 2)`, so that the squares neither overflow nor underflow.
fn length(v: DVec3) -> f64 {
    let exponent = ((v.abs().max_element().to_bits() >> 52) & 0x7ff) as i64 - 1023;
    let scale = f64::from_bits(((1023 - exponent.clamp(-1022, 1022)) as u64) << 52);
    (v * scale).length() / scale
}

/// Which interior the widened test decides for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WidenedShape {
    /// `0 <= alpha <= 1`, `0 <= beta <= 1`.
    Parallelogram,
    /// `alpha >= 0`, `beta >= 0`, `alpha + beta <= 1`.
    Triangle,
}

/// A quad decided as hitkit 0.1.0's default decided it.
#[derive(Clone, Copy, Debug)]
pub struct Widened {
    plane: Plane,
    /// `v x w` and `w x u`, `w = n / |u x v|` (`n` the unit normal), as 0.1.0's plane kept
    /// them: `alpha = (p - q).(v x w)`, `beta = (p - q).(w x u)`.
    to_alpha: DVec3,
    to_beta: DVec3,
    shape: WidenedShape,
    bbox: Aabb,
}

impl Widened {
    /// The shape with corner `q` and edges `u`, `v`.
    ///
    /// # Errors
    /// As [`Plane::new`].
    pub fn new(q: DVec3, u: DVec3, v: DVec3, shape: WidenedShape) -> Result<Self, GeometryError> {
        let plane = Plane::new(q, u, v)?;
        let w = plane.normal() / length(u.cross(v));
        // 0.1.0's `corner_rounding`: the boxes hold the exact shape, not only its rounded
        // corners.
        let rounding = gamma(2) * (q.abs() + u.abs() + v.abs());
        let corners = match shape {
            WidenedShape::Parallelogram => vec![q, q + u, q + v, q + u + v],
            WidenedShape::Triangle => vec![q, q + u, q + v],
        };
        let tight = Aabb::from_points(&corners);
        Ok(Self {
            plane,
            to_alpha: v.cross(w),
            to_beta: w.cross(u),
            shape,
            bbox: Aabb::new(tight.min() - rounding, tight.max() + rounding),
        })
    }

    /// 0.1.0's `Interior::contains`.
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        match self.shape {
            WidenedShape::Parallelogram => {
                (0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta)
            }
            WidenedShape::Triangle => alpha >= 0.0 && beta >= 0.0 && alpha + beta <= 1.0,
        }
    }

    /// 0.1.0's `Interior::contains_within`: within `err_alpha` and `err_beta` of the shape.
    fn contains_within(&self, alpha: f64, beta: f64, err_alpha: f64, err_beta: f64) -> bool {
        match self.shape {
            WidenedShape::Parallelogram => {
                (-err_alpha..=1.0 + err_alpha).contains(&alpha)
                    && (-err_beta..=1.0 + err_beta).contains(&beta)
            }
            WidenedShape::Triangle => {
                // The sum's own rounding (`u_r |alpha + beta|`) is added to the slack.
                let slack = err_alpha + err_beta + gamma(2) * (alpha.abs() + beta.abs());
                alpha >= -err_alpha && beta >= -err_beta && alpha + beta <= 1.0 + slack
            }
        }
    }

    /// 0.1.0's `Plane::coordinate_error`: bounds on the rounding errors of `hit.alpha` and
    /// `hit.beta` (see its documentation at 2a10e80). With `a = |q - o|_1`,
    /// `b = |t| |d|_1`, `P = |p|_1`, `1/c <= |d|_1 / |n.d|`, `s` the sine between `u` and
    /// `v`: `e = gamma(5) (a + b) (1 + 1/c) + P (3 gamma(4) + 2 gamma(2) / s +
    /// (2 gamma(2) / s + 2 u_r) / c)`, times `|v x w|_1` and `|w x u|_1`.
    fn coordinate_error(&self, ray: &Ray, hit: &PlaneHit) -> DVec2 {
        let l1 = |v: DVec3| v.abs().element_sum();
        let q_minus_o = self.plane.q() - ray.origin;
        let p = hit.t * ray.direction - q_minus_o;
        let d = l1(ray.direction);
        let (a, b, big_p) = (l1(q_minus_o), hit.t.abs() * d, l1(p));
        let inv_c = d / self.plane.normal().dot(ray.direction).abs();
        // |v x w| = 1 / (|u| s) and |w x u| = 1 / (|v| s), so 1 / s = |u| |v x w|.
        let (inv_us, inv_vs) = (l1(self.to_alpha), l1(self.to_beta));
        let inv_s = l1(self.plane.u()) * inv_us;
        let e = gamma(5) * (a + b) * (1.0 + inv_c)
            + big_p
                * (3.0 * gamma(4)
                    + 2.0 * gamma(2) * inv_s
                    + (2.0 * gamma(2) * inv_s + 2.0 * gamma(1)) * inv_c);
        // The bound's own arithmetic rounds too: a few more ulps.
        e * (1.0 + gamma(8)) * DVec2::new(inv_us, inv_vs)
    }
}

impl Hittable for Widened {
    /// 0.1.0's `Quad::hit`: the plane's crossing in `ray_t`, accepted if its coordinates are
    /// inside, or outside by less than their error bound.
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let hit = self.plane.intersect(ray, ray_t)?;
        if !self.contains(hit.alpha, hit.beta) {
            // An error bound that overflows says nothing: such a point (coordinates near
            // f64::MAX) is no hit.
            let error = self.coordinate_error(ray, &hit);
            if !error.is_finite() || !self.contains_within(hit.alpha, hit.beta, error.x, error.y) {
                return None;
            }
        }
        self.plane
            .hit_record(ray, hit, DVec2::new(hit.alpha, hit.beta))
    }

    /// 0.1.0's box: the corners' box grown by their rounding.
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }
}
