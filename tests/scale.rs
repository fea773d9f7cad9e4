//! Hits that the book's absolute epsilons lose: tiny directions, grazing rays over large
//! quads, scenes far from the origin.

use hitkit::glam::DVec3;
use hitkit::{Hittable, Interval, Plane, Quad, Ray};

const FORWARD: Interval = Interval::FORWARD;

/// The book rejects `|n.d| < 1e-8`; with `n = u x v` of a unit quad that is any direction
/// shorter than 1e-8, however squarely it is aimed.
#[test]
fn a_tiny_direction_aimed_straight_at_a_quad_hits_it() {
    let quad = Quad::new(DVec3::new(-1.0, -1.0, 0.0), DVec3::X * 2.0, DVec3::Y * 2.0).unwrap();
    let ray = Ray::new(DVec3::new(0.25, 0.5, 1.0), DVec3::new(0.0, 0.0, -1e-12));
    let hit = quad.hit(&ray, FORWARD).expect("aimed straight at it");
    assert_eq!(hit.t, 1e12);
    assert_eq!(hit.point, DVec3::new(0.25, 0.5, 0.0));
}

/// 5e-9 radians from grazing: `n.d` is 5e-9 times the book's `|n|`-scaled threshold for a
/// quad of side 2e6 (`|n| = 4e12`), so the book still finds it; but `o + t d - q` at 2e5 from
/// the corner loses the height entirely. The hit must come back at t = 2e5 with the point
/// on the ground.
#[test]
fn a_grazing_ray_finds_a_large_ground_quad_at_the_right_distance() {
    let side = 2e6;
    let ground = Quad::new(
        DVec3::new(-side / 2.0, 0.0, -side / 2.0),
        DVec3::Z * side,
        DVec3::X * side,
    )
    .unwrap();
    let angle: f64 = 5e-9;
    let ray = Ray::new(
        DVec3::new(0.0, 1e-3, 0.0),
        DVec3::new(angle.cos(), -angle.sin(), 0.0),
    );
    let hit = ground
        .hit(&ray, FORWARD)
        .expect("the grazing ray reaches the ground");
    // t = height / sin(angle); the relative error of t is a few ulps over the cosine of
    // incidence, here 5e-9: gamma(8) / 5e-9 < 2e-7.
    let expected = 1e-3 / angle.sin();
    assert!(
        (hit.t - 2e5).abs() / 2e5 < 1e-6 && (hit.t - expected).abs() / expected < 2e-7,
        "t = {}",
        hit.t
    );
    assert!(
        hit.point.y.abs() <= hit.point_error.y,
        "point {} error {}",
        hit.point,
        hit.point_error
    );
    assert_eq!(hit.normal, DVec3::Y);
}

/// Whether a surface is hit, and where, does not depend on the direction's length.
#[test]
fn the_hit_point_does_not_depend_on_the_direction_length() {
    let quad = Quad::new(
        DVec3::new(1e6, 1e6, 1e6),
        DVec3::new(3.0, 0.5, 0.0),
        DVec3::new(0.0, 1.0, 2.5),
    )
    .unwrap();
    let origin = DVec3::new(1e6 - 4.0, 1e6 + 0.7, 1e6 + 1.1);
    let base = (quad.plane().q() - origin) + 0.3 * quad.plane().u() + 0.6 * quad.plane().v();
    let reference = quad.hit(&Ray::new(origin, base), FORWARD).unwrap();
    // The relative error of t is at most (gamma(4) |q - o| + gamma(3) t |d|) / (t |d| c) (see
    // plane_roundtrip.rs), c the cosine of incidence; two such t, plus the rounding of
    // `base * scale` and of `t * scale`, may differ by twice that plus gamma(2).
    let gamma = |k: f64| k * f64::EPSILON / 2.0 / (1.0 - k * f64::EPSILON / 2.0);
    let c = quad.plane().normal().dot(base.normalize()).abs();
    let (a, d) = (
        (quad.plane().q() - origin).length(),
        base.length() * reference.t,
    );
    let rel = 2.0 * (gamma(4.0) * a + gamma(3.0) * d) / (d * c) + gamma(2.0);
    // Each hit point is within the in-plane bound E of plane_roundtrip.rs of the exact hit:
    // E = M (2 gamma(3) + 2 gamma(4) / c) + (1.5 gamma(2) / s + 2 u_r) |p| / c, with M the
    // magnitudes summed (|q - o| + |p| + t |d|) and p the hit relative to q.
    let (u, v) = (quad.plane().u(), quad.plane().v());
    let sin_uv = u.cross(v).length() / (u.length() * v.length());
    let p = (reference.point - quad.plane().q()).length();
    let e = (a + p + d) * (2.0 * gamma(3.0) + 2.0 * gamma(4.0) / c)
        + (1.5 * gamma(2.0) / sin_uv + 2.0 * gamma(1.0)) * p / c;
    for scale in [1e-12, 1e-6, 1e-3, 3.0, 1e3, 1e9] {
        let hit = quad
            .hit(&Ray::new(origin, base * scale), FORWARD)
            .expect("same ray, rescaled");
        // t scales inversely; the point agrees to within the bound on its error.
        assert!(
            (hit.t * scale - reference.t).abs() <= rel * reference.t,
            "{scale}: {} vs {}",
            hit.t * scale,
            reference.t
        );
        let apart = (hit.point - reference.point).length();
        assert!(
            apart <= 2.0 * e + (hit.point_error + reference.point_error).length(),
            "{scale}: {apart} vs {e}"
        );
    }
}

#[test]
fn a_quad_far_from_the_origin_is_as_accurate_as_one_at_it() {
    for offset in [0.0, 1e4, 1e8, 1e12] {
        let q = DVec3::splat(offset);
        let quad = Quad::new(q, DVec3::X * 1e-3, DVec3::Y * 1e-3).unwrap();
        // Aimed at (alpha, beta) = (0.999, 0.001): inside by 1e-3 of an edge of 1e-3, i.e.
        // by 1e-6 absolute, which the book's form (error ~ 1e-16 * 1e12 = 1e-4) cannot see.
        let target_rel = DVec3::new(0.999e-3, 0.001e-3, 0.0);
        let origin = q + DVec3::new(0.0, 0.0, 1e-3);
        let ray = Ray::new(origin, (q - origin) + target_rel);
        let hit = quad.plane().intersect(&ray, FORWARD).expect("hit");
        assert!(
            (hit.alpha - 0.999).abs() < 1e-9 && (hit.beta - 0.001).abs() < 1e-9,
            "offset {offset}: {hit:?}"
        );
    }
}

#[test]
fn parallel_rays_miss_and_rays_in_the_plane_miss() {
    let plane = Plane::new(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    assert!(
        plane
            .intersect(&Ray::new(DVec3::Z, DVec3::X), Interval::UNIVERSE)
            .is_none()
    );
    assert!(
        plane
            .intersect(&Ray::new(DVec3::ZERO, DVec3::X), Interval::UNIVERSE)
            .is_none()
    );
    // The slightest tilt hits, far away.
    let t = plane
        .intersect(
            &Ray::new(DVec3::Z, DVec3::new(1.0, 0.0, -1e-300)),
            Interval::UNIVERSE,
        )
        .unwrap()
        .t;
    // 1 / 1e-300, rounded once (1e-300 itself is inexact): within 2 ulps.
    assert!((t - 1e300).abs() <= 2.0 * f64::EPSILON * 1e300, "{t}");
}

#[test]
fn an_axis_aligned_plane_is_a_thin_slab_and_a_tilted_one_is_unbounded() {
    let ground = Plane::new(DVec3::new(0.0, 2.0, 0.0), DVec3::Z, DVec3::X).unwrap();
    let b = ground.bounding_box();
    assert!(b.min().y <= 2.0 && 2.0 <= b.max().y && b.max().y - b.min().y < 1e-9);
    assert!(b.min().x.is_infinite() && b.max().z.is_infinite() && !b.is_bounded());
    let tilted = Plane::new(DVec3::ZERO, DVec3::new(1.0, 1e-6, 0.0), DVec3::Z).unwrap();
    assert_eq!(tilted.bounding_box(), hitkit::Aabb::UNIVERSE);
    // The slab holds every hit on the plane, however far.
    let far = Ray::new(DVec3::new(1e15, 10.0, -3e14), DVec3::new(0.1, -1.0, 0.2));
    let hit = ground.hit(&far, FORWARD).unwrap();
    assert!(b.contains(hit.point) && b.hit(&far, FORWARD));
}

#[test]
fn spawned_rays_leave_the_surface_on_the_side_they_head_to() {
    for offset in [0.0, 1.0, 1e6, 1e9, 1e12] {
        let q = DVec3::new(offset, offset * 0.5, -offset);
        let quad = Quad::new(q, DVec3::new(2.0, 0.3, 0.1), DVec3::new(-0.2, 0.4, 1.7)).unwrap();
        let target = q + (0.4 * quad.plane().u() + 0.7 * quad.plane().v());
        let origin = target + DVec3::new(1.0, 2.0, 3.0);
        let hit = quad
            .hit(&Ray::new(origin, target - origin), FORWARD)
            .expect("hit");
        // Reflected (back to the ray's side) and transmitted (through the surface).
        for direction in [hit.normal + DVec3::new(0.1, 0.0, 0.0), -hit.normal] {
            let spawned = hit.spawn_ray(direction);
            assert!(
                quad.hit(&spawned, FORWARD).is_none(),
                "offset {offset}: re-hit along {direction}"
            );
            let side = (spawned.origin - q).dot(quad.plane().normal()).signum();
            assert_eq!(
                side,
                direction.dot(quad.plane().normal()).signum(),
                "offset {offset}"
            );
        }
    }
}
