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
