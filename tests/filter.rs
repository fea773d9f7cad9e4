//! `Filtered`: a mesh's crossings asked of a filter inside the search. A filter that
//! rejects nothing answers as the mesh; a cut-out answers as the loop over the faces with
//! the same cut applied, on rays through the faces' corners, edges and insides; it is asked
//! at most once per face and query; `occluded` answers as `hit(..).is_some()`; a stochastic
//! cut-out lets through the fraction it says; spawned rays leave; and instances and trees of
//! filtered meshes answer as their loops.

mod support;

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::{
    Bvh, Candidate, Filtered, HitRecord, Hittable, Interval, Ray, Transformed, TriangleMesh,
};
use support::SplitMix;

const FORWARD: Interval = Interval::FORWARD;

/// A bumpy sphere with texture coordinates from its longitude and latitude, turned and
/// moved off the origin: faces of every slant, shared edges and vertices.
fn mesh() -> TriangleMesh {
    let (unit, faces) = support::icosphere(3);
    let turn = DQuat::from_axis_angle(DVec3::new(0.3, -1.0, 0.4).normalize(), 0.9);
    let vertices: Vec<DVec3> = unit
        .iter()
        .map(|&p| turn * (p * (1.0 + 0.1 * (7.0 * p.x).sin())) + DVec3::new(3.0, -1.0, 2.0))
        .collect();
    let uvs: Vec<DVec2> = unit
        .iter()
        .map(|p| DVec2::new(p.z.atan2(p.x), p.y.clamp(-1.0, 1.0).asin()))
        .collect();
    TriangleMesh::new(&vertices, &faces)
        .unwrap()
        .with_uvs(&uvs)
        .unwrap()
}

/// A cut-out on the texture: a checkerboard of holes, and every seventh face gone.
fn cut(primitive: u32, uv: DVec2) -> bool {
    let cell = (4.0 * uv).floor();
    primitive % 7 != 3 && (cell.x + cell.y).rem_euclid(2.0) == 0.0
}

/// The closest crossing the cut keeps, by the loop over the faces (ties to the lower
/// face number, as the mesh breaks them).
fn looped(mesh: &TriangleMesh, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
    let mut best: Option<HitRecord> = None;
    for face in mesh.faces() {
        let Some((hit, _)) = face.hit_barycentric(ray, ray_t) else {
            continue;
        };
        if !cut(face.index(), hit.uv) {
            continue;
        }
        if best.is_none_or(|b| hit.t < b.t || (hit.t == b.t && hit.primitive < b.primitive)) {
            best = Some(hit);
        }
    }
    best
}

/// Rays aimed at the faces' corners, edges and insides from all around.
fn rays(mesh: &TriangleMesh, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = SplitMix::new(seed);
    let faces: Vec<_> = mesh.faces().collect();
    (0..n)
        .map(|k| {
            let face = faces[(rng.next_u64() % faces.len() as u64) as usize];
            let target = support::face_point(&mut rng, face.corners(), k);
            let origin = target + 4.0 * rng.direction();
            Ray::new(origin, target - origin)
        })
        .collect()
}

#[test]
fn a_filter_that_rejects_nothing_answers_as_the_mesh() {
    let mesh = Arc::new(mesh());
    let all = Filtered::new(mesh.clone(), |_: &Candidate| true);
    for ray in rays(&mesh, 3000, 11) {
        let (a, b) = (all.hit(&ray, FORWARD), mesh.hit(&ray, FORWARD));
        assert_eq!(a, b, "{ray:?}");
        assert_eq!(all.occluded(&ray, FORWARD), mesh.occluded(&ray, FORWARD));
    }
}

#[test]
fn a_cut_out_answers_as_the_loop_over_the_faces_with_the_same_cut() {
    let mesh = mesh();
    let leaf = Filtered::new(&mesh, |c: &Candidate| cut(c.primitive(), c.uv()));
    let mut through = 0;
    for ray in rays(&mesh, 4000, 12) {
        let expected = looped(&mesh, &ray, FORWARD);
        let hit = leaf.hit(&ray, FORWARD);
        assert_eq!(hit, expected, "{ray:?}");
        assert_eq!(leaf.occluded(&ray, FORWARD), hit.is_some(), "{ray:?}");
        // What the mesh alone finds first, the cut-out passed over on this ray.
        if mesh.hit(&ray, FORWARD).map(|h| h.t) != hit.map(|h| h.t) {
            through += 1;
        }
        // A shadow ray up to just short of the hit finds nothing the cut keeps.
        if let Some(h) = hit {
            let short = Interval::new(0.0, h.t * (1.0 - 1e-9));
            assert_eq!(
                leaf.occluded(&ray, short),
                looped(&mesh, &ray, short).is_some()
            );
        }
    }
    // The test means something: most rays meet a hole somewhere.
    assert!(through > 1000, "{through}");
}

#[test]
fn the_filter_is_asked_at_most_once_per_face_and_query() {
    let mesh = mesh();
    let asked: Mutex<HashMap<u32, u32>> = Mutex::new(HashMap::new());
    let counting = Filtered::new(&mesh, |c: &Candidate| {
        *asked.lock().unwrap().entry(c.primitive()).or_default() += 1;
        cut(c.primitive(), c.uv())
    });
    let mut most = 0;
    for ray in rays(&mesh, 2000, 13) {
        for occluded in [false, true] {
            asked.lock().unwrap().clear();
            if occluded {
                counting.occluded(&ray, FORWARD);
            } else {
                counting.hit(&ray, FORWARD);
            }
            let asked = asked.lock().unwrap();
            assert!(asked.values().all(|&n| n == 1), "{ray:?}: {asked:?}");
            most = most.max(asked.len());
        }
    }
    // And more than one face is asked on some rays (the search goes on past a rejection).
    assert!(most >= 2, "{most}");
}

/// A hash of the ray and the face, as a number in [0, 1): the same for the same question.
fn coin(ray: &Ray, primitive: u32) -> f64 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64 ^ u64::from(primitive);
    for x in [ray.origin, ray.direction]
        .iter()
        .flat_map(|v| v.to_array())
    {
        h = (h ^ x.to_bits()).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h ^= h >> 31;
    }
    (h >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn a_stochastic_cut_out_lets_through_what_it_says() {
    // One square of two faces, a quarter opaque: of many rays through it, a quarter hit,
    // within four standard deviations of the binomial count.
    let square = TriangleMesh::new(
        &[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        &[[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let veil = Filtered::new(&square, |c: &Candidate| coin(c.ray, c.primitive()) < 0.25);
    let mut rng = SplitMix::new(14);
    let n = 40_000;
    let mut hits = 0;
    for _ in 0..n {
        let target = DVec3::new(rng.next_f64(), rng.next_f64(), 0.0);
        let origin = target + DVec3::new(0.0, 0.0, 1.0) + 0.5 * rng.direction();
        let ray = Ray::new(origin, target - origin);
        let hit = veil.hit(&ray, FORWARD);
        assert_eq!(veil.occluded(&ray, FORWARD), hit.is_some());
        hits += usize::from(hit.is_some());
    }
    let (mean, sd) = (0.25 * n as f64, (n as f64 * 0.25 * 0.75).sqrt());
    assert!((hits as f64 - mean).abs() < 4.0 * sd, "{hits} of {n}");
}

#[test]
fn spawned_rays_leave_a_filtered_face() {
    let mesh = mesh();
    let leaf = Filtered::new(&mesh, |c: &Candidate| cut(c.primitive(), c.uv()));
    let mut rng = SplitMix::new(15);
    for ray in rays(&mesh, 2000, 16) {
        let Some(hit) = leaf.hit(&ray, FORWARD) else {
            continue;
        };
        for direction in [rng.direction(), hit.normal, -hit.normal] {
            let spawned = hit.spawn_ray(direction);
            if let Some(again) = leaf.hit(&spawned, FORWARD) {
                assert_ne!(again.primitive, hit.primitive, "{hit:?} by {spawned:?}");
            }
        }
    }
}

#[test]
fn turned_instances_of_a_filtered_mesh_in_a_tree_answer_as_their_loop() {
    let mesh = Arc::new(mesh());
    let leaf = Arc::new(Filtered::new(mesh.clone(), |c: &Candidate| {
        cut(c.primitive(), c.uv())
    }));
    let mut rng = SplitMix::new(17);
    let instances: Vec<_> = (0..30)
        .map(|i| {
            let turn = DQuat::from_axis_angle(rng.direction(), rng.next_f64() * 6.0);
            let at = 12.0 * (rng.vec3() - 0.5);
            Transformed::new(leaf.clone(), turn, at)
                .unwrap()
                .with_instance_id(i)
        })
        .collect();
    let tree = Bvh::new(instances.clone());
    for _ in 0..3000 {
        let origin = 20.0 * (rng.vec3() - 0.5);
        let ray = Ray::new(origin, rng.direction());
        let hit = tree.hit(&ray, FORWARD);
        let expected = support::brute_force(&instances, &ray, FORWARD).map(|(_, h)| h);
        assert_eq!(hit, expected, "{ray:?}");
        assert_eq!(tree.occluded(&ray, FORWARD), hit.is_some(), "{ray:?}");
    }
}

/// The quads and disks of a tree, cut out by a checkerboard of their `(alpha, beta)`, and
/// spheres whose nearer crossings are cut away: `Bvh::hit_filtered` answers as the loop
/// over the objects with the same cut, `occluded_filtered` as `hit_filtered(..).is_some()`,
/// and the filter is asked once per crossing.
#[test]
fn a_tree_filtered_object_by_object_answers_as_the_loop() {
    use hitkit::custom::Made;
    use hitkit::{Disk, ObjectCandidate, Quad, Sphere};
    let mut rng = SplitMix::new(18);
    let mut objects: Vec<Box<dyn Hittable>> = Vec::new();
    for k in 0..120 {
        let q = 20.0 * (rng.vec3() - 0.5);
        let (u, v) = (2.0 * rng.direction(), 2.0 * rng.direction());
        if k % 2 == 0 {
            objects.push(Box::new(Quad::new(q, u, v).unwrap()));
        } else {
            objects.push(Box::new(Quad::with_interior(q, u, v, Disk).unwrap()));
        }
    }
    let spheres = 120..140;
    for _ in spheres.clone() {
        objects.push(Box::new(
            Sphere::new(20.0 * (rng.vec3() - 0.5), 1.5).unwrap(),
        ));
    }
    // Quads and disks: a checkerboard of their coordinates.
    let keeps = |object: usize, coords: DVec2| {
        let cell = (3.0 * coords).floor();
        object >= 120 || (cell.x + cell.y).rem_euclid(2.0) == 0.0
    };
    let tree = hitkit::Bvh::new(objects);
    let asked: Mutex<HashMap<(usize, u64), u32>> = Mutex::new(HashMap::new());
    let filter = |c: &ObjectCandidate| {
        *asked
            .lock()
            .unwrap()
            .entry((c.object, c.t.to_bits()))
            .or_default() += 1;
        // A sphere's crossing counts only from the far side of its centre on.
        let centre_t = if spheres.contains(&c.object) {
            let o = &tree.objects()[(0..tree.len())
                .find(|&i| tree.original_index(i) == c.object)
                .unwrap()];
            let middle = o.bounding_box().min().midpoint(o.bounding_box().max());
            (middle - c.ray.origin).dot(c.ray.direction) / c.ray.direction.length_squared()
        } else {
            f64::NEG_INFINITY
        };
        c.t >= centre_t && keeps(c.object, c.coords.truncate())
    };
    let mut cut = 0;
    for _ in 0..2000 {
        let ray = Ray::new(30.0 * (rng.vec3() - 0.5), rng.direction());
        asked.lock().unwrap().clear();
        let hit = tree.hit_filtered(&ray, FORWARD, filter);
        assert!(asked.lock().unwrap().values().all(|&n| n == 1));
        // The loop: each quad's one crossing, each sphere's far one.
        let mut best: Option<(usize, HitRecord)> = None;
        for i in 0..tree.len() {
            let (object, shape) = (tree.original_index(i), &tree.objects()[i]);
            let found = if spheres.contains(&object) {
                let middle = shape
                    .bounding_box()
                    .min()
                    .midpoint(shape.bounding_box().max());
                let centre_t =
                    (middle - ray.origin).dot(ray.direction) / ray.direction.length_squared();
                shape.hit(&ray, Interval::new(centre_t.max(0.0), f64::INFINITY))
            } else {
                // The shape's own coordinates of its one crossing, as the filter sees them.
                let found = shape.find(&ray, FORWARD, &mut Made::new());
                found
                    .filter(|f| keeps(object, f.coords.truncate()))
                    .and_then(|_| shape.hit(&ray, FORWARD))
            };
            if let Some(h) = found
                && best.is_none_or(|(b, bh)| h.t < bh.t || (h.t == bh.t && object < b))
            {
                best = Some((object, h));
            }
        }
        assert_eq!(
            hit.map(|(i, h)| (i, h.t)),
            best.map(|(i, h)| (i, h.t)),
            "{ray:?}"
        );
        assert_eq!(tree.occluded_filtered(&ray, FORWARD, filter), hit.is_some());
        cut +=
            usize::from(tree.hit_with_index(&ray, FORWARD).map(|(i, _)| i) != hit.map(|(i, _)| i));
    }
    assert!(cut > 100, "{cut}");
}

/// `Candidate::front_face` says what the hit reports in `front_face`, so a single-sided
/// surface culls by it: a closed mesh culled to its fronts is hit from outside as before,
/// and from inside (every crossing a back face) not at all; through a mirroring instance
/// too.
#[test]
fn a_candidate_knows_the_side_it_crosses() {
    use hitkit::glam::DAffine3;
    let mut rng = SplitMix::new(4907);
    let (vertices, faces) = support::icosphere(2);
    let mesh = TriangleMesh::new(&vertices, &faces).unwrap();
    let seen = Mutex::new(Vec::new());
    let sides = Filtered::new(&mesh, |c: &Candidate| {
        seen.lock().unwrap().push((c.t, c.front_face()));
        true
    });
    let culled = Filtered::new(&mesh, |c: &Candidate| c.front_face());
    let mirror = DAffine3::from_scale(DVec3::new(-1.0, 2.0, 1.0));
    let mirrored_sides = Transformed::affine(&sides, mirror).unwrap();
    let (mut outside, mut inside) = (0, 0);
    for _ in 0..2000 {
        let from_inside = rng.next_f64() < 0.5;
        let origin = if from_inside {
            0.5 * rng.direction()
        } else {
            3.0 * rng.direction()
        };
        let toward = if from_inside {
            rng.direction()
        } else {
            0.8 * rng.direction() - origin
        };
        let ray = Ray::new(origin, toward);
        for (object, ray) in [
            (&sides as &dyn Hittable, ray),
            (
                &mirrored_sides,
                Ray::new(
                    mirror.transform_point3(ray.origin),
                    mirror.transform_vector3(ray.direction),
                ),
            ),
        ] {
            seen.lock().unwrap().clear();
            let Some(hit) = object.hit(&ray, Interval::FORWARD) else {
                continue;
            };
            let asked = seen.lock().unwrap().clone();
            let side = asked
                .iter()
                .filter(|(t, _)| *t == hit.t)
                .map(|&(_, f)| f)
                .next_back();
            assert_eq!(side, Some(hit.front_face), "{ray:?}");
        }
        let culled_hit = culled.hit(&ray, Interval::FORWARD);
        if from_inside {
            assert!(culled_hit.is_none(), "a back face from inside: {ray:?}");
            inside += 1;
        } else if let Some(plain) = mesh.hit(&ray, Interval::FORWARD) {
            assert_eq!(culled_hit.map(|h| h.t), Some(plain.t), "{ray:?}");
            outside += 1;
        }
    }
    assert!(inside > 500 && outside > 500, "{inside} {outside}");
}
