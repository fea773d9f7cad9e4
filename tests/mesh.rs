//! `TriangleMesh` against the contract, on meshes built as users build them (rotated, at
//! offsets to 1e12, sizes 1e-6 to 1e6), and instancing: a tree of moved instances of one
//! shared mesh answers as the same triangles flattened into one mesh.

mod support;

use std::sync::Arc;

use hitkit::glam::{DMat3, DQuat, DVec2, DVec3};
use hitkit::{Bvh, GeometryError, Hittable, Interval, PdfHittable, Ray, Transformed, TriangleMesh};
use proptest::prelude::*;
use support::distance::{planar_bound, to_polygon};
use support::{
    SplitMix, cube_corner, cube_faces, face_point, icosphere, instances, loop_over_faces,
    placements, rotation,
};

const FORWARD: Interval = Interval::FORWARD;

/// An icosphere of `levels` around `centre`, rotated: the vertices, the faces and the mesh.
fn sphere_mesh(
    centre: DVec3,
    radius: f64,
    rot: DMat3,
    levels: u32,
) -> (Vec<DVec3>, Vec<[u32; 3]>, TriangleMesh) {
    let (unit, faces) = icosphere(levels);
    let vertices: Vec<DVec3> = unit.iter().map(|&p| centre + rot * (radius * p)).collect();
    let mesh = TriangleMesh::new(&vertices, &faces).unwrap();
    (vertices, faces, mesh)
}

fn corners(vertices: &[DVec3], face: [u32; 3]) -> [DVec3; 3] {
    face.map(|i| vertices[i as usize])
}

/// The distance from `p` to the ray's line.
fn to_line(p: DVec3, ray: &Ray) -> f64 {
    let d = ray.direction.normalize();
    let rel = p - ray.origin;
    (rel - rel.dot(d) * d).length()
}

/// The tree finds what the loop over the faces finds (same face, same `t`, same point), on
/// rays from inside and from up to 1e12 times the mesh's size away, aimed at corners,
/// edges and faces, and grazing ones; and every hit lies on its face (clause 1: within
/// `2^-43 M / s^2`, as for a `Quad<Triangle>` on the same corners) and on the ray (to a few
/// ulps of the distance the ray travels, how well its own line is known).
#[test]
fn mesh_hits_equal_the_loop_over_its_faces_and_lie_on_them() {
    let mut rng = SplitMix::new(31);
    let (mut compared, mut hits) = (0, 0);
    for (offset, size) in placements() {
        let centre = DVec3::new(offset, -0.6 * offset, 0.3 * offset);
        let (vertices, faces, mesh) = sphere_mesh(centre, size, rotation(&mut rng), 2);
        for k in 0..200 {
            let face = faces[(rng.next_u64() % faces.len() as u64) as usize];
            let aim = face_point(&mut rng, corners(&vertices, face), k);
            let ray = match k % 5 {
                0 | 1 => Ray::new(centre + 0.3 * size * rng.vec3(), aim - centre),
                2 => {
                    let away = size * 10f64.powi(2 + (k % 11) as i32);
                    Ray::new(aim - away * rng.direction(), rng.direction())
                }
                3 => {
                    let away = size * 10f64.powi(2 + (k % 11) as i32);
                    let d = rng.direction();
                    Ray::new(aim - away * d, away * d)
                }
                _ => {
                    // Grazing: along the sphere's tangent at the aim.
                    let n = (aim - centre).normalize();
                    let along = n.any_orthonormal_vector();
                    Ray::new(aim - size * along, along + 1e-9 * rng.vec3())
                }
            };
            let expected = loop_over_faces(&mesh, &ray, FORWARD, |_| true);
            let found = mesh.hit(&ray, FORWARD);
            compared += 1;
            assert_eq!(found, expected, "offset {offset}, size {size}, ray {ray:?}");
            assert_eq!(mesh.occluded(&ray, FORWARD), expected.is_some());
            let Some(hit) = found else { continue };
            hits += 1;
            let face = faces[hit.primitive.unwrap() as usize];
            let [a, b, c] = corners(&vertices, face);
            let bound = planar_bound(a, b - a, c - a);
            let off = to_polygon(hit.point, &[a, b, c]);
            assert!(off <= bound, "hit {off:e} from its face (bound {bound:e})");
            let line = to_line(hit.point, &ray);
            let slack = 1e-14 * (ray.origin - hit.point).length();
            assert!(line <= bound + slack, "hit {line:e} from the ray");
        }
    }
    assert!(
        compared > 3000 && hits > compared / 2,
        "{hits} hits of {compared}"
    );
}

/// A hit is a hit of the exact ray on the exact face, from any distance: rays from 2^40
/// (about 1e12) times the face's size away, aimed at points within 1e-4 of its edges
/// (where `f64` alone misjudges the side: its rounding at that distance is about 1e-4 of
/// the size). Each ray is built so that its origin is exact (`t - 2^40 d` on the grid
/// both lie on), so the side it passes is the sign of `det(a - t, b - t, d)` per edge, a
/// determinant of numbers near 1, computed here to within 1e-15 and trusted only where it
/// is larger than 1e-12.
#[test]
fn rays_from_afar_are_decided_exactly_at_the_edges() {
    let mut rng = SplitMix::new(36);
    let (mut decided, mut inside) = (0, 0);
    let grid = |x: f64| (x * 4096.0).round() / 4096.0;
    for _ in 0..200 {
        let rot = rotation(&mut rng);
        let corners = [
            DVec3::new(-0.6, -0.4, 0.0),
            DVec3::new(0.7, -0.3, 0.0),
            DVec3::new(0.1, 0.6, 0.0),
        ]
        .map(|p| rot * p);
        let mesh = TriangleMesh::new(&corners, &[[0, 1, 2]]).unwrap();
        let n = rot * DVec3::Z;
        for k in 0..50 {
            let (a, b) = (corners[k % 3], corners[(k + 1) % 3]);
            let near = a + rng.next_f64() * (b - a) + 1e-4 * rng.vec3();
            let t = DVec3::new(grid(near.x), grid(near.y), grid(near.z));
            // A direction on a 2^-20 grid, not too close to the face's plane.
            let d = loop {
                let d = rng.direction();
                let d = DVec3::new(
                    (d.x * 1048576.0).round(),
                    (d.y * 1048576.0).round(),
                    (d.z * 1048576.0).round(),
                ) / 1048576.0;
                if d.normalize().dot(n).abs() > 0.2 {
                    break d;
                }
            };
            let origin = t - 2f64.powi(40) * d;
            assert_eq!(origin + 2f64.powi(40) * d, t, "the origin is exact");
            let det = |p: DVec3, q: DVec3| (p - t).cross(q - t).dot(d);
            let e = [
                det(corners[0], corners[1]),
                det(corners[1], corners[2]),
                det(corners[2], corners[0]),
            ];
            if e.iter().any(|e| e.abs() < 1e-12) {
                continue;
            }
            let truth = e.iter().all(|&e| e > 0.0) || e.iter().all(|&e| e < 0.0);
            let hit = mesh.hit(&Ray::new(origin, d), FORWARD).is_some();
            assert_eq!(hit, truth, "edge functions {e:?}");
            decided += 1;
            inside += usize::from(truth);
        }
    }
    assert!(
        decided > 8000 && inside > decided / 5 && inside < decided * 4 / 5,
        "{inside} of {decided}"
    );
}

/// Clause 2 on a `TriangleMesh`: a closed mesh with shared vertices, rotated, at every
/// offset to 1e12 and size from 1e-6 to 1e6: no ray from inside toward a corner, an edge
/// or a face escapes, nor one from outside aimed through them at the centre; and the same
/// through a `Bvh` of a moved instance of the mesh.
#[test]
fn closed_meshes_with_shared_vertices_never_leak() {
    let mut rng = SplitMix::new(32);
    let mut rays = 0;
    for (offset, size) in placements() {
        let centre = DVec3::new(-0.4 * offset, offset, 0.7 * offset);
        let rot = rotation(&mut rng);
        let (vertices, faces, mesh) = sphere_mesh(centre, size, rot, 3);
        // The same sphere built at the origin and moved there as an instance.
        let (_, _, local) = sphere_mesh(DVec3::ZERO, size, DMat3::IDENTITY, 3);
        let quat = DQuat::from_mat3(&rot);
        let scene = Bvh::new(vec![
            Transformed::new(Arc::new(local), quat, centre)
                .unwrap()
                .with_instance_id(7),
        ]);
        for k in 0..600 {
            let face = faces[(rng.next_u64() % faces.len() as u64) as usize];
            let aim = face_point(&mut rng, corners(&vertices, face), k);
            let inside = centre + 0.3 * size * rng.vec3();
            let out = Ray::new(inside, aim - inside);
            let outside = centre + (aim - centre) * (1.0 + 10f64.powi((k % 7) as i32));
            let back = Ray::new(outside, centre - outside);
            for ray in [out, back] {
                rays += 1;
                assert!(
                    mesh.hit(&ray, FORWARD).is_some(),
                    "leaked (offset {offset}, size {size}, ray {ray:?})"
                );
                assert!(mesh.occluded(&ray, FORWARD), "leaked from occluded()");
            }
            // The instance's corners were moved by the instance, so they are not the aim's;
            // aimed at its own centre from inside, every ray still has a face to meet.
            let hit = scene.hit(&out, FORWARD).expect("leaked from the instance");
            assert_eq!(hit.instance, Some(7));
        }
    }
    assert!(rays > 20000);
}

/// A thousand instances of one shared mesh, each rotated and moved, in a top-level `Bvh`,
/// hit the same faces as the same triangles moved one by one and flattened into one mesh:
/// the same instance and face, at the same point to within the rounding of moving the
/// corners (`gamma(5)` of their magnitudes, over the cosine of the ray with the face) and
/// of the two hits' own error bounds.
#[test]
fn instances_hit_the_faces_of_the_flattened_mesh() {
    let mut rng = SplitMix::new(33);
    let (moved, vertices, flat_faces) = instances(1, 1000, 1e3, 60.0, &mut rng);
    let faces = icosphere(1).1;
    let scene = Bvh::new(moved);
    let flat = TriangleMesh::new(&vertices, &flat_faces).unwrap();
    let per = faces.len() as u32;
    let mut matched = 0;
    for _ in 0..3000 {
        let face = flat_faces[(rng.next_u64() % flat_faces.len() as u64) as usize];
        let [a, b, c] = corners(&vertices, face);
        let aim = (a + b + c) / 3.0;
        let origin = 1e3 + 200.0 * rng.vec3();
        let ray = Ray::new(origin, aim - origin);
        let (Some(inst), Some(flat_hit)) = (scene.hit(&ray, FORWARD), flat.hit(&ray, FORWARD))
        else {
            panic!("an aimed ray missed: {ray:?}");
        };
        let id = inst.instance.unwrap() * per + inst.primitive.unwrap();
        assert_eq!(Some(id), flat_hit.primitive, "ray {ray:?}");
        let cos = flat_hit.normal.dot(ray.direction.normalize()).abs();
        let magnitude = 1e3 + 61.0;
        let tol = (inst.point_error + flat_hit.point_error).length()
            + 4.0 * support::gamma(5) * magnitude / cos;
        let apart = (inst.point - flat_hit.point).length();
        assert!(apart <= tol, "{apart:e} apart, tolerance {tol:e}");
        matched += 1;
    }
    assert_eq!(matched, 3000);
}

/// Bad meshes are errors that name the fault, never a panic.
#[test]
fn bad_meshes_are_errors() {
    let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
    assert_eq!(
        TriangleMesh::new(
            &[DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Y],
            &[[0, 1, 2]]
        )
        .unwrap_err(),
        GeometryError::NonFiniteElement {
            what: "vertex",
            index: 1
        }
    );
    let err = TriangleMesh::new(&v, &[[0, 1, 2], [0, 3, 2]]).unwrap_err();
    assert_eq!(
        err,
        GeometryError::IndexOutOfRange {
            face: 1,
            index: 3,
            vertices: 3
        }
    );
    assert_eq!(
        err.to_string(),
        "face 1 names vertex 3, but there are 3 vertices"
    );
    let huge = [DVec3::ZERO, DVec3::X * 1e300, DVec3::Y * 1e300];
    assert_eq!(
        TriangleMesh::new(&huge, &[[0, 1, 2]]).unwrap_err(),
        GeometryError::OutOfRange
    );
    let mesh = TriangleMesh::new(&v, &[[0, 1, 2]]).unwrap();
    assert!(matches!(
        mesh.clone().with_normals(&[DVec3::Z; 2]),
        Err(GeometryError::LengthMismatch {
            expected: 3,
            found: 2,
            ..
        })
    ));
    assert!(matches!(
        mesh.with_uvs(&[DVec2::ZERO, DVec2::ONE, DVec2::splat(f64::INFINITY)]),
        Err(GeometryError::NonFiniteElement {
            what: "uvs",
            index: 2
        })
    ));
    // An empty mesh is a mesh that nothing hits.
    let empty = TriangleMesh::new(&[], &[]).unwrap();
    assert!(
        empty
            .hit(&Ray::new(DVec3::ZERO, DVec3::X), FORWARD)
            .is_none()
    );
    assert_eq!(empty.pdf_value(DVec3::ZERO, DVec3::X), 0.0);
    assert_eq!(
        empty.sample_direction(DVec3::ZERO, DVec2::splat(0.5)),
        DVec3::ZERO
    );
}

/// Degenerate faces (repeated indices, repeated positions, three corners on a line) are
/// never hit, and the other faces keep the caller's numbers.
#[test]
fn degenerate_faces_keep_the_numbering() {
    let v = [
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::X, // a second copy of vertex 1's position
        2.0 * DVec3::X,
    ];
    let faces = [[0, 0, 2], [0, 1, 3], [0, 1, 4], [0, 1, 2]];
    let mesh = TriangleMesh::new(&v, &faces).unwrap();
    assert_eq!((mesh.face_count(), mesh.hittable_face_count()), (4, 1));
    let hit = mesh
        .hit(
            &Ray::new(DVec3::new(0.25, 0.25, 1.0), DVec3::NEG_Z),
            FORWARD,
        )
        .unwrap();
    assert_eq!(hit.primitive, Some(3));
    assert_eq!(mesh.faces().next().unwrap().index(), 3);
}

/// Vertex normals and texture coordinates are interpolated by the hit's barycentrics; the
/// shading normal lies on the side of the geometric one.
#[test]
fn normals_and_uvs_are_interpolated() {
    let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let n = [DVec3::Z, DVec3::new(1.0, 0.0, 1.0).normalize(), DVec3::Z];
    let uv = [DVec2::ZERO, DVec2::X, DVec2::Y];
    let mesh = TriangleMesh::new(&v, &[[0, 1, 2]])
        .unwrap()
        .with_normals(&n)
        .unwrap()
        .with_uvs(&uv)
        .unwrap();
    // From below: the geometric normal faces -z, and so does the shading normal.
    let ray = Ray::new(DVec3::new(0.5, 0.25, -1.0), DVec3::Z);
    let (hit, b) = mesh
        .faces()
        .next()
        .unwrap()
        .hit_barycentric(&ray, FORWARD)
        .unwrap();
    assert_eq!(b, DVec3::new(0.25, 0.5, 0.25));
    assert_eq!(hit.uv, DVec2::new(0.5, 0.25));
    assert_eq!(hit.normal, DVec3::NEG_Z);
    let expected = -(0.5 * DVec3::Z + 0.5 * n[1]).normalize();
    assert!((hit.shading_normal - expected).length() < 4.0 * f64::EPSILON);
    assert!(!hit.front_face);
}

/// A secondary ray spawned from a mesh hit does not hit the same mesh again on its own
/// side, at any placement.
#[test]
fn rays_spawned_from_mesh_hits_leave_the_surface() {
    let mut rng = SplitMix::new(34);
    let mut spawned = 0;
    for (offset, size) in placements() {
        let centre = DVec3::splat(offset);
        let (_, _, mesh) = sphere_mesh(centre, size, rotation(&mut rng), 2);
        for _ in 0..200 {
            let inside = centre + 0.3 * size * rng.vec3();
            let Some(hit) = mesh.hit(&Ray::new(inside, rng.direction()), FORWARD) else {
                panic!("leaked");
            };
            // Back into the sphere: the spawned ray must find another face, not this one;
            // out of it (a convex mesh): nothing.
            let inward = -hit.normal.dot(rng.direction()).signum() * rng.direction();
            let d = if inward.dot(hit.normal) > 0.0 {
                inward
            } else {
                -inward
            };
            let again = mesh.hit(&hit.spawn_ray(d), FORWARD);
            assert!(
                again.is_none_or(|h| h.primitive != hit.primitive),
                "re-hit its face"
            );
            let outward = if d.dot(hit.normal) > 0.0 { -d } else { d };
            assert!(mesh.hit(&hit.spawn_ray(outward), FORWARD).is_none());
            spawned += 1;
        }
    }
    assert!(spawned > 3000);
}

/// A room of walls on the coordinate planes, `x = 0` among them (as the book's Cornell box
/// is built): a ray spawned from a wall, as a bounce or as a shadow ray toward a point in
/// the room, never finds the wall it leaves, nor anything else (the room is convex from
/// inside). From a wall at zero, the last step of `spawn_ray` leaves the origin a hair
/// off it; the crossing's depths are then all about that hair, and a `t` computed from
/// them rounds to zero: its error bound must say so (it said zero once, and shadow rays
/// from the wall at `x = 0` found it at `t = -0`).
#[test]
fn rays_spawned_from_walls_at_zero_leave_them() {
    let mut rng = SplitMix::new(35);
    let mut spawned = 0;
    for size in [1e-3, 1.0, 555.0, 1e6] {
        let vertices: Vec<DVec3> = (0..8).map(|i| cube_corner(i) * size).collect();
        let room = TriangleMesh::new(&vertices, &cube_faces()).unwrap();
        for _ in 0..500 {
            let inside = |rng: &mut SplitMix| (0.05 + 0.9 * rng.vec3()) * size;
            let Some(hit) = room.hit(&Ray::new(inside(&mut rng), rng.direction()), FORWARD) else {
                panic!("leaked");
            };
            let into = if hit.normal.dot(DVec3::splat(size / 2.0) - hit.point) > 0.0 {
                hit.normal
            } else {
                -hit.normal
            };
            let bounce = hit.spawn_ray(into + rng.direction());
            if bounce.direction.dot(into) > 0.0 {
                let again = room.hit(&bounce, FORWARD);
                assert!(
                    again.is_some_and(|h| h.primitive != hit.primitive),
                    "re-hit its wall"
                );
            }
            let shadow = hit.spawn_ray(inside(&mut rng) - hit.point);
            assert!(
                !room.occluded(&shadow, Interval::new(0.0, 1.0)),
                "blocked by its wall"
            );
            spawned += 1;
        }
    }
    assert_eq!(spawned, 2000);
    // From that wall, the origin steps to 2^-900, past the subnormals (and far enough
    // that its distances times a rounding bound and a direction's reciprocal stay normal).
    let wall = TriangleMesh::new(&[DVec3::ZERO, DVec3::Y, DVec3::Z], &[[0, 1, 2]]).unwrap();
    let onto = Ray::new(DVec3::new(1.0, 0.2, 0.3), DVec3::NEG_X);
    let spawned = wall.hit(&onto, FORWARD).unwrap().spawn_ray(DVec3::X);
    assert_eq!(spawned.origin.x, 2f64.powi(-900));
    // The same, from an origin given a subnormal coordinate by hand.
    for x in [5e-324, 1e-320, 2.2e-308] {
        let ray = Ray::new(DVec3::new(x, 0.2, 0.3), DVec3::new(1.0, 0.1, 0.2));
        assert!(wall.hit(&ray, FORWARD).is_none() && !wall.occluded(&ray, FORWARD));
    }
    // While a crossing that far from the origin is too near to count (within its error
    // bound of it), one a little farther still counts: the bound's underflow term is a few
    // times the smallest normal number.
    let toward = Ray::new(DVec3::new(1e-300, 0.2, 0.3), DVec3::new(-1.0, 0.1, 0.2));
    assert!(wall.hit(&toward, FORWARD).is_some());
}

/// As a light: the density of a direction is the density of the points that send it,
/// summed over every face it crosses (a closed mesh: twice). Whatever a density is, the
/// mean of `1 / pdf` over its own samples is the measure of where it samples: here the
/// solid angle of the cone toward the mesh. The mesh is an icosphere inscribed in the unit
/// sphere, so its cone is a little narrower than the sphere's (by under 1% at this level);
/// with 20,000 samples the mean's own spread is well under that.
#[test]
fn a_mesh_samples_by_area() {
    let (unit, faces) = icosphere(3);
    let mesh = TriangleMesh::new(&unit, &faces).unwrap();
    let origin = DVec3::new(0.0, 0.0, 4.0);
    let mut rng = SplitMix::new(35);
    let n = 20000;
    let mut inverse = 0.0;
    for _ in 0..n {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        let d = mesh.sample_direction(origin, u);
        let pdf = mesh.pdf_value(origin, d);
        assert!(pdf > 0.0 && pdf.is_finite());
        inverse += 1.0 / pdf;
    }
    let solid_angle = inverse / f64::from(n);
    // The cone toward the unit sphere from distance 4: 2 pi (1 - cos), sin = 1/4.
    let sphere = std::f64::consts::TAU * (1.0 - (1.0 - 1.0 / 16.0f64).sqrt());
    assert!(
        solid_angle < sphere && solid_angle > 0.97 * sphere,
        "{solid_angle} against {sphere}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any vertices (NaN, infinite, huge, tiny) and any indices: a mesh or an error, and
    /// for a mesh, hits without NaN on any ray.
    #[test]
    fn any_input_gives_a_mesh_or_an_error(
        coords in proptest::collection::vec(
            prop_oneof![
                -1e3..1e3f64,
                Just(f64::NAN),
                Just(f64::INFINITY),
                Just(1e300),
                Just(-1e-300),
                Just(0.0),
            ],
            0..30,
        ),
        indices in proptest::collection::vec(0u32..12, 0..30),
        origin in proptest::array::uniform3(-1e6..1e6f64),
        direction in proptest::array::uniform3(-1.0..1.0f64),
    ) {
        let vertices: Vec<DVec3> = coords.chunks_exact(3).map(DVec3::from_slice).collect();
        let faces: Vec<[u32; 3]> = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        if let Ok(mesh) = TriangleMesh::new(&vertices, &faces) {
            let ray = Ray::new(DVec3::from_array(origin), DVec3::from_array(direction));
            if let Some(hit) = mesh.hit(&ray, FORWARD) {
                prop_assert!(hit.t.is_finite() && hit.point.is_finite());
                prop_assert!(hit.normal.is_finite() && hit.point_error.is_finite());
            }
            prop_assert!(mesh.pdf_value(ray.origin, ray.direction).is_finite());
        }
    }
}

/// The parallel build makes the same tree: the faces in the same order, the same bytes,
/// the same hits; and so does `Bvh::new_parallel`, on a scene large enough (80k faces) to
/// split in parallel.
#[cfg(feature = "rayon")]
#[test]
fn the_parallel_build_makes_the_same_tree() {
    let (unit, faces) = icosphere(6);
    let serial = TriangleMesh::new(&unit, &faces).unwrap();
    let parallel = TriangleMesh::new_parallel(&unit, &faces).unwrap();
    let order = |m: &TriangleMesh| m.faces().map(|f| f.index()).collect::<Vec<_>>();
    assert_eq!(order(&serial), order(&parallel));
    assert_eq!(serial.heap_bytes(), parallel.heap_bytes());
    let mut rng = SplitMix::new(37);
    for _ in 0..2000 {
        let ray = Ray::new(0.5 * rng.vec3(), rng.direction());
        assert_eq!(serial.hit(&ray, FORWARD), parallel.hit(&ray, FORWARD));
    }
    let triangles: Vec<_> = serial.faces().collect();
    let (a, b) = (Bvh::new(triangles.clone()), Bvh::new_parallel(triangles));
    assert!((0..a.len()).all(|i| a.original_index(i) == b.original_index(i)));
}

/// A mesh of unrelated triangles in the caller's own (random) order, with vertices shared
/// at random, some never used, and degenerate faces: the mesh keeps its vertices in the
/// order its tree meets them, and what the caller numbered must stay the caller's.
fn shuffled_mesh(seed: u64) -> (Vec<DVec3>, Vec<[u32; 3]>, TriangleMesh) {
    let mut rng = SplitMix::new(seed);
    let vertices: Vec<DVec3> = (0..300).map(|_| 10.0 * rng.vec3()).collect();
    let mut faces: Vec<[u32; 3]> = (0..400)
        .map(|_| [0; 3].map(|_| (rng.next_u64() % 280) as u32))
        .collect();
    faces.push([7, 7, 9]); // degenerate
    let mesh = TriangleMesh::new(&vertices, &faces).unwrap();
    (vertices, faces, mesh)
}

/// Each face's indices are the caller's, its corners the caller's vertices at them, and
/// normals and uvs given per caller vertex are interpolated from those same vertices.
#[test]
fn faces_keep_the_callers_numbering_in_the_meshs_order() {
    let (vertices, faces, mesh) = shuffled_mesh(71);
    let normals: Vec<DVec3> = (0..vertices.len())
        .map(|i| DVec3::new(1.0, i as f64, -0.5 * i as f64).normalize())
        .collect();
    let uvs: Vec<DVec2> = (0..vertices.len())
        .map(|i| DVec2::new(i as f64, (i * i) as f64))
        .collect();
    let mesh = mesh.with_normals(&normals).unwrap().with_uvs(&uvs).unwrap();
    assert!(mesh.vertices().len() <= 280);
    let mut hits = 0;
    for face in mesh.faces() {
        let indices = face.indices();
        assert_eq!(indices, faces[face.index() as usize]);
        assert_eq!(face.corners(), indices.map(|i| vertices[i as usize]));
        // Toward the centroid, from off the face's plane.
        let [a, b, c] = face.corners();
        let centroid = (a + b + c) / 3.0;
        let normal = (b - a).cross(c - a).normalize();
        let ray = Ray::new(centroid + normal, -normal);
        let Some((hit, w)) = face.hit_barycentric(&ray, FORWARD) else {
            continue; // a sliver whose centroid rounding puts beside it
        };
        hits += 1;
        let [i, j, k] = indices.map(|i| i as usize);
        assert_eq!(hit.uv, w.x * uvs[i] + w.y * uvs[j] + w.z * uvs[k]);
        let shading = (w.x * normals[i] + w.y * normals[j] + w.z * normals[k]).normalize();
        let expected = if shading.dot(hit.normal) < 0.0 {
            -shading
        } else {
            shading
        };
        // Normalizing rounds by a few ulps of each unit component.
        assert!((hit.shading_normal - expected).length() < 8.0 * f64::EPSILON);
    }
    assert!(hits > 350, "only {hits} centroids hit");
}

/// Sampling by area picks the face a running sum over every face picks (the mesh keeps a
/// sum for every few faces and adds the rest again): every direction drawn crosses the face
/// whose share of the total area holds `u.x`, at the ends of shares and between them.
#[test]
fn area_sampling_picks_the_face_a_full_running_sum_picks() {
    let (_, _, mesh) = shuffled_mesh(72);
    let faces: Vec<_> = mesh.faces().collect();
    let mut sums = Vec::new();
    let mut total = 0.0;
    for face in &faces {
        let [a, b, c] = face.corners();
        total += 0.5 * (b - a).cross(c - a).length();
        sums.push(total);
    }
    assert_eq!(mesh.area(), total);
    let origin = DVec3::new(31.0, -17.0, 23.0);
    let mut us: Vec<f64> = (0..2000).map(|i| i as f64 / 2000.0).collect();
    // Exactly at the ends of shares, where a block's sum and a face's meet.
    us.extend(sums.iter().map(|&s| s / total).filter(|&u| u < 1.0));
    us.push(1.0);
    for u in us {
        let target = u * total;
        let expected = sums.partition_point(|&c| c <= target).min(faces.len() - 1);
        let d = mesh.sample_direction(origin, DVec2::new(u, 0.5));
        let ray = Ray::new(origin, d);
        assert!(
            faces[expected].hit_barycentric(&ray, FORWARD).is_some(),
            "u.x = {u}: the sample misses face {expected}"
        );
    }
}
