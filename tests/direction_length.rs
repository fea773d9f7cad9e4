//! A ray's direction may have any length f64 holds: `Ray::new(o, d)` and
//! `Ray::new(o, d * 2^k)` are the same ray. Whatever `k`, drawn across f64's whole exponent
//! range, every shape, instance and tree finds the same hit (the same point, `t` scaled by
//! `2^-k`), `occluded` agrees with `hit`, a `Bvh` answers as the shape alone, nothing is NaN,
//! and a light's density over solid angle is the same.
//!
//! The scalings are exact (a direction whose scaling would round is not drawn), so the
//! answers must be equal bit for bit: every formula hitkit uses is homogeneous in the
//! direction, and power-of-two scalings commute with rounding away from over- and
//! underflow.

mod support;

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::{
    Bvh, Cuboid, Disk, Emission, HitRecord, Hittable, Interval, LightTree, Mixture, Moving,
    PdfHittable, Plane, Quad, Ray, Ring, Sphere, Transformed, Triangle, TriangleMesh,
};
use proptest::prelude::*;
use support::icosphere;

const FORWARD: Interval = Interval::FORWARD;

/// `x * 2^k`, or `None` where that rounds (over- or underflows): two factors, each a
/// normal power of two, and the way back must give `x` again.
fn times_two_to(x: DVec3, k: i32) -> Option<DVec3> {
    let p = |e: i32| 2f64.powi(e);
    let (a, b) = (k / 2, k - k / 2);
    let y = x * p(a) * p(b);
    (y.is_finite() && y * p(-a) * p(-b) == x).then_some(y)
}

/// A kind of shape, placed at `centre` with size `size`, turned by `turn`.
fn shape(kind: u8, centre: DVec3, size: f64, turn: DQuat) -> Box<dyn Hittable> {
    let (u, v) = (turn * DVec3::X * size, turn * DVec3::Y * size);
    let q = centre - 0.5 * (u + v);
    let sphere = || Sphere::new(centre, 0.5 * size).unwrap();
    match kind % 12 {
        0 => Box::new(Quad::new(q, u, v).unwrap()),
        1 => Box::new(Quad::with_interior(q, u, v, Triangle).unwrap()),
        2 => Box::new(Quad::with_interior(centre, u, v, Disk).unwrap()),
        3 => Box::new(Quad::with_interior(centre, u, v, Ring::new(0.4).unwrap()).unwrap()),
        4 => Box::new(sphere()),
        5 => Box::new(Cuboid::new(q, q + u + v + turn * DVec3::Z * size).unwrap()),
        6 => Box::new(
            Transformed::new(Quad::new(-0.5 * (u + v), u, v).unwrap(), turn, centre).unwrap(),
        ),
        7 => Box::new(
            Transformed::new(Sphere::new(DVec3::ZERO, 0.5 * size).unwrap(), turn, centre).unwrap(),
        ),
        8 => Box::new(Moving::new(sphere(), u).unwrap()),
        9 => Box::new(mesh(centre, size, turn)),
        10 => Box::new(Plane::new(q, u, v).unwrap()),
        _ => Box::new(Bvh::new(vec![
            shape(0, centre, size, turn),
            shape(4, centre + u, 0.5 * size, turn),
            shape(9, centre - v, size, turn),
        ])),
    }
}

/// An icosphere of 80 faces.
fn mesh(centre: DVec3, size: f64, turn: DQuat) -> TriangleMesh {
    let (vertices, faces) = icosphere(1);
    let vertices: Vec<DVec3> = vertices
        .iter()
        .map(|&p| centre + turn * p * (0.5 * size))
        .collect();
    TriangleMesh::new(&vertices, &faces).unwrap()
}

/// A light of one of the kinds that can be sampled.
fn light(kind: u8, centre: DVec3, size: f64, turn: DQuat) -> Box<dyn PdfHittable> {
    let (u, v) = (turn * DVec3::X * size, turn * DVec3::Y * size);
    let q = centre - 0.5 * (u + v);
    match kind % 6 {
        0 => Box::new(Quad::new(q, u, v).unwrap()),
        1 => Box::new(Quad::with_interior(q, u, v, Triangle).unwrap()),
        2 => Box::new(Quad::with_interior(centre, u, v, Disk).unwrap()),
        3 => Box::new(Sphere::new(centre, 0.5 * size).unwrap()),
        4 => Box::new(
            Transformed::new(Quad::new(-0.5 * (u + v), u, v).unwrap(), turn, centre).unwrap(),
        ),
        _ => Box::new(mesh(centre, size, turn)),
    }
}

/// The fields of a hit that must not depend on the direction's length.
fn seen(hit: &HitRecord) -> (DVec3, DVec3, bool, DVec2) {
    (hit.point, hit.normal, hit.front_face, hit.uv)
}

fn finite(hit: &HitRecord) -> bool {
    hit.t.is_finite()
        && hit.point.is_finite()
        && hit.point_error.is_finite()
        && hit.normal.is_finite()
        && hit.uv.is_finite()
}

/// A placed scene: where it is, how large, how turned, and a ray from outside it aimed at a
/// point near it (most hit), with direction components of 24 significant bits, so that
/// scalings stay exact down into f64's subnormals.
fn placed() -> impl Strategy<Value = (DVec3, f64, DQuat, DVec3, DVec3)> {
    (
        prop::array::uniform3(-1.0f64..1.0),
        prop_oneof![Just(0.0), Just(1e3), Just(1e6)],
        -3i32..=3,
        prop::array::uniform3(-1.0f64..1.0),
        0.0f64..std::f64::consts::TAU,
        prop::array::uniform3(-1.0f64..1.0),
        1.5f64..10.0,
        prop::array::uniform3(-0.8f64..0.8),
    )
        .prop_filter_map(
            "a direction",
            |(at, offset, e, axis, angle, from, far, aim)| {
                let size = 10f64.powi(e);
                let centre = DVec3::from(at) * offset;
                let turn = DQuat::from_axis_angle(DVec3::from(axis).try_normalize()?, angle);
                let origin = centre + DVec3::from(from).try_normalize()? * size * far;
                let target = centre + DVec3::from(aim) * size;
                let direction = (target - origin).as_vec3().as_dvec3();
                (direction != DVec3::ZERO).then_some((centre, size, turn, origin, direction))
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 1024,
        // Scalings that round are drawn again.
        max_global_rejects: 100_000,
        ..ProptestConfig::default()
    })]

    /// The same hit along `d` and along `d * 2^k`, for every kind of shape, instance and
    /// tree, with `k` from the subnormals to f64's largest directions.
    #[test]
    fn the_hit_does_not_depend_on_the_direction_length(
        kind in 0u8..12,
        (centre, size, turn, origin, direction) in placed(),
        k in -1100i32..1030,
    ) {
        let Some(scaled) = times_two_to(direction, k) else {
            return Err(TestCaseError::reject("the scaling rounds"));
        };
        let object = shape(kind, centre, size, turn);
        let tree = Bvh::new(vec![shape(kind, centre, size, turn)]);
        let (ray, far_ray) = (Ray::new(origin, direction), Ray::new(origin, scaled));
        let reference = object.hit(&ray, FORWARD);
        let hit = object.hit(&far_ray, FORWARD);
        // Clause 3 and the any-hit query, at every length.
        prop_assert_eq!(tree.hit(&far_ray, FORWARD), hit, "kind {}: the Bvh differs", kind);
        prop_assert_eq!(object.occluded(&far_ray, FORWARD), hit.is_some(), "kind {}", kind);
        prop_assert_eq!(tree.occluded(&far_ray, FORWARD), hit.is_some(), "kind {}", kind);
        if let Some(h) = &hit {
            prop_assert!(finite(h), "kind {}: {:?}", kind, h);
        }
        match reference {
            None => prop_assert!(hit.is_none(), "kind {}: found only along d * 2^{}", kind, k),
            Some(reference) => {
                // t along the scaled direction, where that is a normal number (a t past
                // f64's range cannot be reported; a subnormal one rounds).
                let expected = times_two_to(DVec3::splat(reference.t), -k).map(|t| t.x);
                if let Some(t) = expected.filter(|t| t.abs() >= f64::MIN_POSITIVE) {
                    let hit = hit.ok_or_else(|| {
                        TestCaseError::fail(format!("kind {kind}: lost along d * 2^{k} (t = {t:e})"))
                    })?;
                    prop_assert_eq!(hit.t, t, "kind {}, k {}", kind, k);
                    prop_assert_eq!(seen(&hit), seen(&reference), "kind {}, k {}", kind, k);
                }
            }
        }
    }

    /// A light's density over solid angle is the same along `d` and `d * 2^k`, alone and
    /// in a mixture and a light tree.
    #[test]
    fn a_density_does_not_depend_on_the_direction_length(
        kind in 0u8..6,
        (centre, size, turn, origin, direction) in placed(),
        k in -1100i32..1030,
    ) {
        let Some(scaled) = times_two_to(direction, k) else {
            return Err(TestCaseError::reject("the scaling rounds"));
        };
        let lights = || vec![light(kind, centre, size, turn), light(kind + 1, centre + turn * DVec3::Z * size, size, turn)];
        let one = light(kind, centre, size, turn);
        let mixture = Mixture::uniform(lights());
        let tree = LightTree::new(lights(), &[1.0, 2.0], &[Emission::Everywhere; 2]).unwrap();
        let samplers: [(&str, &dyn PdfHittable); 3] =
            [("alone", &*one), ("mixture", &mixture), ("tree", &tree)];
        for (what, sampler) in samplers {
            let (a, b) = (sampler.pdf_value(origin, direction), sampler.pdf_value(origin, scaled));
            prop_assert!(b.is_finite() && b >= 0.0, "{} kind {}: {}", what, kind, b);
            prop_assert_eq!(a, b, "{} kind {}, k {}", what, kind, k);
        }
    }
}

/// The reproducer: a cuboid in a `Bvh`, a direction of about `1e-300`; the cuboid
/// alone hits at `t = 1.6e301`, and so must the tree.
#[test]
fn a_bvh_finds_a_cuboid_along_a_direction_of_1e_minus_300() {
    let q = DVec3::new(7.846299635420155, 14.772719691658901, -14.95497618051579);
    let u = DVec3::new(
        -1.8666733996555938,
        -1.4387161155662676,
        -2.1048678127967646,
    );
    let ray = Ray::new(
        DVec3::new(-3.0334308269587362, 0.0, -9.936088894243778),
        DVec3::new(
            6.09891614866474e-301,
            8.350725673255905e-301,
            -4.299746295212241e-301,
        ),
    );
    let cuboid = Cuboid::new(q, q + u).unwrap();
    let alone = cuboid.hit(&ray, FORWARD).expect("the cuboid alone hits");
    assert_eq!(alone.t, 1.596747887287953e301);
    let tree = Bvh::new(vec![cuboid]);
    assert_eq!(tree.hit(&ray, FORWARD), Some(alone));
    assert!(tree.occluded(&ray, FORWARD));
}

/// The reproducer: a unit tetrahedron aimed at from the origin, at every direction
/// scale from `2^-1023` (components subnormal, `t` near f64's largest) up to `2^1000`.
#[test]
fn a_mesh_is_hit_at_every_direction_scale() {
    let vertices = [
        DVec3::new(1.0, 1.0, 4.0),
        DVec3::new(2.0, 1.0, 4.0),
        DVec3::new(1.0, 2.0, 4.0),
        DVec3::new(1.0, 1.0, 5.0),
    ];
    let mesh = TriangleMesh::new(&vertices, &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]).unwrap();
    let d = DVec3::new(1.25, 1.25, 4.5);
    let reference = mesh.hit(&Ray::new(DVec3::ZERO, d), FORWARD).unwrap();
    for k in -1023..=1000 {
        let scaled = times_two_to(d, k).unwrap();
        let hit = mesh
            .hit(&Ray::new(DVec3::ZERO, scaled), FORWARD)
            .unwrap_or_else(|| panic!("lost at 2^{k}"));
        assert_eq!(
            hit.t,
            times_two_to(DVec3::splat(reference.t), -k).unwrap().x,
            "2^{k}"
        );
        assert_eq!(hit.point, reference.point, "2^{k}");
    }
}

/// The reproducer: a sphere along a direction of `1e-160` (whose square underflows)
/// and of `1e160` (whose square overflows), as a shape, moving, and as a light.
#[test]
fn a_sphere_is_hit_and_sampled_along_directions_whose_squares_leave_f64() {
    let ball = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0).unwrap();
    let moving = Moving::new(ball, DVec3::new(0.0, 0.5, 0.0)).unwrap();
    let unit = Ray::new(DVec3::ZERO, DVec3::NEG_Z);
    let pdf = ball.pdf_value(DVec3::ZERO, DVec3::NEG_Z);
    assert!(pdf > 0.0);
    for length in [1e-160, 1e160] {
        let ray = Ray::new(DVec3::ZERO, DVec3::NEG_Z * length);
        assert_eq!(ball.hit(&ray, FORWARD).map(|h| h.t), Some(4.0 / length));
        assert_eq!(
            moving.hit(&ray, FORWARD).map(|h| h.point),
            moving.hit(&unit, FORWARD).map(|h| h.point)
        );
        assert_eq!(ball.pdf_value(DVec3::ZERO, ray.direction), pdf);
    }
}
