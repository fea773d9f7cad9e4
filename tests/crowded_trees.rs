//! Trees whose nodes have every child entered, level after level: coincident copies, nested
//! shells, slivers meeting at a point, long overlapping strands. Such trees crashed the walk
//! (a stack indexed one past its end: the Khronos ToyCar's panic) while every other test
//! passed; here every query of `Bvh` and `TriangleMesh`, built, after inserts, removals,
//! `optimize` and refits, answers as the loop over its objects or faces, and none panics.

mod support;

use hitkit::custom::Made;
use hitkit::glam::{DMat3, DVec3};
use hitkit::{
    Bvh, Filtered, HitRecord, Hittable, Interval, Quad, Ray, Sphere, Triangle, TriangleMesh, Visits,
};
use std::sync::Arc;
use support::{SplitMix, brute_force, loop_over_faces};

/// Rays, each with the interval it is asked within.
type Rays = Vec<(Ray, Interval)>;

// Sizes and seeds at which the walk, as it was before the ToyCar's crash was fixed, wrote
// past its small stack (found by a sweep of sizes and seeds; it failed on each).
const COPIES: usize = 400;
const BLADES: (usize, u64) = (600, 3);
const CROWD: (usize, u64) = (200, 0);

/// What a filter by number turns away: every third object (or face).
fn turned_away(number: usize) -> bool {
    number % 3 == 1
}

/// The loop's answer over the live objects of `model` (by number), ties to the smaller
/// number, counting only those `keep` takes.
fn loop_hit<T: Hittable>(
    model: &[Option<T>],
    ray: &Ray,
    ray_t: Interval,
    keep: impl Fn(usize) -> bool,
) -> Option<(usize, HitRecord)> {
    let live: Vec<(usize, &T)> = model
        .iter()
        .enumerate()
        .filter_map(|(i, o)| o.as_ref().filter(|_| keep(i)).map(|o| (i, o)))
        .collect();
    let objects: Vec<&T> = live.iter().map(|(_, o)| *o).collect();
    brute_force(&objects, ray, ray_t).map(|(k, hit)| (live[k].0, hit))
}

/// The same answer: the same object and, bit for bit, the same `t` and point.
fn same(got: Option<(usize, HitRecord)>, want: Option<(usize, HitRecord)>) -> bool {
    match (got, want) {
        (None, None) => true,
        (Some((i, a)), Some((j, b))) => {
            i == j && a.t.to_bits() == b.t.to_bits() && a.point == b.point
        }
        _ => false,
    }
}

/// Every query of `bvh` against the loop over `model` on `rays`.
fn check_bvh<T: Hittable>(what: &str, bvh: &Bvh<T>, model: &[Option<T>], rays: &[(Ray, Interval)]) {
    let mut hits = 0;
    for (r, &(ray, ray_t)) in rays.iter().enumerate() {
        let want = loop_hit(model, &ray, ray_t, |_| true);
        hits += usize::from(want.is_some());
        let got = bvh.hit_with_index(&ray, ray_t);
        assert!(
            same(got, want),
            "{what}, ray {r}: hit_with_index {got:?}, the loop {want:?}"
        );
        let hit = bvh.hit(&ray, ray_t);
        assert_eq!(
            hit.map(|h| h.t.to_bits()),
            want.map(|w| w.1.t.to_bits()),
            "{what}, ray {r}: hit"
        );
        let mut made = Made::new();
        let found = bvh.find(&ray, ray_t, &mut made);
        let record = found.and_then(|f| made.record(bvh, &ray, ray_t, &f));
        assert_eq!(
            record.map(|h| h.t.to_bits()),
            want.map(|w| w.1.t.to_bits()),
            "{what}, ray {r}: find"
        );
        assert_eq!(
            bvh.occluded(&ray, ray_t),
            want.is_some(),
            "{what}, ray {r}: occluded"
        );

        let want = loop_hit(model, &ray, ray_t, |i| !turned_away(i));
        let got = bvh.hit_filtered(&ray, ray_t, |c| !turned_away(c.object));
        assert!(
            same(got, want),
            "{what}, ray {r}: hit_filtered {got:?}, the loop {want:?}"
        );
        let occluded = bvh.occluded_filtered(&ray, ray_t, |c| !turned_away(c.object));
        assert_eq!(
            occluded,
            want.is_some(),
            "{what}, ray {r}: occluded_filtered"
        );

        let visits = [
            bvh.hit_visits(&ray, ray_t),
            bvh.occluded_visits(&ray, ray_t),
        ];
        counted(&format!("{what}, ray {r}"), hit.is_some(), visits);
    }
    crowded(what, hits, rays.len());
}

/// Where a ray hits, both counters count a test.
fn counted(what: &str, hit: bool, visits: [Visits; 2]) {
    assert!(
        !hit || visits.iter().all(|v| v.tests >= 1),
        "{what}: visits {visits:?}"
    );
}

/// A quarter of the rays at least hit: the crowd is in their way.
fn crowded(what: &str, hits: usize, rays: usize) {
    assert!(
        hits * 4 >= rays,
        "{what}: {hits} of {rays} rays hit: not crowded"
    );
}

/// Every query of `mesh` (and of it filtered) against the loop over its faces on `rays`.
fn check_mesh(what: &str, mesh: &TriangleMesh, rays: &[(Ray, Interval)]) {
    let key = |h: Option<HitRecord>| h.map(|h| (h.t.to_bits(), h.primitive));
    let filtered = Filtered::new(mesh, |c: &hitkit::Candidate| {
        !turned_away(c.primitive() as usize)
    });
    let mut hits = 0;
    for (r, &(ray, ray_t)) in rays.iter().enumerate() {
        let want = loop_over_faces(mesh, &ray, ray_t, |_| true);
        hits += usize::from(want.is_some());
        let hit = mesh.hit(&ray, ray_t);
        assert_eq!(key(hit), key(want), "{what}, ray {r}: hit");
        let mut made = Made::new();
        let found = mesh.find(&ray, ray_t, &mut made);
        let record = found.and_then(|f| made.record(mesh, &ray, ray_t, &f));
        assert_eq!(key(record), key(want), "{what}, ray {r}: find");
        assert_eq!(
            mesh.occluded(&ray, ray_t),
            want.is_some(),
            "{what}, ray {r}: occluded"
        );

        let want = loop_over_faces(mesh, &ray, ray_t, |f| !turned_away(f as usize));
        assert_eq!(
            key(filtered.hit(&ray, ray_t)),
            key(want),
            "{what}, ray {r}: filtered"
        );
        assert_eq!(
            filtered.occluded(&ray, ray_t),
            want.is_some(),
            "{what}, ray {r}: filtered any"
        );

        let visits = [
            mesh.hit_visits(&ray, ray_t),
            mesh.occluded_visits(&ray, ray_t),
        ];
        counted(&format!("{what}, ray {r}"), hit.is_some(), visits);
    }
    crowded(what, hits, rays.len());
}

/// Rays at `focus` (where the crowd meets) from every side and from `scale` away, from
/// inside it, and along `axis` both ways; some stop short of it.
fn rays_at(rng: &mut SplitMix, focus: DVec3, axis: DVec3, scale: f64, n: usize) -> Rays {
    (0..n)
        .map(|i| {
            let aim = focus + 1e-3 * scale * (rng.vec3() - 0.5);
            let (origin, direction) = match i % 4 {
                0 => (aim + 3.0 * scale * rng.direction(), DVec3::ZERO),
                1 => (aim, rng.direction()),
                2 => (aim - 3.0 * scale * axis, axis + 1e-3 * rng.direction()),
                _ => (aim + 3.0 * scale * axis, -axis + 1e-3 * rng.direction()),
            };
            let direction = if direction == DVec3::ZERO {
                aim - origin
            } else {
                direction
            };
            let ray_t = if i % 7 == 6 {
                Interval::new(0.0, 0.5 * (aim - origin).length() / direction.length())
            } else {
                Interval::FORWARD
            };
            (Ray::new(origin, direction), ray_t)
        })
        .collect()
}

/// `objects` in a `Bvh` built at once, inserted one by one, and then with every fifth
/// removed, `optimize`d and a dozen copies of the last inserted: each checked on `rays`.
fn check_every_way<T: Hittable + Clone>(what: &str, objects: Vec<T>, rays: &[(Ray, Interval)]) {
    let more = objects.last().expect("a crowd").clone();
    let mut model: Vec<Option<T>> = objects.iter().cloned().map(Some).collect();
    check_bvh(
        &format!("{what}, built"),
        &Bvh::new(objects.clone()),
        &model,
        rays,
    );
    let mut bvh = Bvh::new(Vec::new());
    for o in objects {
        bvh.insert(o);
    }
    check_bvh(&format!("{what}, inserted"), &bvh, &model, rays);
    for number in (0..model.len()).step_by(5) {
        assert!(bvh.remove(number).is_some());
        model[number] = None;
    }
    bvh.optimize(0.3);
    for _ in 0..12 {
        assert_eq!(bvh.insert(more.clone()), model.len());
        model.push(Some(more.clone()));
    }
    check_bvh(
        &format!("{what}, removed, optimized, inserted"),
        &bvh,
        &model,
        rays,
    );
}

/// `n` copies of one quad, and as many of a second quad that crosses it, in turn, and rays
/// at where they cross.
fn copies(n: usize, seed: u64) -> (Vec<Quad>, Rays) {
    let mut rng = SplitMix::new(seed);
    let a = Quad::new(
        DVec3::new(-0.5, -0.5, 0.3),
        DVec3::new(1.0, 0.2, 0.0),
        DVec3::new(0.0, 1.0, 0.4),
    )
    .unwrap();
    let b = Quad::new(
        DVec3::new(-0.5, 0.0, -0.2),
        DVec3::X,
        DVec3::new(0.0, 0.1, 1.0),
    )
    .unwrap();
    let quads = (0..2 * n).map(|i| if i % 2 == 0 { a } else { b }).collect();
    (
        quads,
        rays_at(&mut rng, DVec3::new(0.0, 0.1, 0.5), DVec3::Z, 1.0, 48),
    )
}

#[test]
fn coincident_copies_answer_as_the_loop() {
    let (quads, rays) = copies(COPIES, 57);
    check_every_way("copies of two crossing quads", quads, &rays);
    let mut rng = SplitMix::new(57);
    let ball = Sphere::new(DVec3::new(0.1, -0.2, 0.3), 0.7).unwrap();
    let rays = rays_at(&mut rng, DVec3::new(0.1, -0.2, 0.3), DVec3::Y, 1.0, 48);
    check_every_way("400 copies of a ball", vec![ball; 400], &rays);
}

#[test]
fn nested_shells_answer_as_the_loop() {
    let mut rng = SplitMix::new(58);
    let centre = DVec3::new(3.0, -1.0, 2.0);
    // Each ball inside the last, about one centre and about centres a little apart.
    for jitter in [0.0, 1e-3] {
        let balls: Vec<Sphere> = (0..400)
            .map(|i| {
                let c = centre + jitter * (rng.vec3() - 0.5);
                Sphere::new(c, 2.0 / (1.0 + 0.01 * f64::from(i))).unwrap()
            })
            .collect();
        let rays = rays_at(&mut rng, centre, DVec3::X, 2.0, 48);
        check_every_way(&format!("400 nested balls, jitter {jitter}"), balls, &rays);
    }
    // Squares in one plane, each inside the last: every hit a tie the smaller number wins.
    let squares: Vec<Quad> = (0..300)
        .map(|i| {
            let half = 1.0 / (1.0 + 0.01 * f64::from(i));
            Quad::new(
                centre - DVec3::new(half, half, 0.0),
                2.0 * half * DVec3::X,
                2.0 * half * DVec3::Y,
            )
            .unwrap()
        })
        .collect();
    let rays = rays_at(&mut rng, centre, DVec3::Z, 1.0, 48);
    check_every_way("300 nested squares in a plane", squares, &rays);
}

/// A bicone: `n` slivers from a ring of `radius` to each of two apexes, `height` from it,
/// turned by `turn` and moved to `at`: its vertices (the apexes first) and faces.
fn bicone(n: u32, radius: f64, height: f64, turn: DMat3, at: DVec3) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut vertices = vec![
        at + turn * (height * DVec3::Z),
        at - turn * (height * DVec3::Z),
    ];
    vertices.extend((0..n).map(|i| {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        at + turn * (radius * DVec3::new(a.cos(), a.sin(), 0.0))
    }));
    let ring = |i: u32| 2 + i % n;
    let faces = (0..n)
        .flat_map(|i| [[0, ring(i), ring(i + 1)], [1, ring(i + 1), ring(i)]])
        .collect();
    (vertices, faces)
}

#[test]
fn slivers_meeting_at_a_point_answer_as_the_loop() {
    let mut rng = SplitMix::new(59);
    for (scale, offset) in [(1.0, 0.0), (1.3e-3, 1234.567), (1.9e3, 1.1e6 + 0.3)] {
        let turn = support::rotation(&mut rng);
        let at = DVec3::splat(offset);
        let (vertices, faces) = bicone(1024, scale, 3.0 * scale, turn, at);
        let axis = turn * DVec3::Z;
        let mut rays = Vec::new();
        for apex in [vertices[0], vertices[1], at] {
            rays.extend(rays_at(&mut rng, apex, axis, scale, 24));
        }
        let what = format!("bicone of 2048 slivers, scale {scale}, offset {offset}");
        let mut mesh = TriangleMesh::new(&vertices, &faces).unwrap();
        check_mesh(&what, &mesh, &rays);
        // Refitted to the same bicone stretched along its axis, then rebuilt there.
        let stretched: Vec<DVec3> = vertices
            .iter()
            .map(|&p| p + 0.5 * (p - at).dot(axis) * axis)
            .collect();
        mesh.set_vertices(&stretched).unwrap();
        check_mesh(&format!("{what}, refitted"), &mesh, &rays);
        mesh.rebuild();
        check_mesh(&format!("{what}, rebuilt"), &mesh, &rays);

        let quads: Vec<Quad<Triangle>> = faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| vertices[i as usize]);
                Quad::with_interior(a, b - a, c - a, Triangle).unwrap()
            })
            .collect();
        check_every_way(&format!("{what}, as Quad<Triangle>"), quads, &rays[..36]);
    }
}

/// Blades of grass (or hairs): `n` long thin quads along one line, each turned about it;
/// rays at their middle and along them.
fn blades(n: usize, seed: u64) -> (Vec<Quad>, Rays) {
    let mut rng = SplitMix::new(seed);
    let blades = (0..n)
        .map(|_| {
            let foot = 0.02 * (rng.vec3() - 0.5) * DVec3::new(1.0, 1.0, 0.0);
            let a = std::f64::consts::TAU * rng.next_f64();
            let across = 0.01 * DVec3::new(a.cos(), a.sin(), 0.0);
            let along = DVec3::new(0.01 * (rng.next_f64() - 0.5), 0.0, 10.0);
            Quad::new(foot - 0.5 * across, across, along).unwrap()
        })
        .collect();
    let mut rays = rays_at(&mut rng, DVec3::new(0.0, 0.0, 5.0), DVec3::Z, 5.0, 36);
    rays.extend(rays_at(
        &mut rng,
        DVec3::new(0.0, 0.0, 0.1),
        DVec3::Z,
        0.05,
        24,
    ));
    (blades, rays)
}

#[test]
fn long_overlapping_strands_answer_as_the_loop() {
    let (blades, rays) = blades(BLADES.0, BLADES.1);
    check_every_way("blades along a line", blades, &rays);
}

/// `n` balls and quads of random sizes and turns about one point, and rays at it.
fn crowd(n: usize, seed: u64) -> (Vec<Arc<dyn Hittable>>, Rays) {
    let mut rng = SplitMix::new(seed);
    let objects = (0..n)
        .map(|i| -> Arc<dyn Hittable> {
            let c = 0.05 * (rng.vec3() - 0.5);
            if i % 2 == 0 {
                Arc::new(Sphere::new(c, 0.2 + 0.5 * rng.next_f64()).unwrap())
            } else {
                let (u, v) = (rng.direction(), rng.direction());
                Arc::new(Quad::new(c - 0.5 * (u + v), u, v).unwrap())
            }
        })
        .collect();
    (objects, rays_at(&mut rng, DVec3::ZERO, DVec3::X, 1.0, 48))
}

#[test]
fn random_crowds_of_balls_and_quads_answer_as_the_loop() {
    let (objects, rays) = crowd(CROWD.0, CROWD.1);
    check_every_way("balls and quads about a point", objects, &rays);
}
