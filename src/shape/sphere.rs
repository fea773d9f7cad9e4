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
    /// `radius * radius`, made once: every query needs it.
    radius_squared: f64,
    /// `radius_squared (1 + MISS)`, for [`Sphere::clearly_missed`].
    radius_squared_high: f64,
    /// The part of [`Roots::clear`] that depends on the sphere alone.
    box_room: f64,
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
            radius_squared: radius * radius,
            radius_squared_high: radius * radius * (1.0 + MISS),
            box_room: gamma(64) * gamma(2) * center.abs().max_element() + 4.0 * f64::MIN_POSITIVE,
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
            .filter(|r| r.near.is_finite() && r.far.is_finite())
            .map(|r| (r.near, r.far))
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
    fn solve(&self, ray: &Ray) -> Option<Roots> {
        self.solve_as::<true>(ray)
    }

    /// [`Sphere::solve`], which rescales only where `RESCALE` (no recursion, so the
    /// common path inlines).
    #[inline(always)]
    fn solve_as<const RESCALE: bool>(&self, ray: &Ray) -> Option<Roots> {
        let f = ray.origin - self.center;
        let d = ray.direction;
        let a = d.dot(d);
        // Outside the range, where a ray that cannot be traced is too, solved along the
        // rescaled direction. (An infinite or NaN origin with a direction in range makes a
        // NaN or `-inf` discriminant below: no roots.)
        if RESCALE && !in_range(a) {
            return self.solve_rescaled(ray);
        }
        let b = f.dot(d); // half of the usual b
        let closest = f - (b / a) * d;
        let r2 = self.radius_squared;
        let discriminant = r2 - closest.dot(closest);
        if discriminant.is_nan() || discriminant < 0.0 {
            return None; // a miss, or a NaN from an invalid ray
        }
        let ff = f.dot(f);
        let c = ff - r2;
        // One square root serves both: `sqrt(a disc) / a = sqrt(disc / a)`, the half chord
        // in units of `t`.
        let root = sqrt(a * discriminant);
        // (`copysign`, not `signum`: the same for every `b` that gets here, a number.)
        let q = -(b + root.copysign(b));
        let (t0, t1) = (c / q, q / a);
        // (Written for `minsd` and `maxsd`: a NaN root ends as `near` or `far`, checked.)
        let less = t0 < t1;
        let (near, far) = (if less { t0 } else { t1 }, if less { t1 } else { t0 });
        let scale = root / a;
        // `|d_i| <= sqrt(a)`, so a finite `root / a` makes a half chord of at most about
        // `sqrt(discriminant) <= r` per coordinate: finite.
        if near.is_nan() || far.is_nan() || scale == f64::INFINITY {
            return None;
        }
        // See `Roots::clear`: `c / q` is as accurate as the point needs where
        // `q^2 >= a (f.f + r^2) / 64`.
        let clear = if RESCALE && q * q >= a * (ff + r2) * (1.0 / 64.0) {
            self.radius - (CLEAR * (f.abs().max_element() + self.radius) + self.box_room)
        } else {
            f64::NEG_INFINITY
        };
        Some(Roots {
            near,
            far,
            closest,
            half_chord: scale * d,
            clear,
        })
    }
}

/// What [`Sphere::solve`] found: the roots, nearer first, the vector from the centre to the
/// ray's point closest to it, half the chord as a vector along the ray, and `clear`.
///
/// `clear` is a bound on the vector `w` from the centre to a root's point as computed
/// (`closest -/+ half_chord`): where `|w_i| <= clear` on every axis, the root's `t` is
/// inside the box's span by the box's own quick test (`Aabb::clamp_hit` keeps it as it
/// is), so the root needs no clamp. Derivation (`u_r` the unit roundoff, `f = o - center`
/// and `q` as computed, `M = |f|_inf + r`): the point `o + t d` of a computed root lies
/// within `E` of `center + w`. For `t = q / a` (`q = -(b + sign(b) root)`), `t d` and `w`
/// are the same sum of the same computed terms, rounded apart: `E <= gamma(24) (|f| + r)`.
/// For `t = c / q` add its distance from that consistent root, `|a c - b^2 + root^2| |d| /
/// (a |q|)`, whose numerator is the discriminant's rounding (`gamma(70) a (f.f + r^2)`,
/// see [`Sphere::clearly_missed`]): with `q^2 >= a (f.f + r^2) / 64` (checked; it fails
/// only where `b` and the chord are both small, a ray from the surface along it), at most
/// `gamma(700) (|f| + r)`. So `E <= gamma(1262) M`. The box's quick test asks each
/// coordinate of `t d` to lie inside the box, from the origin, by `gamma(6)` of the
/// magnitudes (`|t d_i| + |bound - o_i|`, at most `2.1 M + 2 E + gamma(2) |center|_inf`,
/// the box being the sphere's, grown by `gamma(1) (|center| + r)`), itself rounded: it
/// holds where `r - |w_i| >= E + gamma(40) (M + gamma(2) |center|_inf) + 4 MIN_POSITIVE`.
/// `clear` is `r - gamma(2048) M - box_room`, with `box_room = gamma(64) gamma(2)
/// |center|_inf + 4 MIN_POSITIVE`: no hit point more than about `2.3e-13 M` from the six
/// points where the sphere touches its box is clamped. `-inf` where it is not known (the
/// bound on `q` fails, or the direction was rescaled).
#[derive(Clone, Copy)]
struct Roots {
    near: f64,
    far: f64,
    closest: DVec3,
    half_chord: DVec3,
    clear: f64,
}

/// The relative margin of [`Sphere::clearly_missed`].
const MISS: f64 = gamma(128);

/// The factor of `|f|_inf + r` in [`Roots::clear`].
const CLEAR: f64 = gamma(2048);

impl Sphere {
    /// [`Hittable::find`]'s crossing, which `hit` records without a [`Made`] (it never
    /// makes one): most misses decided by [`Sphere::clearly_missed`], the rest by
    /// [`Sphere::careful_crossing`].
    #[inline(always)]
    fn crossing(&self, ray: &Ray, ray_t: Interval) -> Option<Found> {
        if self.clearly_missed(ray) {
            return None;
        }
        self.careful_crossing::<true>(ray, ray_t)
    }

    /// Whether the ray misses the sphere by a margin that the careful discriminant's
    /// rounding cannot close, decided by the book's arithmetic: `b^2 < a c` with
    /// `a = d.d`, `b = f.d`, `c = f.f - r^2` (`f = o - center`, as computed; `r^2` the
    /// stored square), whose exact difference `b^2 - a c` is `a` times the exact
    /// discriminant `r^2 - |f - (b / a) d|^2` that [`Sphere::solve`] computes, with the
    /// margin folded into `c`: `b^2 + 2^-900 < a (f.f (1 - G) - r^2 (1 + G))`,
    /// `G = gamma(128)`, `r^2 (1 + G)` made once per sphere.
    ///
    /// Derivation (`u_r` the unit roundoff, `S = a (f.f + r^2)`, and `|f| |d|` bounding
    /// `sum |f_i d_i|`, so `b^2 <= a f.f`): `a`, `b` and `f.f` carry `gamma(3)` of their
    /// magnitudes, so the exact `b^2` is at most the computed one plus `gamma(7) a f.f`,
    /// and the right side, rounded four more times, is within `gamma(10)` of its exact
    /// value; a test that holds so makes the exact `b^2 - a c` at most `-(G - gamma(20)) S`.
    /// The careful discriminant's closest point errs by `gamma(23) |f|` (the quotient
    /// `b / a` by `gamma(9) |f| / |d|`, its product and difference by a few `u_r` more,
    /// `|closest| <= |f|`), so the discriminant by `gamma(51) (f.f + r^2)`, or
    /// `gamma(51) S` once times `a`: below `-(G - gamma(20)) S` exactly, it is negative as
    /// computed, the same miss. The `2^-900` covers what underflow adds (at most a few
    /// `2^-1074`, times `a <= 2^66`). Only for `a` in the range [`Sphere::solve`] takes
    /// without rescaling; a NaN or infinity anywhere (an invalid ray, or squares past f64's
    /// range) decides nothing here.
    #[inline(always)]
    fn clearly_missed(&self, ray: &Ray) -> bool {
        // 2^-900.
        const TINY: f64 = f64::from_bits((1023 - 900) << 52);
        let f = ray.origin - self.center;
        let d = ray.direction;
        let (a, b, ff) = (d.dot(d), f.dot(d), f.dot(f));
        // (An infinite right side, `f.f` past f64's range, decides nothing.)
        let c_times_a = a * (ff * (1.0 - MISS) - self.radius_squared_high);
        in_range(a) && b * b + TINY < c_times_a && c_times_a <= f64::MAX
    }

    /// The careful crossing: [`Sphere::solve`]'s roots, clamped into the box's span where
    /// their points are not clear of its faces ([`Roots::clear`]; always, without `QUICK`:
    /// the reference the tests hold the quick decisions to). Out of line, so that the
    /// misses decided before it do not pay its registers' saving.
    #[inline(never)]
    fn careful_crossing<const QUICK: bool>(&self, ray: &Ray, ray_t: Interval) -> Option<Found> {
        let Roots {
            near,
            far,
            closest,
            half_chord,
            clear,
        } = self.solve(ray)?;
        let clear = if QUICK { clear } else { f64::NEG_INFINITY };
        // Each root kept in the box's span along the whole ray (so that a Bvh finds what a
        // loop finds), then the first in range; a root past f64's range (along a direction
        // of extreme length) is no hit.
        // (The far root is clamped only where the near one is out of range: both miss the
        // box or neither does, since a clamp that keeps its root has the box's span hold it.)
        // The vector from the centre comes from the closest point and the half chord, not
        // from `o + t d`, which cancels to nothing for a ray from far away.
        let (t, outward) = match self.clamp(ray, near, closest - half_chord, clear)? {
            Some(near) if ray_t.contains(near) => (near, closest - half_chord),
            _ => match self.clamp(ray, far, closest + half_chord, clear)? {
                Some(far) if ray_t.contains(far) => (far, closest + half_chord),
                _ => return None,
            },
        };
        // Finite (`|closest|^2 <= r^2`, and the half chord is finite) and not zero, it has
        // a direction.
        (outward != DVec3::ZERO).then(|| Found::new(t, outward, 0))
    }

    /// A root kept in the box's span along the whole ray; `Some(None)` for a root past
    /// f64's range, `None` where the ray misses the box. Kept as it is, without the box's
    /// test, where its point `center + outward` is clear of the box's faces
    /// ([`Roots::clear`]). (Inlined always: as a closure it was a call of its own, a fifth
    /// of the search's instructions in the port.)
    #[inline(always)]
    fn clamp(&self, ray: &Ray, t: f64, outward: DVec3, clear: f64) -> Option<Option<f64>> {
        if t.abs() < f64::INFINITY {
            if outward.abs().max_element() <= clear {
                return Some(Some(t));
            }
            self.bbox.clamp_hit(ray, t).map(Some)
        } else {
            Some(None)
        }
    }

    /// [`Sphere::solve`] for a direction outside its range: `None` for a ray that cannot
    /// be traced, else along the [rescaled](Ray::rescaled) direction where it scales.
    #[cold]
    #[inline(never)]
    fn solve_rescaled(&self, ray: &Ray) -> Option<Roots> {
        if !ray.is_valid() {
            return None;
        }
        let Some((scaled, scale)) = ray.rescaled() else {
            return self.solve_as::<false>(ray);
        };
        self.solve_as::<false>(&scaled).map(|r| Roots {
            near: r.near * scale,
            far: r.far * scale,
            ..r
        })
    }
}

/// Whether `a = d.d` is in the range [`Sphere::solve`] takes without rescaling:
/// `[2^-128, 2^66]`.
#[inline(always)]
fn in_range(a: f64) -> bool {
    (1.0 / (1u128 << 64) as f64 / (1u128 << 64) as f64..=(1u128 << 66) as f64).contains(&a)
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
        let ray = Ray::new(origin, direction);
        !self.clearly_missed(&ray) && self.roots(&ray).is_some_and(|(_, far)| far >= 0.0)
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

#[cfg(test)]
mod tests {
    use super::Sphere;
    use crate::math::Stream;
    use crate::{Interval, Ray};
    use glam::DVec3;

    /// The crossing as the careful path alone finds it: every ray checked, every root
    /// clamped by the box's own test.
    fn careful(sphere: &Sphere, ray: &Ray, ray_t: Interval) -> Option<super::Found> {
        if !ray.is_valid() {
            return None;
        }
        sphere.careful_crossing::<false>(ray, ray_t)
    }

    /// The quick decisions (the book's discriminant for misses, `Roots::clear` for the box
    /// clamp, the checks left to the arithmetic) answer as the careful path does, bit for
    /// bit in `t` and the vector to the hit, on adversarial rays: radii 1e-150 to 1e150,
    /// centres up to 1e9 away, aimed at the sphere's rim (tangent, within 10^-k of it on
    /// either side), at the six points where it touches its box, from its surface (along
    /// it, into it, out of it), from inside, from far away, with directions from 1e-200 to
    /// 1e200 long, and a few invalid ones. Each quick decision must be exercised, and the
    /// box's clamp must move some roots (else the bound on `clear` would go untested).
    #[test]
    fn quick_decisions_answer_as_the_careful_path() {
        let mut s = Stream(0x05ee_d0f5_fe7e);
        let (mut quick_misses, mut clear, mut clamped, mut hits) = (0, 0, 0, 0);
        for i in 0..200_000 {
            let radius = if i % 50 == 0 {
                s.pick(&[1e-150, 1e150, 3e-100, 7e120])
            } else {
                s.power(-6, 6) * (1.0 + s.uniform())
            };
            let offset = s.pick(&[0.0, 1.0, 1e3, 1e6, 1e9]) * radius.max(1.0);
            let center = s.unit() * offset;
            let Ok(sphere) = Sphere::new(center, radius) else {
                continue;
            };
            let axis = s.pick(&[DVec3::X, DVec3::Y, DVec3::Z]) * s.pick(&[-1.0, 1.0]);
            let (origin, direction) = match (s.uniform() * 6.0) as u32 {
                // At the rim: tangent, within 10^-k of it, on either side.
                0 => {
                    let d = s.unit();
                    let side = s.unit().reject_from(d).normalize();
                    let k = 1.0 + s.pick(&[-1.0, 1.0]) * s.power(-16, -1);
                    let target = center + side * radius * k;
                    (target - d * radius * s.power(-3, 8), d)
                }
                // At the six points where the sphere touches its box, near them.
                1 => {
                    let target = center + axis * radius + s.unit() * radius * s.power(-16, -1);
                    let d = s.unit();
                    (target - d * radius * s.power(-3, 8), d)
                }
                // From the surface, as a spawned ray: along it, into it, out of it.
                2 => {
                    let n = s.unit();
                    let d = match s.uniform() {
                        u if u < 0.4 => (s.unit().reject_from(n).normalize()
                            + n * s.power(-16, -1) * s.pick(&[-1.0, 1.0]))
                        .normalize(),
                        u if u < 0.7 => -s.unit().abs() * n.signum(),
                        _ => s.unit(),
                    };
                    (center + n * radius, d)
                }
                // From inside.
                3 => (center + s.unit() * radius * s.uniform(), s.unit()),
                // From far away, aimed anywhere near.
                4 => {
                    let target = center + s.unit() * radius * (0.5 + s.uniform());
                    let d = s.unit();
                    (target - d * radius * s.power(4, 12), d)
                }
                // Anywhere.
                _ => (center + s.unit() * radius * s.power(0, 3), s.unit()),
            };
            let length = if i % 40 == 0 {
                s.pick(&[1e-200, 1e200, 1e-40, 1e40, 0.0, f64::NAN, f64::INFINITY])
            } else {
                s.power(-3, 3)
            };
            let ray = Ray::new(origin, direction * length);
            let ray_t = match i % 4 {
                0 => Interval::FORWARD,
                1 => Interval::UNIVERSE,
                2 => Interval::new(1e-9 * radius / length, f64::INFINITY),
                _ => Interval::new(0.0, radius * s.power(-1, 3) / length),
            };
            let quick = sphere.crossing(&ray, ray_t);
            let reference = careful(&sphere, &ray, ray_t);
            let bits = |f: Option<super::Found>| {
                f.map(|f| (f.t.to_bits(), f.coords.to_array().map(f64::to_bits)))
            };
            assert_eq!(bits(quick), bits(reference), "{sphere:?} {ray:?} {ray_t:?}");
            quick_misses += usize::from(sphere.clearly_missed(&ray));
            if let (Some(found), Some(roots)) = (reference, sphere.solve(&ray)) {
                hits += 1;
                clear += usize::from(found.coords.abs().max_element() <= roots.clear);
                clamped += usize::from(found.t != roots.near && found.t != roots.far);
            }
        }
        assert!(
            quick_misses > 20_000 && clear > 20_000 && clamped > 50 && hits > 50_000,
            "{quick_misses} {clear} {clamped} {hits}"
        );
    }
}
