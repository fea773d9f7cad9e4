//! Each interior shape: the quad hits exactly where the predicate accepts, `uv` follows the
//! documented mapping, the bounding box contains every point of the shape, and a ring with
//! no hole is the disk.

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Disk, Hittable, Interior, Interval, Parallelogram, Quad, Ray, Ring, Triangle};
use proptest::prelude::*;
use support::gamma;

type Frame = (DVec3, DVec3, DVec3);

fn frame() -> impl Strategy<Value = Frame> {
    let v3 =
        || (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    (v3(), v3(), v3(), -3.0f64..3.0, -3.0f64..6.0).prop_filter_map(
        "nearly degenerate frame",
        |(q, u, v, scale, offset)| {
            let (s, o) = (10f64.powf(scale), 10f64.powf(offset));
            let (q, u, v) = (q * o, u * s, v * s);
            // At least ~3 degrees between u and v, so that (alpha, beta) errors stay a small
            // multiple of rounding (the round-trip test covers the bound itself).
            (u.cross(v).length() > 0.05 * u.length() * v.length()).then_some((q, u, v))
        },
    )
}

/// A ray from above the plane point (alpha, beta), aimed at it along the normal.
fn ray_at((q, u, v): Frame, alpha: f64, beta: f64) -> Ray {
    let n = u.cross(v).normalize();
    let height = u.length().max(v.length());
    Ray::new(q + (alpha * u + beta * v + n * height), -n * height)
}

/// How far from (alpha, beta) (both within 1.5 in size) the ray of `ray_at` can land, in
/// plane coordinates. Its origin is rounded once, by at most
/// `sqrt(3) u_r (|q| + 2.5 (|u| + |v|))` in length, which moves a ray along the normal
/// (c = 1) by as much in the plane. The intersection then adds the bound derived in
/// `plane_roundtrip.rs` with c = 1: `E = M (2 gamma(3) + 2 gamma(4))`
/// `+ (1.5 gamma(2) / s + 2 u_r) |p|` plus `2 gamma(5) |p|`, with `M <= 5 (|u| + |v|)` and
/// `|p| <= 1.5 (|u| + |v|)`, and `(3 gamma(2) / s + gamma(5)) 1.5` from the rounded normal. A position error `e` is `e / (|u| s)` in
/// alpha and `e / (|v| s)` in beta.
fn landing_error((q, u, v): Frame) -> f64 {
    let s = u.cross(v).length() / (u.length() * v.length());
    let edges = u.length() + v.length();
    let (m, p) = (5.0 * edges, 1.5 * edges);
    let origin = 3f64.sqrt() * gamma(1) * (q.length() + 2.5 * edges);
    let e = origin
        + m * (2.0 * gamma(3) + 2.0 * gamma(4))
        + (1.5 * gamma(2) / s + 2.0 * gamma(1)) * p
        + 2.0 * gamma(5) * p;
    e / (u.length().min(v.length()) * s) + 1.5 * (3.0 * gamma(2) / s + gamma(5))
}

/// The predicate at (alpha, beta), when it gives the same answer `h` further in every
/// direction, with `h` the landing error: then the quad must answer the same.
fn clear_of_the_edge<S: Interior>(shape: &S, alpha: f64, beta: f64, h: f64) -> Option<bool> {
    let here = shape.contains(alpha, beta);
    [(h, 0.0), (-h, 0.0), (0.0, h), (0.0, -h)]
        .iter()
        .all(|(da, db)| shape.contains(alpha + da, beta + db) == here)
        .then_some(here)
}

fn check_hit<S: Interior + Copy>(
    shape: S,
    frame: Frame,
    alpha: f64,
    beta: f64,
    uv: impl Fn(f64, f64) -> DVec2,
) -> Result<(), TestCaseError> {
    let quad = Quad::with_interior(frame.0, frame.1, frame.2, shape).unwrap();
    let hit = quad.hit(&ray_at(frame, alpha, beta), Interval::FORWARD);
    let h = landing_error(frame);
    if let Some(expect) = clear_of_the_edge(&shape, alpha, beta, h) {
        prop_assert_eq!(hit.is_some(), expect, "alpha {} beta {}", alpha, beta);
    }
    if let Some(hit) = hit {
        // The documented mapping, up to the landing error (the mappings are 1-Lipschitz).
        prop_assert!(
            (hit.uv - uv(alpha, beta)).abs().max_element() <= h,
            "uv {} for ({}, {})",
            hit.uv,
            alpha,
            beta
        );
        prop_assert!(
            quad.bounding_box().contains(hit.point),
            "hit point {} outside {:?}",
            hit.point,
            quad.bounding_box()
        );
    }
    Ok(())
}

/// Every point of the shape (here: a dense sample of its boundary, where a box is tight,
/// and its interior) lies in its box, up to the rounding of computing the point itself,
/// `gamma(3) (|q| + |alpha u| + |beta v|)`.
fn check_box<S: Interior>(
    shape: S,
    (q, u, v): Frame,
    points: &[(f64, f64)],
) -> Result<(), TestCaseError> {
    let quad = Quad::with_interior(q, u, v, shape).unwrap();
    let b = quad.bounding_box();
    for &(alpha, beta) in points {
        let (au, bv) = (alpha * u, beta * v);
        let p = q + (au + bv);
        let slack = gamma(3) * (q.abs() + au.abs() + bv.abs());
        prop_assert!(
            b.min().cmple(p + slack).all() && (p - slack).cmple(b.max()).all(),
            "({}, {}) -> {} outside {:?}",
            alpha,
            beta,
            p,
            b
        );
    }
    Ok(())
}

fn circle(r: f64) -> Vec<(f64, f64)> {
    (0..64)
        .map(|i| f64::from(i) * core::f64::consts::TAU / 64.0)
        .map(|s| (r * s.cos(), r * s.sin()))
        .collect()
}

fn disk_uv(a: f64, b: f64) -> DVec2 {
    DVec2::new(0.5 * (a + 1.0), 0.5 * (b + 1.0))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn parallelogram_hits_where_0_le_alpha_beta_le_1(frame in frame(), a in -0.5f64..1.5, b in -0.5f64..1.5) {
        check_hit(Parallelogram, frame, a, b, DVec2::new)?;
    }

    #[test]
    fn triangle_hits_where_alpha_beta_ge_0_and_their_sum_le_1(frame in frame(), a in -0.5f64..1.5, b in -0.5f64..1.5) {
        check_hit(Triangle, frame, a, b, DVec2::new)?;
    }

    #[test]
    fn disk_hits_where_alpha2_plus_beta2_le_1(frame in frame(), a in -1.5f64..1.5, b in -1.5f64..1.5) {
        check_hit(Disk, frame, a, b, disk_uv)?;
    }

    #[test]
    fn ring_hits_between_its_radii(frame in frame(), a in -1.5f64..1.5, b in -1.5f64..1.5, inner in 0.0f64..0.99) {
        check_hit(Ring::new(inner).unwrap(), frame, a, b, disk_uv)?;
    }

    #[test]
    fn a_ring_with_no_hole_is_the_disk(frame in frame(), a in -1.5f64..1.5, b in -1.5f64..1.5) {
        let ring = Quad::with_interior(frame.0, frame.1, frame.2, Ring::new(0.0).unwrap()).unwrap();
        let disk = Quad::with_interior(frame.0, frame.1, frame.2, Disk).unwrap();
        let ray = ray_at(frame, a, b);
        let forward = Interval::FORWARD;
        prop_assert_eq!(ring.hit(&ray, forward), disk.hit(&ray, forward));
        prop_assert_eq!(ring.bounding_box(), disk.bounding_box());
        prop_assert_eq!(Ring::new(0.0).unwrap().contains(a, b), Disk.contains(a, b));
    }

    #[test]
    fn bounding_boxes_contain_every_point_of_their_shape(frame in frame()) {
        let grid: Vec<(f64, f64)> = (0..=8).flat_map(|i| (0..=8).map(move |j| (f64::from(i) / 8.0, f64::from(j) / 8.0))).collect();
        check_box(Parallelogram, frame, &grid)?;
        let tri: Vec<(f64, f64)> = grid.iter().copied().filter(|(a, b)| a + b <= 1.0).collect();
        check_box(Triangle, frame, &tri)?;
        check_box(Disk, frame, &circle(1.0))?;
        check_box(Ring::new(0.5).unwrap(), frame, &circle(1.0))?;
    }
}

#[test]
fn edges_and_corners_are_inclusive() {
    let frame = (DVec3::ZERO, DVec3::X, DVec3::Y);
    for (a, b) in [(0.0, 0.0), (1.0, 1.0), (0.0, 0.5), (1.0, 0.25), (0.5, 1.0)] {
        assert!(Parallelogram.contains(a, b), "({a}, {b})");
    }
    for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.5)] {
        assert!(Triangle.contains(a, b), "({a}, {b})");
    }
    for (a, b) in [(1.0, 0.0), (0.0, -1.0), (0.6, 0.8)] {
        assert!(Disk.contains(a, b), "({a}, {b})");
        assert!(Ring::new(0.5).unwrap().contains(a, b), "({a}, {b})");
    }
    assert!(
        Ring::new(0.5).unwrap().contains(0.5, 0.0) && Ring::new(0.5).unwrap().contains(0.3, 0.4)
    );
    // And through a quad, at exactly representable corner points.
    let quad = Quad::new(frame.0, frame.1, frame.2).unwrap();
    for (a, b) in [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0)] {
        assert!(
            quad.hit(&ray_at(frame, a, b), Interval::UNIVERSE).is_some(),
            "corner ({a}, {b})"
        );
    }
}

#[test]
fn a_disk_box_is_the_ellipse_extent_not_the_parallelogram() {
    // Semi-axes (1, 1, 0) and (-1, 1, 0): a circle of radius sqrt(2) centred at q.
    let q = DVec3::new(10.0, 0.0, 0.0);
    let disk = Quad::with_interior(
        q,
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.0),
        Disk,
    )
    .unwrap();
    let b = disk.bounding_box();
    let r = 2f64.sqrt();
    assert!(
        (b.max().x - (q.x + r)).abs() < 1e-12 && (b.min().y + r).abs() < 1e-12,
        "{b:?}"
    );
}

#[test]
fn closures_are_interiors() {
    let quad = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, |a: f64, b: f64| {
        a > 0.5 && (0.0..=1.0).contains(&b)
    })
    .unwrap();
    let forward = Interval::FORWARD;
    assert!(
        quad.hit(
            &ray_at((DVec3::ZERO, DVec3::X, DVec3::Y), 0.75, 0.5),
            forward
        )
        .is_some()
    );
    assert!(
        quad.hit(
            &ray_at((DVec3::ZERO, DVec3::X, DVec3::Y), 0.25, 0.5),
            forward
        )
        .is_none()
    );
    // Its extent is unknown: the plane's box (a slab here), grown by the tolerance that
    // every quad's box holds.
    let (b, slab) = (quad.bounding_box(), quad.plane().bounding_box());
    assert_eq!((b.min().x, b.max().y), (f64::NEG_INFINITY, f64::INFINITY));
    assert!(b.min().z <= slab.min().z && slab.max().z <= b.max().z && b.max().z < 1e-12);
}
