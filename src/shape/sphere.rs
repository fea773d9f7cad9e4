//! The sphere, with the careful quadratic of Ray Tracing Gems chapter 7 (Haines, Günther,
//! Akenine-Möller, "Precision Improvements for Ray/Sphere Intersection", 2019), and sampled
//! as a light by the cone it subtends.

use core::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

use crate::math::{acos, atan2, direction_scale, gamma, sin_cos, sqrt, unit_and_length};
use crate::record::{Found, Made};
use crate::sample::{reaching, toward_middle};
use crate::{Aabb, GeometryError, HitRecord, Hittable, Interval, MaterialId, PdfHittable, Ray};

/// A sphere: centre and radius. `uv` is `(phi / 2 pi, theta / pi)`, `phi` around the y axis
/// from -x (as the book's `get_sphere_uv`), `theta` from -y.
///
/// ```
/// use hitkit::{glam::DVec3, Hittable, Interval, Ray, Sphere};
/// let ball = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0).unwrap();
/// let hit = ball.hit(&Ray::new(DVec3::ZERO, DVec3::NEG_Z), Interval::FORWARD).unwrap();
/// assert_eq!((hit.t, hit.normal), (4.0, DVec3::Z));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    center: DVec3,
    radius: f64,
    material: MaterialId,
    /// Made once: every query clamps its roots to it.
    bbox: Aabb,
}

impl Sphere {
    /// The sphere of `radius` around `center`.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite input,
    /// [`GeometryError::InvalidParameter`] for a radius that is not positive, or whose
    /// square over- or underflows.
    pub fn new(center: DVec3, radius: f64) -> Result<Self, GeometryError> {
        if !center.is_finite() {
            return Err(GeometryError::NonFinite { what: "center" });
        }
        if !radius.is_finite() {
            return Err(GeometryError::NonFinite { what: "radius" });
        }
        if !(radius * radius).is_normal() || radius <= 0.0 {
            return Err(GeometryError::InvalidParameter {
                what: "sphere radius",
                value: radius,
                domain: "(1e-154, 1e154) roughly: positive, with a representable square",
            });
        }
        let r = DVec3::splat(radius);
        // `center ± r` rounds once: a rounding's worth of room keeps the box conservative.
        let bbox = Aabb::new(center - r, center + r).grown(gamma(1) * (center.abs() + r));
        Ok(Self {
            center,
            radius,
            material: MaterialId::default(),
            bbox,
        })
    }

    /// The same sphere with material `material`.
    #[inline]
    #[must_use]
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.material = material;
        self
    }

    /// The centre.
    #[inline]
    #[must_use]
    pub fn center(&self) -> DVec3 {
        self.center
    }

    /// The radius.
    #[inline]
    #[must_use]
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The material.
    #[inline]
    #[must_use]
    pub fn material(&self) -> MaterialId {
        self.material
    }

    /// The two ray parameters where the ray meets the sphere, nearer first, or `None`.
    ///
    /// The discriminant comes from the squared distance between the centre and the ray's
    /// closest point, computed as a vector (`f - (f.d / d.d) d`, `f = o - center`) rather than
    /// as `b^2 - 4ac`, which cancels catastrophically for small spheres far away; the roots
    /// are `c / q` and `q / a` with `q = -(b + sign(b) sqrt(...))`, so neither subtracts
    /// nearly equal numbers (Ray Tracing Gems, chapter 7).
    #[must_use]
    pub(crate) fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        self.solve(ray)
            .filter(|&(near, far, ..)| near.is_finite() && far.is_finite())
            .map(|(near, far, ..)| (near, far))
    }

    /// The roots, nearer first, the vector from the centre to the ray's point closest to
    /// it, and half the chord as a vector along the ray (`sqrt(discriminant / d.d) d`): the
    /// point of a root is the closest point moved by minus (near) or plus (far) that, a
    /// form that stays accurate where `o + t d` cancels (a ray from far away).
    ///
    /// Where `d.d` leaves `[2^-128, 2^66]` (a direction of extreme length, whose square
    /// could over- or underflow), solved along the same ray with the direction scaled by a
    /// power of two (exactly: [`Ray::rescaled`], after which `d.d` is at least `2^-104`)
    /// and the roots scaled back, which may then pass f64's range (infinite, never NaN).
    #[inline]
    fn solve(&self, ray: &Ray) -> Option<(f64, f64, DVec3, DVec3)> {
        self.solve_as::<true>(ray)
    }

    /// [`Sphere::solve`], which rescales only where `RESCALE` (no recursion, so the
    /// common path inlines).
    #[inline(always)]
    fn solve_as<const RESCALE: bool>(&self, ray: &Ray) -> Option<(f64, f64, DVec3, DVec3)> {
        let f = ray.origin - self.center;
        let d = ray.direction;
        let a = d.dot(d);
        if RESCALE
            && !((1.0 / (1u128 << 64) as f64 / (1u128 << 64) as f64..=(1u128 << 66) as f64)
                .contains(&a))
            && let Some(rescaled) = ray.rescaled()
        {
            return self.solve_rescaled(rescaled);
        }
        let b = f.dot(d); // half of the usual b
        let closest = f - (b / a) * d;
        let r2 = self.radius * self.radius;
        let discriminant = r2 - closest.dot(closest);
        if discriminant.is_nan() || discriminant < 0.0 {
            return None; // a miss, or a NaN from an invalid ray
        }
        let c = f.dot(f) - r2;
        // One square root serves both: `sqrt(a disc) / a = sqrt(disc / a)`, the half chord
        // in units of `t`.
        let root = sqrt(a * discriminant);
        let q = -(b + b.signum() * root);
        let (t0, t1) = (c / q, q / a);
        let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        let half_chord = (root / a) * d;
        (!(near.is_nan() || far.is_nan()) && half_chord.is_finite())
            .then_some((near, far, closest, half_chord))
    }
}

impl Sphere {
    /// [`Hittable::find`]'s crossing, which `hit` records without a [`Made`] (it never
    /// makes one).
    fn crossing(&self, ray: &Ray, ray_t: Interval) -> Option<Found> {
        if !ray.is_valid() {
            return None;
        }
        let (near, far, closest, half_chord) = self.solve(ray)?;
        // Each root kept in the box's span along the whole ray (so that a Bvh finds what a
        // loop finds), then the first in range; a root past f64's range (along a direction
        // of extreme length) is no hit.
        // (The far root is clamped only where the near one is out of range: both miss the
        // box or neither does, since a clamp that keeps its root has the box's span hold it.)
        let (t, along) = match self.clamp(ray, near)? {
            Some(near) if ray_t.contains(near) => (near, -half_chord),
            _ => match self.clamp(ray, far)? {
                Some(far) if ray_t.contains(far) => (far, half_chord),
                _ => return None,
            },
        };
        // The vector comes from the closest point and the half chord, not from `o + t d`,
        // which cancels to nothing for a ray from far away. Finite and not zero, it has a
        // direction.
        let outward = closest + along;
        (outward.is_finite() && outward != DVec3::ZERO).then(|| Found::new(t, outward, 0))
    }

    /// A root kept in the box's span along the whole ray; `Some(None)` for a root past
    /// f64's range, `None` where the ray misses the box. (Inlined always: as a closure it
    /// was a call of its own, a fifth of the search's instructions in the port.)
    #[inline(always)]
    fn clamp(&self, ray: &Ray, t: f64) -> Option<Option<f64>> {
        if t.abs() < f64::INFINITY {
            self.bbox.clamp_hit(ray, t).map(Some)
        } else {
            Some(None)
        }
    }

    /// [`Sphere::solve`] along a ray whose direction was [rescaled](Ray::rescaled).
    #[cold]
    #[inline(never)]
    fn solve_rescaled(&self, (scaled, scale): (Ray, f64)) -> Option<(f64, f64, DVec3, DVec3)> {
        self.solve_as::<false>(&scaled)
            .map(|(near, far, closest, chord)| (near * scale, far * scale, closest, chord))
    }
}

impl Hittable for Sphere {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.record(ray, ray_t, &self.crossing(ray, ray_t)?)
    }

    /// In `coords`, the vector from the centre to the hit, before it is made unit length:
    /// the point, normal and `uv` (an `acos` and an `atan2`) are made for the winner alone.
    #[inline]
    fn find(&self, ray: &Ray, ray_t: Interval, _: &mut Made) -> Option<Found> {
        self.crossing(ray, ray_t)
    }

    #[inline]
    fn record(&self, ray: &Ray, _: Interval, found: &Found) -> Option<HitRecord> {
        // Reprojected onto the sphere (pbrt-v4): the point is then the centre plus a radius
        // along a unit vector, off the surface by a few roundings of its coordinates.
        let (outward, _) = unit_and_length(found.coords);
        let offset = self.radius * outward;
        let point = self.center + offset;
        let point_error = gamma(5) * (self.center.abs() + offset.abs());
        let theta = acos((-outward.y).clamp(-1.0, 1.0));
        let phi = atan2(-outward.z, outward.x) + PI;
        let uv = DVec2::new(phi / TAU, theta / PI);
        Some(
            HitRecord::new(ray, found.t, point, outward)
                .with_point_error(point_error)
                .with_uv(uv)
                .with_material(self.material),
        )
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }
}

impl PdfHittable for Sphere {
    /// From outside, `1 / (2 pi (1 - cos theta_max))` for directions inside the cone the
    /// sphere subtends (0 elsewhere, and where that overflows: a sphere so small and far
    /// that its solid angle underflows); from inside or on it, `1 / (4 pi)` (every
    /// direction).
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        // As for a quad: a direction of ordinary length (an exact scaling) keeps the roots
        // within f64's range.
        let direction = direction * direction_scale(direction);
        match self.cone(origin) {
            Some((_, one_minus_cos)) => {
                let hits = self.ahead(origin, direction);
                let pdf = 1.0 / (TAU * one_minus_cos);
                // A cone so thin that `1 - cos` underflows has no finite density: 0, as for
                // a miss (also for NaN from an invalid ray).
                if hits && pdf < f64::INFINITY {
                    pdf
                } else {
                    0.0
                }
            }
            None => 1.0 / (4.0 * PI),
        }
    }

    /// A direction uniformly distributed in the cone the sphere subtends from `origin`
    /// (uniform over the sphere of directions from inside). A direction on the cone's edge
    /// (`u.x` near 1), which rounding may turn just past the sphere, is drawn again a little
    /// further in, so that its [`pdf_value`](PdfHittable::pdf_value) is positive (the
    /// contract's clause 6).
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        if !origin.is_finite() {
            return DVec3::ZERO; // no direction from nowhere; it hits nothing
        }
        let u = u.clamp(DVec2::ZERO, DVec2::ONE);
        let cone = self.cone(origin);
        let (axis, one_minus_cos) = cone.unwrap_or((DVec3::Z, 2.0));
        let (t, b) = axis.any_orthonormal_pair();
        let sample = |k: f64| {
            let u = toward_middle(u, k);
            let one_minus = u.x * one_minus_cos;
            let cos = 1.0 - one_minus;
            let sin = sqrt((one_minus * (2.0 - one_minus)).max(0.0));
            let (s, c) = sin_cos(TAU * u.y);
            (c * sin) * t + (s * sin) * b + cos * axis
        };
        if cone.is_none() {
            return sample(1.0); // from inside, every direction meets the sphere
        }
        reaching(sample, |d| self.ahead(origin, d))
    }
}

impl Sphere {
    /// Whether the ray from `origin` along `direction` meets the sphere at `t >= 0`: the
    /// roots alone, not a hit record (whose point, error bound and uv would be thrown away).
    #[inline]
    fn ahead(&self, origin: DVec3, direction: DVec3) -> bool {
        self.roots(&Ray::new(origin, direction))
            .is_some_and(|(_, far)| far >= 0.0)
    }

    /// The axis (unit, toward the centre) and `1 - cos theta_max` of the cone the sphere
    /// subtends from `origin`, or `None` when the origin is inside or on it (or NaN). Written
    /// as `s^2 / (1 + sqrt(1 - s^2))`, `s = r / distance`, which keeps its digits for small,
    /// far spheres where `1 - sqrt(1 - s^2)` cancels.
    fn cone(&self, origin: DVec3) -> Option<(DVec3, f64)> {
        let (mut axis, distance) = unit_and_length(self.center - origin);
        if distance == f64::INFINITY {
            // The difference overflows; its halves do not, and point the same way.
            axis = unit_and_length(0.5 * self.center - 0.5 * origin).0;
        }
        let s = self.radius / distance;
        if s.is_nan() || s >= 1.0 {
            return None;
        }
        let s2 = s * s;
        Some((axis, s2 / (1.0 + sqrt(1.0 - s2))))
    }
}
