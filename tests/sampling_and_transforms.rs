//! Light sampling on quads (`SampleInterior`, `PdfHittable for Quad`), `Cuboid`, and
//! `Transformed`: sampled directions hit with a finite positive density that integrates to
//! 1, misses have density 0 and nothing is NaN, a cuboid faces outward, and a moved object
//! hits where the same object built in place does.

mod support;

use std::f64::consts::{FRAC_PI_2, PI};

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::{
    Cuboid, Disk, GeometryError, Hittable, Interval, Parallelogram, PdfHittable, Quad, Ray, Ring,
    SampleInterior, Transformed, Triangle,
};
use support::{SplitMix, gamma};

const FORWARD: Interval = Interval::FORWARD;

/// A light, its centre, and its unit normal.
struct Light {
    name: &'static str,
    light: Box<dyn PdfHittable>,
    on: DVec3,
    normal: DVec3,
}

/// The shape on a skewed frame; `centre` is its centroid in `(alpha, beta)`.
fn light<S: SampleInterior + 'static>(name: &'static str, shape: S, centre: DVec2) -> Light {
    let (q, u, v) = (
        DVec3::new(0.3, -0.2, 1.0),
        DVec3::new(1.5, 0.2, -0.3),
        DVec3::new(0.4, 1.2, 0.5),
    );
    let quad = Quad::with_interior(q, u, v, shape).unwrap();
    Light {
        name,
        on: q + centre.x * u + centre.y * v,
        normal: quad.plane().normal(),
        light: Box::new(quad),
    }
}

/// The four built-in shapes on one skewed frame, and a disk moved by a generic rotation.
fn lights() -> Vec<Light> {
    let axis = DVec3::new(1.0, -2.0, 0.5).normalize();
    let (rotation, translation) = (
        DQuat::from_axis_angle(axis, 0.7),
        DVec3::new(-3.0, 5.0, 2.5),
    );
    let moved = Quad::with_interior(DVec3::new(1.0, 1.0, 0.0), DVec3::X, DVec3::Y * 2.0, Disk);
    let moved = Transformed::new(moved.unwrap(), rotation, translation).unwrap();
    vec![
        light("parallelogram", Parallelogram, DVec2::splat(0.5)),
        light("triangle", Triangle, DVec2::splat(1.0 / 3.0)),
        light("disk", Disk, DVec2::ZERO),
        light("ring", Ring::new(0.6).unwrap(), DVec2::ZERO),
        Light {
            name: "moved disk",
            on: moved.rotation() * DVec3::new(1.0, 1.0, 0.0) + translation,
            normal: moved.rotation() * DVec3::Z,
            light: Box::new(moved),
        },
    ]
}

#[test]
fn sampled_directions_hit_the_light_with_a_finite_positive_density() {
    let mut rng = SplitMix::new(1);
    for Light {
        name,
        light,
        on,
        normal,
    } in lights()
    {
        let along = normal.any_orthonormal_vector();
        let origins = [
            ("near", on + 0.2 * normal),
            ("far", on + 500.0 * normal + 3.0 * along),
            ("oblique", on + 6.0 * along + 0.05 * normal),
            ("behind", on - 2.0 * normal),
        ];
        for (place, origin) in origins {
            for _ in 0..500 {
                let direction =
                    light.sample_direction(origin, DVec2::new(rng.next_f64(), rng.next_f64()));
                let ray = Ray::new(origin, direction);
                assert!(
                    light.hit(&ray, FORWARD).is_some(),
                    "{name} {place}: {ray:?} misses"
                );
                let pdf = light.pdf_value(origin, direction);
                assert!(pdf.is_finite() && pdf > 0.0, "{name} {place}: pdf {pdf}");
            }
        }
    }
}

/// The density over solid angle integrates to 1 over the sphere of directions: the mean of
/// `4 pi pdf(d)` over `N` uniform directions `d` estimates that integral. The test allows 5
/// standard errors, the standard error computed from the sample variance (a false failure
/// with probability under 1e-6 per light and origin, were the seed not fixed), and requires
/// that error to be under 0.015, so that a density off by 7.5% or more (a wrong area
/// factor, a missing cosine) fails. The origins see the light under a large solid angle,
/// which keeps the variance small enough for `N = 100_000` (a fraction of a second in debug
/// for all of them).
#[test]
fn the_density_integrates_to_one_over_the_sphere() {
    const N: usize = 100_000;
    let mut rng = SplitMix::new(2);
    for Light {
        name,
        light,
        on,
        normal,
    } in lights()
    {
        let along = normal.any_orthonormal_vector();
        for origin in [on + normal, on - normal + 0.3 * along] {
            let values: Vec<f64> = (0..N)
                .map(|_| 4.0 * PI * light.pdf_value(origin, rng.direction()))
                .collect();
            let mean = values.iter().sum::<f64>() / N as f64;
            let variance = values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (N - 1) as f64;
            let error = (variance / N as f64).sqrt();
            assert!(
                error < 0.015,
                "{name} from {origin}: standard error {error}"
            );
            assert!(
                (mean - 1.0).abs() <= 5.0 * error,
                "{name} from {origin}: integral {mean} +- {error}"
            );
        }
    }
}

#[test]
fn the_density_is_zero_off_the_light_and_never_nan() {
    let mut rng = SplitMix::new(3);
    for Light {
        name,
        light,
        on,
        normal,
    } in lights()
    {
        let origin = on + normal;
        let toward = light.sample_direction(origin, DVec2::splat(0.3));
        let along = normal.any_orthonormal_vector();
        for direction in [
            -toward,
            along,
            normal,
            DVec3::ZERO,
            DVec3::NAN,
            DVec3::INFINITY,
        ] {
            assert_eq!(
                light.pdf_value(origin, direction),
                0.0,
                "{name} along {direction}"
            );
        }
        for origin in [DVec3::NAN, DVec3::INFINITY] {
            assert_eq!(light.pdf_value(origin, toward), 0.0, "{name} from {origin}");
        }
        // An origin on the light: in its plane to within rounding, so the density is 0 or
        // finite, whatever the direction.
        for _ in 0..200 {
            let pdf = light.pdf_value(on, rng.direction());
            assert!(
                pdf.is_finite() && pdf >= 0.0,
                "{name} from its own point: {pdf}"
            );
        }
        // A NaN or out-of-range sample point still gives a direction, and no NaN.
        for u in [DVec2::NAN, DVec2::new(-1.0, 2.0), DVec2::ONE] {
            assert!(
                light.sample_direction(origin, u).is_finite(),
                "{name} at {u}"
            );
        }
    }
    // Exactly in the plane of an axis-aligned quad: inside it, outside it, any direction.
    let quad = Quad::new(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    for origin in [DVec3::new(0.25, 0.5, 0.0), DVec3::new(3.0, 2.0, 0.0)] {
        for direction in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(0.3, 0.2, 0.5),
        ] {
            assert_eq!(
                quad.pdf_value(origin, direction),
                0.0,
                "from {origin} along {direction}"
            );
        }
    }
}

/// Corners on multiples of 1/4, so that faces, edges and the rays below are exact.
fn cuboid() -> Cuboid {
    Cuboid::new(DVec3::new(2.0, 1.0, 1.5), DVec3::new(-1.0, -2.0, -0.5)).unwrap()
}

#[test]
fn a_cuboid_faces_outward_on_all_six_sides() {
    let block = cuboid();
    let centre = DVec3::new(0.5, -0.5, 0.5);
    let half = DVec3::new(1.5, 1.5, 1.0);
    for (axis, face) in [(2, 0), (0, 1), (2, 2), (0, 3), (1, 4), (1, 5)] {
        let outward = block.faces()[face].plane().normal();
        let mut offset = DVec3::ZERO;
        offset[axis] = outward[axis] * (half[axis] + 4.0);
        // Straight at the face, and slanted through a point off its centre.
        for origin in [centre + offset, centre + offset + 0.25 * half] {
            let ray = Ray::new(origin, centre - origin);
            let hit = block
                .hit(&ray, FORWARD)
                .expect("a ray from outside toward the centre");
            assert!(hit.front_face, "face {face}");
            assert_eq!(hit.normal, outward, "face {face}");
            assert_eq!(hit.point[axis], centre[axis] + outward[axis] * half[axis]);
            assert!(block.bounding_box().contains(hit.point));
        }
    }
}

#[test]
fn a_ray_from_inside_a_cuboid_hits_a_back_face() {
    let block = cuboid();
    let mut rng = SplitMix::new(4);
    for _ in 0..300 {
        let inside = DVec3::new(-1.0, -2.0, -0.5)
            + DVec3::new(3.0, 3.0, 2.0)
                * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
        let ray = Ray::new(inside, rng.direction());
        let hit = block
            .hit(&ray, FORWARD)
            .expect("a closed box holds every ray from inside");
        assert!(
            !hit.front_face && hit.normal.dot(ray.direction) < 0.0,
            "{ray:?}"
        );
        assert!(block.occluded(&ray, FORWARD));
    }
}

#[test]
fn rays_through_cuboid_edges_and_corners_do_not_slip_through() {
    let block = cuboid();
    let (lo, hi) = (DVec3::new(-1.0, -2.0, -0.5), DVec3::new(2.0, 1.0, 1.5));
    let mut targets = Vec::new();
    for x in [lo.x, 0.5, hi.x] {
        for y in [lo.y, -0.5, hi.y] {
            for z in [lo.z, 0.5, hi.z] {
                let on_bounds = [
                    x == lo.x || x == hi.x,
                    y == lo.y || y == hi.y,
                    z == lo.z || z == hi.z,
                ];
                if on_bounds.iter().filter(|&&b| b).count() >= 2 {
                    targets.push(DVec3::new(x, y, z)); // an edge midpoint or a corner
                }
            }
        }
    }
    for target in targets {
        let out = (target - DVec3::new(0.5, -0.5, 0.5)).signum();
        // From outside, through the point (exact: small multiples of 1/4), slanted a little
        // differently each time.
        for slant in [
            DVec3::new(1.0, 0.5, 0.25),
            DVec3::new(0.25, 1.0, 0.5),
            DVec3::new(0.5, 0.25, 1.0),
        ] {
            let origin = target + out * (DVec3::splat(2.0) + slant);
            let ray = Ray::new(origin, target - origin);
            let hit = block.hit(&ray, FORWARD);
            assert!(
                hit.is_some_and(|h| h.t == 1.0),
                "{ray:?} through {target}: {hit:?}"
            );
        }
    }
}

/// The quarter turn about y maps `(x, y, z)` to `(z, y, -x)`; with the translation below it
/// maps every corner used here to multiples of 1/4, so the world-space build is exact.
fn quarter_turn(p: DVec3) -> DVec3 {
    DVec3::new(p.z, p.y, -p.x)
}

const MOVE: DVec3 = DVec3::new(3.25, -1.5, 2.0);

/// Through the quarter turn, every face plane of the moved object is axis aligned, and its
/// `t = (face_i - o_i) / d_i` along the face's axis `i` differs from the in-place object's
/// only by the rounding of the object-space origin `o - MOVE`: at most `u |o_i - MOVE_i|`
/// in the numerator, divided by `|d_i|`, plus two roundings (subtraction, division) of
/// each `t`: `|dt| <= 2 gamma(2) |t| + gamma(2) |o_i - MOVE_i| / |d_i|`, rounded up to
/// `3 gamma(2) |t|` for the second-order terms. (The rotation itself, a matrix of 0s and
/// ±1s, is exact.)
fn t_tolerance(t: f64, origin: DVec3, direction: DVec3, axis: usize) -> f64 {
    3.0 * gamma(2) * t.abs() + gamma(2) * (origin[axis] - MOVE[axis]).abs() / direction[axis].abs()
}

fn axis_of(normal: DVec3) -> usize {
    normal.abs().max_position()
}

#[test]
fn a_quarter_turned_cuboid_hits_like_one_built_in_place() {
    let (a, b) = (DVec3::new(-1.0, -0.5, -0.75), DVec3::new(1.5, 1.0, 0.25));
    let object = Cuboid::new(a, b).unwrap();
    let moved = Transformed::translate(Transformed::rotate_y(object, 90.0).unwrap(), MOVE).unwrap();
    let in_place = Cuboid::new(quarter_turn(a) + MOVE, quarter_turn(b) + MOVE).unwrap();
    let (lo, hi) = (in_place.bounding_box().min(), in_place.bounding_box().max());
    let mut rng = SplitMix::new(5);
    for _ in 0..500 {
        // From a sphere around the box, toward a point well inside it (no edge is near).
        let target = lo
            + (hi - lo) * (0.1 + 0.8 * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()));
        let origin = target + 6.0 * rng.direction();
        let ray = Ray::new(origin, target - origin);
        let (got, want) = (
            moved.hit(&ray, FORWARD).unwrap(),
            in_place.hit(&ray, FORWARD).unwrap(),
        );
        assert_eq!(
            (got.normal, got.front_face),
            (want.normal, want.front_face),
            "{ray:?}"
        );
        let tol = t_tolerance(want.t, origin, ray.direction, axis_of(want.normal));
        assert!(
            (got.t - want.t).abs() <= tol,
            "t {} vs {} (tolerance {tol})",
            got.t,
            want.t
        );
        assert!(moved.bounding_box().contains(got.point), "{got:?} outside");
        assert!(moved.occluded(&ray, FORWARD));
    }
}

#[test]
fn a_quarter_turned_light_has_the_density_of_one_built_in_place() {
    // A quad in the object's xy plane with skewed edges: its plane, and the moved one's,
    // are axis aligned, so both normals and areas are exact.
    let (q, u, v) = (
        DVec3::new(-0.5, -0.25, 0.75),
        DVec3::new(1.5, 0.5, 0.0),
        DVec3::new(-0.25, 1.0, 0.0),
    );
    check_quarter_turned_light(q, u, v, Parallelogram);
    check_quarter_turned_light(q, u, v, Triangle);
    check_quarter_turned_light(q, u, v, Disk);
    check_quarter_turned_light(q, u, v, Ring::new(0.5).unwrap());
}

/// The two densities `(t |d|)^2 / (cos A)` differ by twice the relative difference of `t`
/// (see `t_tolerance`) and of `|d|` (each computed with a relative error of at most
/// `gamma(3)`, the two summing the same squares in different orders), by the cosine's (one
/// more division: `gamma(4)` each) and by the final products and quotient (4 roundings
/// each); `A` is exact in both.
fn check_quarter_turned_light<S: SampleInterior + Copy + 'static>(
    q: DVec3,
    u: DVec3,
    v: DVec3,
    shape: S,
) {
    let object = Quad::with_interior(q, u, v, shape).unwrap();
    let moved = Transformed::translate(Transformed::rotate_y(object, 90.0).unwrap(), MOVE).unwrap();
    let in_place = Quad::with_interior(
        quarter_turn(q) + MOVE,
        quarter_turn(u),
        quarter_turn(v),
        shape,
    )
    .unwrap();
    assert_eq!(in_place.area(), object.area());
    let normal = in_place.plane().normal();
    let mut rng = SplitMix::new(6);
    for _ in 0..300 {
        let origin = in_place.plane().q() + 3.0 * rng.direction();
        // Toward a point of the shape clear of its edges.
        let direction = in_place.sample_direction(
            origin,
            DVec2::splat(0.05) + 0.9 * DVec2::new(rng.next_f64(), rng.next_f64()),
        );
        let (got, want) = (
            moved.pdf_value(origin, direction),
            in_place.pdf_value(origin, direction),
        );
        let axis = axis_of(normal);
        let t = normal.dot(in_place.plane().q() - origin) / normal.dot(direction);
        let dt = t_tolerance(t, origin, direction, axis) / t.abs();
        let tol = 2.0 * dt + 4.0 * gamma(3) + 2.0 * gamma(4) + gamma(8);
        assert!(
            want > 0.0 && (got - want).abs() <= tol * want,
            "{got} vs {want} (relative tolerance {tol})"
        );
        // The moved light's own samples hit it, over the whole of [0, 1)^2.
        let sampled = moved.sample_direction(origin, DVec2::new(rng.next_f64(), rng.next_f64()));
        assert!(moved.hit(&Ray::new(origin, sampled), FORWARD).is_some());
    }
}

#[test]
fn spawned_rays_do_not_hit_a_moved_surface_again() {
    let quad = Quad::new(DVec3::new(-1.0, -1.0, 0.0), DVec3::X * 2.0, DVec3::Y * 2.0).unwrap();
    let rotation = DQuat::from_axis_angle(DVec3::new(0.3, 1.0, -0.2).normalize(), 1.1);
    let mut rng = SplitMix::new(7);
    for far in [1.0, 1e3, 1e6, 1e9] {
        let moved = Transformed::new(quad, rotation, DVec3::new(0.7, -0.4, 0.9) * far).unwrap();
        let (centre, normal) = (moved.translation(), moved.rotation() * DVec3::Z);
        for _ in 0..300 {
            let target = centre
                + moved.rotation()
                    * DVec3::new(2.0 * rng.next_f64() - 1.0, 2.0 * rng.next_f64() - 1.0, 0.0);
            let origin = target + 5.0 * rng.direction();
            let Some(hit) = moved.hit(&Ray::new(origin, target - origin), FORWARD) else {
                continue;
            };
            for bounce in [rng.direction(), normal, -normal] {
                let spawned = hit.spawn_ray(bounce);
                assert!(
                    moved.hit(&spawned, FORWARD).is_none(),
                    "at {far}: {hit:?} re-hit by {spawned:?}"
                );
            }
        }
    }
}

#[test]
fn a_generic_rotation_keeps_the_bounding_box_around_the_hits() {
    let block = cuboid();
    let axis = DVec3::new(1.0, 2.0, -0.5).normalize();
    let moved = Transformed::new(
        block,
        DQuat::from_axis_angle(axis, 2.0),
        DVec3::new(1e4, -3.0, 7.0),
    )
    .unwrap();
    let mut rng = SplitMix::new(8);
    for _ in 0..300 {
        let target = moved.translation() + 1.5 * rng.direction();
        let origin = target + 10.0 * rng.direction();
        let ray = Ray::new(origin, target - origin);
        if let Some(hit) = moved.hit(&ray, Interval::UNIVERSE) {
            assert!(moved.bounding_box().contains(hit.point), "{hit:?}");
            assert!((hit.normal.length() - 1.0).abs() <= gamma(8));
        }
    }
}

#[test]
fn bad_cuboid_and_transform_inputs_are_errors() {
    let (a, b) = (DVec3::ZERO, DVec3::ONE);
    let nan = DVec3::new(0.0, f64::NAN, 0.0);
    assert_eq!(
        Cuboid::new(nan, b),
        Err(GeometryError::NonFinite { what: "a" })
    );
    assert_eq!(
        Cuboid::new(a, DVec3::INFINITY),
        Err(GeometryError::NonFinite { what: "b" })
    );
    assert!(matches!(
        Cuboid::new(a, DVec3::new(1.0, 0.0, 1.0)),
        Err(GeometryError::InvalidParameter {
            what: "cuboid extent along y",
            ..
        })
    ));
    assert_eq!(
        Cuboid::new(DVec3::splat(-1e308), DVec3::splat(1e308)),
        Err(GeometryError::OutOfRange)
    );
    assert_eq!(
        Cuboid::new(a, DVec3::splat(1e-200)),
        Err(GeometryError::OutOfRange)
    );

    let block = cuboid();
    let nan_rotation = DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0);
    assert_eq!(
        Transformed::new(block, nan_rotation, a),
        Err(GeometryError::NonFinite { what: "rotation" })
    );
    assert_eq!(
        Transformed::new(block, DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0), a),
        Err(GeometryError::ZeroVector { what: "rotation" })
    );
    assert_eq!(
        Transformed::new(block, DQuat::IDENTITY, nan),
        Err(GeometryError::NonFinite {
            what: "translation"
        })
    );
    assert_eq!(
        Transformed::rotate_y(block, f64::INFINITY),
        Err(GeometryError::NonFinite {
            what: "rotation angle"
        })
    );
    assert_eq!(
        Transformed::translate(block, DVec3::NEG_INFINITY),
        Err(GeometryError::NonFinite {
            what: "translation"
        })
    );

    // Any non-zero finite quaternion is a rotation, however large or small its components.
    let turn = DQuat::from_rotation_y(FRAC_PI_2);
    for scale in [1e300, 1e-300] {
        let scaled = DQuat::from_xyzw(
            turn.x * scale,
            turn.y * scale,
            turn.z * scale,
            turn.w * scale,
        );
        let moved = Transformed::new(block, scaled, a).unwrap();
        assert!(moved.rotation().abs_diff_eq(
            Transformed::rotate_y(block, 90.0).unwrap().rotation(),
            1e-15
        ));
    }
}
