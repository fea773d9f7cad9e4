//! `Transformed::affine`: instances under scales (uniform and not), shears and mirrors,
//! built as scene files hold them (a random rotation times scales from 1e-3 to 1e3,
//! non-uniform to 1:100, mirrors, offsets to 1e9), hold the contract: a hit lies within its
//! stated bound of the mapped shape (measured in double-double, and against the same quad
//! built at its size), a mapped closed mesh lets no ray through its edges and corners, a
//! spawned ray never finds the surface it leaves, hits stay in the box and a tree of
//! instances answers as their loop, normals are unit and face against the ray, sampled
//! directions have a positive density, and bad maps are errors. (Densities are held by
//! `tests/chi_square.rs`.)

mod support;

use std::sync::Arc;

use hitkit::glam::{DAffine3, DMat3, DVec2, DVec3};
use hitkit::{
    Affine, Bvh, GeometryError, HitRecord, Hittable, Interval, PdfHittable, Quad, Ray, Sphere,
    Transformed, TriangleMesh,
};
use support::{SplitMix, gamma, rotation};

const FORWARD: Interval = Interval::FORWARD;

/// A map as a scene file gives one: a random rotation, per-axis scales drawn
/// log-uniformly from an overall size of 1e-3 to 1e3 times a spread up to 1:100, a mirror
/// one time in three, then a second rotation (so the scales are not along the axes: a
/// shear), and an offset up to 1e9.
fn scene_map(rng: &mut SplitMix) -> DAffine3 {
    let size = 10f64.powf(6.0 * rng.next_f64() - 3.0);
    let spread = |rng: &mut SplitMix| 10f64.powf(2.0 * rng.next_f64() - 1.0);
    let mut scales = size * DVec3::new(spread(rng), spread(rng), spread(rng));
    if rng.next_f64() < 1.0 / 3.0 {
        scales.y = -scales.y;
    }
    let linear = rotation(rng) * DMat3::from_diagonal(scales) * rotation(rng);
    let offset = 10f64.powf(9.0 * rng.next_f64()) * rng.direction();
    DAffine3::from_mat3_translation(linear, offset)
}

/// The unit square, centred on the origin, that the instances share.
fn square() -> Quad {
    Quad::new(DVec3::new(-0.5, -0.5, 0.0), DVec3::X, DVec3::Y).unwrap()
}

/// The world ray toward the mapped square's point at `(alpha, beta)`, from a random
/// direction, a few times the square's size away.
fn ray_toward(map: &DAffine3, rng: &mut SplitMix, alpha: f64, beta: f64) -> Ray {
    let target = map.transform_point3(DVec3::new(alpha - 0.5, beta - 0.5, 0.0));
    let reach = 3.0 * map.matrix3.x_axis.length().max(map.matrix3.y_axis.length());
    let origin = target + reach * rng.direction();
    Ray::new(origin, target - origin)
}

/// A double-double number (the sum of two floats), for distances exact far past `f64`.
#[derive(Clone, Copy)]
struct Dd(f64, f64);

impl Dd {
    fn sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let v = s - a;
        Dd(s, (a - (s - v)) + (b - v))
    }
    fn add(self, o: Dd) -> Dd {
        let s = Dd::sum(self.0, o.0);
        Dd::sum(s.0, s.1 + self.1 + o.1)
    }
    fn mul(self, o: Dd) -> Dd {
        let p = self.0 * o.0;
        let e = self.0.mul_add(o.0, -p) + (self.0 * o.1 + self.1 * o.0);
        Dd::sum(p, e)
    }
    fn neg(self) -> Dd {
        Dd(-self.0, -self.1)
    }
}

/// The distance of `p` from the plane of the square under `map` (exactly, to
/// double-double), and the plane's unit normal: the plane through `c - (m0 + m1) / 2`
/// spanned by the matrix's first two columns `m0`, `m1`.
fn distance_to_mapped_plane(map: &DAffine3, p: DVec3) -> (f64, DVec3) {
    let (m0, m1, c) = (map.matrix3.x_axis, map.matrix3.y_axis, map.translation);
    let d = |x: f64| Dd(x, 0.0);
    let half = |x: f64| d(0.5 * x);
    let w: [Dd; 3] =
        std::array::from_fn(|i| Dd::sum(p[i], -c[i]).add(half(m0[i])).add(half(m1[i])));
    let cross = |i: usize, j: usize| d(m0[i]).mul(d(m1[j])).add(d(m0[j]).mul(d(m1[i])).neg());
    let n = [cross(1, 2), cross(2, 0), cross(0, 1)];
    let dot = n[0].mul(w[0]).add(n[1].mul(w[1])).add(n[2].mul(w[2]));
    let normal = DVec3::new(n[0].0, n[1].0, n[2].0);
    (dot.0.abs() / normal.length(), normal.normalize())
}

#[test]
fn a_mapped_square_hits_where_the_square_built_at_its_size_does() {
    let mut rng = SplitMix::new(391);
    for _ in 0..400 {
        let map = scene_map(&mut rng);
        let Ok(instance) = Transformed::affine(square(), map) else {
            panic!("{map:?}");
        };
        let m = map.matrix3;
        let (q, u, v) = (
            map.transform_point3(DVec3::new(-0.5, -0.5, 0.0)),
            m * DVec3::X,
            m * DVec3::Y,
        );
        let built = Quad::new(q, u, v).unwrap();
        // What building it at its size rounded: its corner `M q + c` (a sum of three
        // products and `c`, gamma(4)) and its edges (gamma(3) each), componentwise; the
        // plane it spans at a point `q + alpha u + beta v` is off the mapped square's by at
        // most that, for `alpha, beta` in [0, 1].
        let built_error = gamma(4) * (m.abs() * DVec3::new(0.5, 0.5, 0.0) + map.translation.abs())
            + gamma(3) * (u.abs() + v.abs());
        for _ in 0..20 {
            // Well inside (both find it) or well outside (neither does).
            let inside = rng.next_f64() < 0.7;
            let (alpha, beta) = if inside {
                (0.05 + 0.9 * rng.next_f64(), 0.05 + 0.9 * rng.next_f64())
            } else {
                (1.05 + rng.next_f64(), rng.next_f64())
            };
            let ray = ray_toward(&map, &mut rng, alpha, beta);
            let (a, b) = (instance.hit(&ray, FORWARD), built.hit(&ray, FORWARD));
            assert_eq!(a.is_some(), inside, "{map:?} {ray:?}");
            assert_eq!(b.is_some(), inside, "{map:?} {ray:?}");
            let (Some(a), Some(b)) = (a, b) else { continue };
            // Clause 1: the instance's point within its bound of the mapped plane, measured
            // in double-double (the distance's own error is ~1e-32 of the terms: nothing
            // against a bound of ulps); the built square's within its bound plus what
            // building it rounded.
            let (apart, unit) = distance_to_mapped_plane(&map, a.point);
            let bound = unit.abs().dot(a.point_error);
            assert!(apart <= bound, "{apart} > {bound}: {map:?} {ray:?}");
            let (apart, unit) = distance_to_mapped_plane(&map, b.point);
            assert!(
                apart <= unit.abs().dot(b.point_error + built_error),
                "{map:?} {ray:?}"
            );
            assert!((a.normal.length() - 1.0).abs() <= gamma(8), "{a:?}");
            assert!(a.normal.dot(ray.direction) < 0.0, "{a:?}");
            // Normals are the same line; a mirror keeps the object's sides (outward stays
            // outward), where a quad built from mirrored edges has its front flipped.
            assert!(a.normal.dot(b.normal) > 1.0 - 1e-6, "{a:?} {b:?}");
            let mirrored = m.determinant() < 0.0;
            assert_eq!(a.front_face, b.front_face != mirrored, "{map:?}");
            assert!(instance.bounding_box().contains(a.point), "{a:?}");
        }
    }
}

/// Rays spawned from `hit` in `directions` find nothing of the instance they leave (the
/// contract's clause 5).
fn assert_spawned_rays_leave(
    instance: &dyn Hittable,
    hit: &HitRecord,
    directions: impl IntoIterator<Item = DVec3>,
) {
    for direction in directions {
        let spawned = hit.spawn_ray(direction);
        let again = instance.hit(&spawned, FORWARD);
        assert!(
            again.is_none(),
            "{hit:?} found again by {spawned:?} at {again:?}"
        );
    }
}

#[test]
fn spawned_rays_never_find_the_mapped_surface_they_leave() {
    let mut rng = SplitMix::new(392);
    let ball = Sphere::new(DVec3::ZERO, 0.5).unwrap();
    let mesh = Arc::new(
        TriangleMesh::new(
            &[
                DVec3::new(-0.5, -0.5, 0.0),
                DVec3::new(0.5, -0.5, 0.0),
                DVec3::new(0.5, 0.5, 0.0),
                DVec3::new(-0.5, 0.5, 0.0),
            ],
            &[[0, 1, 2], [0, 2, 3]],
        )
        .unwrap(),
    );
    for _ in 0..300 {
        let map = scene_map(&mut rng);
        let flat: [Box<dyn Hittable>; 2] = [
            Box::new(Transformed::affine(square(), map).unwrap()),
            Box::new(Transformed::affine(mesh.clone(), map).unwrap()),
        ];
        for instance in &flat {
            for _ in 0..10 {
                let (alpha, beta) = (rng.next_f64(), rng.next_f64());
                let ray = ray_toward(&map, &mut rng, alpha, beta);
                if let Some(hit) = instance.hit(&ray, FORWARD) {
                    // Random directions, and straight off both sides.
                    let (a, b) = (rng.direction(), rng.direction());
                    let directions = [a, hit.normal, -hit.normal, b - hit.normal];
                    assert_spawned_rays_leave(instance.as_ref(), &hit, directions);
                }
            }
        }
        // An ellipsoid is convex: a ray spawned to its outer side finds nothing of it.
        let ellipsoid = Transformed::affine(ball, map).unwrap();
        let reach = 3.0
            * map
                .matrix3
                .abs()
                .to_cols_array()
                .into_iter()
                .fold(0.0, f64::max);
        for _ in 0..10 {
            let target = map.transform_point3(0.5 * rng.direction());
            let origin = target + reach * rng.direction();
            let Some(hit) = ellipsoid.hit(&Ray::new(origin, target - origin), FORWARD) else {
                continue;
            };
            assert!(ellipsoid.bounding_box().contains(hit.point), "{hit:?}");
            let outward = if hit.front_face {
                hit.normal
            } else {
                -hit.normal
            };
            let random = rng.direction();
            let outer = if random.dot(outward) > 0.0 {
                random
            } else {
                -random
            };
            assert_spawned_rays_leave(&ellipsoid, &hit, [outward, outer]);
        }
    }
}

#[test]
fn a_bvh_of_scaled_instances_of_one_mesh_answers_as_the_loop() {
    let mut rng = SplitMix::new(393);
    let (vertices, faces) = support::icosphere(2);
    let mesh = Arc::new(TriangleMesh::new(&vertices, &faces).unwrap());
    // A thousand instances share the mesh's faces; each holds a map and a box.
    let instances: Vec<Transformed<Arc<TriangleMesh>, Affine>> = (0..1000)
        .map(|i| {
            let scales = DVec3::new(
                0.5 + rng.next_f64(),
                0.1 + rng.next_f64(),
                0.5 + 2.0 * rng.next_f64(),
            );
            let turn = support::rotation(&mut rng);
            let at = 40.0 * (rng.vec3() - 0.5);
            let map = DAffine3::from_mat3_translation(turn * DMat3::from_diagonal(scales), at);
            Transformed::affine(mesh.clone(), map).map(|t| t.with_instance_id(i))
        })
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(Arc::strong_count(&mesh), 1001);
    let bvh = Bvh::new(instances.clone());
    for _ in 0..2000 {
        let origin = 60.0 * (rng.vec3() - 0.5);
        let ray = Ray::new(origin, rng.direction());
        let tree = bvh.hit(&ray, FORWARD);
        let looped = support::brute_force(&instances, &ray, FORWARD);
        assert_eq!(
            tree.map(|h| (h.t, h.instance, h.primitive)),
            looped.map(|(_, h)| (h.t, h.instance, h.primitive)),
            "{ray:?}"
        );
        assert_eq!(bvh.occluded(&ray, FORWARD), tree.is_some(), "{ray:?}");
    }
}

#[test]
fn sampled_directions_of_a_mapped_light_hit_it_with_a_positive_density() {
    let mut rng = SplitMix::new(394);
    let corners = [
        DVec2::ZERO,
        DVec2::new(0.0, 1.0 - f64::EPSILON / 2.0),
        DVec2::new(1.0 - f64::EPSILON / 2.0, 0.0),
        DVec2::splat(1.0 - f64::EPSILON / 2.0),
    ];
    for _ in 0..200 {
        let map = scene_map(&mut rng);
        let lights: [Box<dyn PdfHittable>; 2] = [
            Box::new(Transformed::affine(square(), map).unwrap()),
            Box::new(Transformed::affine(Sphere::new(DVec3::ZERO, 0.5).unwrap(), map).unwrap()),
        ];
        let reach = 4.0
            * map
                .matrix3
                .abs()
                .to_cols_array()
                .into_iter()
                .fold(0.0, f64::max);
        for light in &lights {
            let random: [DVec2; 4] =
                std::array::from_fn(|_| DVec2::new(rng.next_f64(), rng.next_f64()));
            for u in corners.into_iter().chain(random) {
                let origin = map.translation + reach * rng.direction();
                let direction = light.sample_direction(origin, u);
                let density = light.pdf_value(origin, direction);
                assert!(
                    density > 0.0 && density.is_finite(),
                    "{density} toward {direction} from {origin}: {map:?}"
                );
                assert!((direction.length() - 1.0).abs() <= gamma(8), "{direction}");
            }
            // Away from the light, nothing.
            let origin = map.translation + reach * DVec3::X;
            assert_eq!(light.pdf_value(origin, DVec3::X), 0.0);
        }
    }
}

#[test]
fn bad_maps_are_errors() {
    let square = square();
    let singular = DAffine3::from_mat3_translation(
        DMat3::from_cols(DVec3::X, DVec3::Y, DVec3::X + DVec3::Y),
        DVec3::ZERO,
    );
    assert!(matches!(
        Transformed::affine(square, singular),
        Err(GeometryError::InvalidParameter { .. })
    ));
    assert!(matches!(
        Transformed::scale(square, DVec3::new(1.0, 0.0, 1.0)),
        Err(GeometryError::InvalidParameter { .. })
    ));
    // Rows one rounding from dependent: the computed inverse is no inverse at all.
    let nearly = DMat3::from_cols(
        DVec3::new(1.0, 4.0, 7.0),
        DVec3::new(2.0, 5.0, 8.0),
        DVec3::new(3.0, 6.0, 9.0 + 2.0 * f64::EPSILON * 8.0),
    );
    assert!(matches!(
        Transformed::affine(square, DAffine3::from_mat3(nearly)),
        Err(GeometryError::InvalidParameter { .. })
    ));
    assert!(matches!(
        Transformed::scale(square, DVec3::new(f64::NAN, 1.0, 1.0)),
        Err(GeometryError::NonFinite { .. })
    ));
    let far = DAffine3::from_mat3_translation(DMat3::IDENTITY, DVec3::new(f64::INFINITY, 0.0, 0.0));
    assert!(matches!(
        Transformed::affine(square, far),
        Err(GeometryError::NonFinite { .. })
    ));
    assert_eq!(
        Transformed::scale(square, DVec3::splat(1e300)).unwrap_err(),
        GeometryError::OutOfRange
    );
    // A ray of any length, NaN or not, gives no NaN.
    let instance = Transformed::scale(square, DVec3::new(1e3, 1e-3, 7.0)).unwrap();
    for length in [1e-300, 1e-20, 1.0, 1e20, 1e300, f64::NAN] {
        let ray = Ray::new(
            DVec3::new(0.1, 0.0, 5.0),
            length * DVec3::new(0.0, 0.0, -1.0),
        );
        if let Some(hit) = instance.hit(&ray, FORWARD) {
            assert!(
                hit.point.is_finite() && hit.point_error.is_finite() && hit.normal.is_finite(),
                "{hit:?}"
            );
            assert_eq!(hit.normal, DVec3::Z);
        } else {
            assert!(
                length.is_nan() || length == 1e-300 || length == 1e300,
                "missed along {length}"
            );
        }
    }
}

#[test]
fn rays_through_the_edges_and_corners_of_a_mapped_closed_mesh_never_escape() {
    // Clause 2 under a map: a closed mesh stays closed, its faces decided in its own space.
    // Each ray starts inside (from where every ray must leave through some face) and
    // passes through a corner, an edge or a face, in world space; from outside, a ray
    // aimed at a corner on the outline could miss by the target's rounding, rightly.
    let mut rng = SplitMix::new(396);
    let (unit, faces) = support::icosphere(2);
    let mesh = Arc::new(TriangleMesh::new(&unit, &faces).unwrap());
    let triangles: Vec<[DVec3; 3]> = faces.iter().map(|f| f.map(|i| unit[i as usize])).collect();
    for _ in 0..100 {
        let map = scene_map(&mut rng);
        let closed = Transformed::affine(mesh.clone(), map).unwrap();
        for k in 0..60 {
            // A corner, a point of an edge, or a point inside a face, in world space.
            let face = triangles[(rng.next_u64() % triangles.len() as u64) as usize];
            let target = map.transform_point3(support::face_point(&mut rng, face, k));
            let origin = map.transform_point3(0.5 * rng.next_f64() * rng.direction());
            let ray = Ray::new(origin, target - origin);
            assert!(closed.hit(&ray, FORWARD).is_some(), "{map:?} {ray:?}");
            assert!(closed.occluded(&ray, FORWARD), "{map:?} {ray:?}");
        }
    }
}
