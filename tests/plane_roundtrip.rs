//! The alpha/beta round trip: a ray aimed at `q + alpha u + beta v` comes back from
//! `Plane::intersect` with that `alpha`, `beta` and the `t` it was built for, to within an
//! error bound derived below from the magnitudes involved, and every shape classifies the
//! point correctly whenever it lies farther from the shape's edge than that bound.
//!
//! # The error bound
//! Write `u_r` for the unit roundoff (2^-53) and `gamma(k) = k u_r / (1 - k u_r)` (pbrt-v4,
//! Higham). The test builds the ray from an origin `o` with direction
//! `d = (q - o) + (alpha u + beta v)`, so that `o + 1 d` is the target. Let
//! `M = |o - q| + |alpha u| + |beta v| + |d|` (every magnitude that is rounded),
//! `c = |n . d| / (|n| |d|)` (the cosine of the ray against the normal), `s` the sine of
//! the angle between `u` and `v`, and `p = alpha u + beta v`. To first order in `u_r`:
//!
//! 1. Building `d` rounds by at most `gamma(3) M`, so the exact ray crosses the plane off the
//!    target by at most `gamma(3) M (1 + 1/c)` (the error, plus its normal part slid along
//!    the ray to the plane), and at `t` off 1 by at most `gamma(3) M / (|d| c)`.
//! 2. `t = n.(q - o) / n.d`: the numerator is off by `gamma(4) |n| |q - o|`, the denominator
//!    by `gamma(3) |n| |d|`, and `|n.(q - o)| = t |n.d| = t |n| |d| c`, so `t` has relative
//!    error at most `(gamma(4) |q - o| + gamma(3) |d|) / (|d| c) + u_r <= gamma(4) M / (|d| c) + u_r`.
//! 3. `p = (o - q) + t d` adds `gamma(2) M` of rounding, and the error of `t` moves it by
//!    at most `gamma(4) M / c + u_r M` along the ray.
//! 4. The computed unit normal `n = (u x v) / |u x v|` is off in direction by at most
//!    `sqrt(2) gamma(2) / s` (the cross product's rounding against its length `|u| |v| s`)
//!    plus `sqrt(3) u_r` (the division of each component; the length's own error scales all
//!    components alike). That tilts the plane used for `t` about `q`: at the hit, a distance
//!    of `(sqrt(2) gamma(2) / s + sqrt(3) u_r) |p|` from the true plane, `/ c` along the ray.
//! 5. `alpha = w.(p x v)` with `w = n / |u x v|` rounds by at most `2 gamma(5) |p| |v| / |u x v|`,
//!    and an in-plane position error `e` becomes an error of `e |v| / |u x v| = e / (|u| s)`;
//!    the errors of `w` scale alpha by `1 + 2 sqrt(2) gamma(2) / s + gamma(5)` at most.
//!
//! Summing, with the constants rounded up (which also covers the second-order terms):
//! `E = M (2 gamma(3) + 2 gamma(4) / c) + (1.5 gamma(2) / s + 2 u_r) |p| / c` is a bound on
//! the in-plane position error, and
//! `tol_alpha = (E + 2 gamma(5) |p|) / (|u| s) + (3 gamma(2) / s + gamma(5)) |alpha|` (beta
//! likewise with `|v|`), `tol_t = (2 gamma(4) M + (1.5 gamma(2) / s + 2 u_r) |p|) / (|d| c) + gamma(1)`.
//! None of it depends on `|q|`: the formulation is relative to `q`, so a quad 1e8 from the
//! origin is as accurate as one at it. (The book's `o + t d - q` form loses `u_r |q|`
//! absolutely, a thousand times this bound for an edge of 1e-2 at 1e8.)

mod support;

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::{
    Disk, Hittable, Interval, Parallelogram, Plane, Quad, Ray, Ring, Triangle,
    custom::CrossingRegion,
};
use proptest::prelude::*;
use support::gamma;

/// A random case: plane, target coordinates and ray.
#[derive(Debug, Clone)]
struct Case {
    q: DVec3,
    u: DVec3,
    v: DVec3,
    alpha: f64,
    beta: f64,
    origin: DVec3,
    direction: DVec3,
}

/// The derived tolerances for a case.
struct Tolerance {
    alpha: f64,
    beta: f64,
    t: f64,
}

impl Case {
    fn tolerance(&self) -> Tolerance {
        let (u, v, d) = (self.u, self.v, self.direction);
        let n = u.cross(v);
        let p = self.alpha * u + self.beta * v;
        let m = (self.origin - self.q).length()
            + (self.alpha * u).length()
            + (self.beta * v).length()
            + d.length();
        let c = n.normalize().dot(d.normalize()).abs();
        let s = n.length() / (u.length() * v.length());
        let tilt = 1.5 * gamma(2) / s + 2.0 * gamma(1);
        let e = m * (2.0 * gamma(3) + 2.0 * gamma(4) / c) + tilt * p.length() / c;
        let rounding = 2.0 * gamma(5) * p.length();
        let scale = 3.0 * gamma(2) / s + gamma(5);
        Tolerance {
            alpha: (e + rounding) / (u.length() * s) + scale * self.alpha.abs(),
            beta: (e + rounding) / (v.length() * s) + scale * self.beta.abs(),
            t: (2.0 * gamma(4) * m + tilt * p.length()) / (d.length() * c) + gamma(1),
        }
    }

    fn ray(&self) -> Ray {
        Ray::new(self.origin, self.direction)
    }
}

/// A unit vector from two uniform numbers.
fn unit(z: f64, phi: f64) -> DVec3 {
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

prop_compose! {
    fn case()(
        q_scale in 0.0f64..8.0, q_dir in (-1.0f64..1.0, 0.0..core::f64::consts::TAU),
        u_len in -2.0f64..2.0, u_dir in (-1.0f64..1.0, 0.0..core::f64::consts::TAU),
        v_len in -2.0f64..2.0, v_spin in 0.0..core::f64::consts::TAU,
        angle_deg in 3.0f64..177.0,
        alpha in -0.5f64..1.5, beta in -0.5f64..1.5,
        dist in -1.0f64..2.0, along_normal in 0.1f64..1.0, side in prop::bool::ANY,
        in_plane in (-1.0f64..1.0, -1.0f64..1.0),
    ) -> Case {
        // q from 1 to 1e8 away from the origin.
        let q = unit(q_dir.0, q_dir.1) * 10f64.powf(q_scale);
        let u = unit(u_dir.0, u_dir.1) * 10f64.powf(u_len);
        // v: `angle_deg` away from u, spun about u by `v_spin`.
        let perp = u.any_orthonormal_vector();
        let off = DQuat::from_axis_angle(u.normalize(), v_spin) * perp;
        let angle = angle_deg.to_radians();
        let v = (u.normalize() * angle.cos() + off * angle.sin()) * 10f64.powf(v_len);
        // The origin: from the target, a distance of 0.1 to 100 longest edges, along a
        // direction at least ~3 degrees off the plane.
        let nhat = u.cross(v).normalize();
        let (t1, t2) = (u.normalize(), nhat.cross(u.normalize()));
        let away = (nhat * if side { along_normal } else { -along_normal } + t1 * in_plane.0 + t2 * in_plane.1).normalize();
        let target_rel = alpha * u + beta * v;
        let origin = (q + target_rel) + away * 10f64.powf(dist) * u.length().max(v.length());
        let direction = (q - origin) + target_rel;
        Case { q, u, v, alpha, beta, origin, direction }
    }
}

/// Whether some point `region.at(s)`, `|s| <= region.reach`, is within `radius` of
/// `target` in both coordinates.
fn segment_reaches(region: &CrossingRegion, target: DVec2, radius: DVec2) -> bool {
    let (mut lo, mut hi) = (-region.reach, region.reach);
    for (c, w, x, r) in [
        (region.center.x, region.along.x, target.x, radius.x),
        (region.center.y, region.along.y, target.y, radius.y),
    ] {
        if w == 0.0 {
            if (x - c).abs() > r {
                return false;
            }
        } else {
            let (a, b) = ((x - r - c) / w, (x + r - c) / w);
            lo = lo.max(a.min(b));
            hi = hi.min(a.max(b));
        }
    }
    lo <= hi
}

/// `Some(true)` when `margin` (positive inside) clears the tolerance, `Some(false)` when
/// it is outside by more than it, `None` in between, where either answer is right.
fn classify(margin: f64, tol: f64) -> Option<bool> {
    if margin > tol {
        Some(true)
    } else if margin < -tol {
        Some(false)
    } else {
        None
    }
}

/// Inside a shape that is an intersection of conditions: clearly out if any condition is
/// clearly out, clearly in if all are clearly in.
fn all_of(conditions: &[Option<bool>]) -> Option<bool> {
    if conditions.contains(&Some(false)) {
        Some(false)
    } else if conditions.iter().all(|c| *c == Some(true)) {
        Some(true)
    } else {
        None
    }
}

fn assert_shape_agrees<S: hitkit::Interior>(
    case: &Case,
    shape: S,
    expect: Option<bool>,
    name: &str,
) -> Result<(), TestCaseError> {
    let quad = Quad::with_interior(case.q, case.u, case.v, shape).unwrap();
    let hit = quad.hit(&case.ray(), Interval::FORWARD);
    if let Some(expect) = expect {
        prop_assert_eq!(
            hit.is_some(),
            expect,
            "{} at alpha {} beta {}",
            name,
            case.alpha,
            case.beta
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    #[test]
    fn intersect_returns_alpha_beta_t_within_the_derived_bound(case in case()) {
        let plane = Plane::new(case.q, case.u, case.v).unwrap();
        let tol = case.tolerance();
        let hit = plane.intersect(&case.ray(), Interval::UNIVERSE).expect("a ray aimed at the plane meets it");
        prop_assert!((hit.alpha - case.alpha).abs() <= tol.alpha, "alpha {} vs {}, tol {}", hit.alpha, case.alpha, tol.alpha);
        prop_assert!((hit.beta - case.beta).abs() <= tol.beta, "beta {} vs {}, tol {}", hit.beta, case.beta, tol.beta);
        prop_assert!((hit.t - 1.0).abs() <= tol.t, "t {} vs 1, tol {}", hit.t, tol.t);

        // hitkit's own region for the exact crossing (what its quads decide by), grown by the
        // error of building the ray (item 1 above), must hold the target too: some point of
        // its segment is within its radius of the target.
        let region = plane.crossing_region(&case.ray(), &hit);
        let (u, v, d) = (case.u, case.v, case.direction);
        let n = u.cross(v);
        let c = n.normalize().dot(d.normalize()).abs();
        let s = n.length() / (u.length() * v.length());
        let m = (case.origin - case.q).length() + (case.alpha * u).length() + (case.beta * v).length() + d.length();
        let built = gamma(3) * m * (1.0 + 1.0 / c);
        let slack = DVec2::new(built / (u.length() * s), built / (v.length() * s));
        let target = DVec2::new(case.alpha, case.beta);
        prop_assert!(
            segment_reaches(&region, target, region.radius + slack),
            "target {:?} outside {:?} (+ {:?})", target, region, slack
        );
    }

    #[test]
    fn shapes_hit_points_inside_by_the_bound_and_miss_points_outside_by_it(case in case()) {
        let (a, b) = (case.alpha, case.beta);
        let tol = case.tolerance();
        // The quads decide by the region where the exact crossing can be (watertight edges,
        // `Plane::crossing_region`), which holds their tolerance too: a point outside by
        // less than its extent may hit, so the extent joins the tolerance.
        let plane = Plane::new(case.q, case.u, case.v).unwrap();
        let hit = plane.intersect(&case.ray(), Interval::UNIVERSE).expect("aimed at the plane");
        let region = plane.crossing_region(&case.ray(), &hit);
        let widening = region.radius + region.half_length();
        let (ta, tb) = (tol.alpha + widening.x, tol.beta + widening.y);
        // Margins are measured on the exact (alpha, beta) the ray was aimed at.
        let square = [classify(a, ta), classify(1.0 - a, ta), classify(b, tb), classify(1.0 - b, tb)];
        assert_shape_agrees(&case, Parallelogram, all_of(&square), "parallelogram")?;

        // alpha + beta is rounded once more in the predicate: gamma(1) (|alpha| + |beta|) at most.
        let tri = [classify(a, ta), classify(b, tb), classify(1.0 - a - b, ta + tb + gamma(1) * (a.abs() + b.abs()))];
        assert_shape_agrees(&case, Triangle, all_of(&tri), "triangle")?;

        // r^2 = alpha^2 + beta^2 moves by 2|alpha| ta + 2|beta| tb + ta^2 + tb^2, and its
        // evaluation rounds by gamma(2) r^2.
        let r2 = a * a + b * b;
        let tol_r2 = 2.0 * a.abs() * ta + 2.0 * b.abs() * tb + ta * ta + tb * tb + gamma(2) * r2;
        let outer = classify(1.0 - r2, tol_r2);
        assert_shape_agrees(&case, Disk, outer, "disk")?;
        let inner = 0.5f64;
        let ring = [outer, classify(r2 - inner * inner, tol_r2)];
        assert_shape_agrees(&case, Ring::new(inner).unwrap(), all_of(&ring), "ring")?;
    }
}
