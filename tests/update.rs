//! Scenes that change: a `TriangleMesh` whose vertices move and a `Bvh` whose objects move,
//! refitted in place (or rebuilt where a refit cannot hold them), still answer exactly as
//! the loop over their faces or objects after every update of a random sequence: moves from
//! an ulp to the scene's size, jumps to offsets of 1e12, faces collapsing to degenerate
//! and opening again, objects turning unbounded and back (the contract's clause 3).

mod support;

use hitkit::glam::DVec3;
use hitkit::{
    Bvh, GeometryError, Hittable, Interval, Plane, Quad, Ray, Sphere, Triangle, TriangleMesh,
};
use proptest::prelude::*;
use support::{
    OFFSETS, SplitMix, brute_force, face_point, icosphere, loop_over_faces, meaningful, rotation,
};

const FORWARD: Interval = Interval::FORWARD;

/// One update of a sequence: how far things move (relative to the scene's size), whether
/// the whole scene jumps to another offset, and how many faces or objects collapse or
/// change kind.
#[derive(Clone, Copy, Debug)]
struct Step {
    /// Each vertex (or object) moves by up to `10^scale` times the scene's size; `scale` of
    /// -16 is an ulp or so, 0 the scene's own size.
    scale: i32,
    /// A jump of the whole scene to `OFFSETS[jump]`, or none.
    jump: Option<usize>,
    /// How many faces get two corners at one point (degenerate), or objects that turn
    /// into an unbounded plane.
    collapse: usize,
}

fn step() -> impl Strategy<Value = Step> {
    (
        prop_oneof![Just(-16), Just(-9), -4i32..=0],
        prop::option::weighted(0.3, 0..OFFSETS.len()),
        prop_oneof![3 => Just(0usize), 1 => 1usize..4],
    )
        .prop_map(|(scale, jump, collapse)| Step {
            scale,
            jump,
            collapse,
        })
}

/// The objects of the trees' tests: about this size, within 10 of it of where they sit.
const SIZE: f64 = 1.1;

/// The object `seed` makes near `at`: a sphere, a triangle or a parallelogram, or (where
/// `plane`) an unbounded plane through the same point.
fn object(seed: u64, at: DVec3, plane: bool) -> Box<dyn Hittable> {
    let mut rng = SplitMix::new(seed);
    let q = at + 10.0 * SIZE * rng.vec3();
    let (u, v) = (SIZE * rng.direction(), SIZE * rng.direction());
    // Two random directions may be parallel: then the axes.
    match (plane, rng.next_u64() % 3) {
        (true, _) => Box::new(
            Plane::new(q, u, v).unwrap_or_else(|_| Plane::new(q, DVec3::X, DVec3::Y).unwrap()),
        ),
        (_, 0) => Box::new(Sphere::new(q, SIZE * rng.next_f64() + 1e-3).unwrap()),
        (_, 1) => Box::new(
            Quad::with_interior(q, u, v, Triangle)
                .unwrap_or_else(|_| Quad::with_interior(q, DVec3::X, DVec3::Y, Triangle).unwrap()),
        ),
        _ => Box::new(
            Quad::new(q, u, v).unwrap_or_else(|_| Quad::new(q, DVec3::X, DVec3::Y).unwrap()),
        ),
    }
}

/// Whether `tree` answers as the loop over `objects` (numbered `numbers` in the tree) on
/// `rays` rays: at points of the objects' boxes and around `offset`, from 2 to 1e6 times
/// the objects' size away; the same object by number at the same `t`, ties to the smaller
/// number, and `occluded` agreeing with `hit`.
fn agrees_with_the_loop(
    tree: &Bvh<Box<dyn Hittable>>,
    objects: &[Box<dyn Hittable>],
    numbers: &[usize],
    offset: DVec3,
    rng: &mut SplitMix,
    rays: usize,
) -> Result<(), TestCaseError> {
    for r in 0..rays {
        let target = if objects.is_empty() || r % 4 == 3 {
            offset + 10.0 * SIZE * rng.vec3()
        } else {
            let aim = objects[r % objects.len()].bounding_box();
            if aim.is_bounded() {
                aim.min() + (aim.max() - aim.min()) * rng.vec3()
            } else {
                offset
            }
        };
        let origin = target - SIZE * [2.0, 50.0, 1e6][r % 3] * rng.direction();
        let ray = Ray::new(origin, target - origin);
        let expected = brute_force(objects, &ray, FORWARD).map(|(i, h)| (numbers[i], h.t));
        let found = tree.hit_with_index(&ray, FORWARD).map(|(k, h)| (k, h.t));
        prop_assert_eq!(found, expected, "tree and loop differ");
        prop_assert_eq!(tree.occluded(&ray, FORWARD), found.is_some());
    }
    Ok(())
}

/// Rays at the mesh's corners, edges and faces (where watertightness is decided) from
/// every side and from far away, and rays through its box at random.
fn rays_at(vertices: &[DVec3], faces: &[[u32; 3]], rng: &mut SplitMix, size: f64) -> Vec<Ray> {
    let centre = vertices.iter().sum::<DVec3>() / vertices.len() as f64;
    (0..48)
        .map(|k| {
            let face = faces[rng.next_u64() as usize % faces.len()].map(|i| vertices[i as usize]);
            let target = if k % 4 == 3 {
                centre + size * (rng.vec3() - 0.5)
            } else {
                face_point(rng, face, k)
            };
            let distance = size * [2.0, 50.0, 1e6][k % 3];
            let origin = target - distance * rng.direction();
            Ray::new(origin, target - origin)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// After every update of a random sequence, the mesh's tree finds what the loop over
    /// its faces finds (same face, same `t`) and what a mesh built afresh on the same
    /// vertices finds; `occluded` agrees with `hit`; faces keep their numbers; and the
    /// cost it reports is finite and positive.
    #[test]
    fn a_moving_mesh_answers_as_its_faces_after_every_update(
        seed in any::<u64>(),
        start in 0..OFFSETS.len(),
        size in prop_oneof![Just(1.7e-3), Just(1.1), Just(1.9e3)],
        steps in prop::collection::vec(step(), 1..6),
        stray in any::<bool>(),
    ) {
        let mut rng = SplitMix::new(seed);
        let (unit, mut faces) = icosphere(1);
        let rot = rotation(&mut rng);
        let place = |offset: f64| DVec3::new(offset, -0.5 * offset, 0.25 * offset);
        prop_assume!(meaningful(OFFSETS[start], size));
        let mut vertices: Vec<DVec3> =
            unit.iter().map(|&p| place(OFFSETS[start]) + rot * (size * p)).collect();
        if stray {
            // A vertex far off that only a face degenerate for good (two corners named
            // alike) names: kept, moved, never hit.
            vertices.push(place(OFFSETS[start]) + 1e3 * size * DVec3::ONE);
            let n = vertices.len() as u32 - 1;
            faces.push([n, n, 0]);
        }
        let mut mesh = TriangleMesh::new(&vertices, &faces).unwrap();
        for step in steps {
            let offset = step.jump.map_or(OFFSETS[start], |j| OFFSETS[j]);
            if !meaningful(offset, size) {
                continue;
            }
            let shift = step.jump.map_or(DVec3::ZERO, |j| place(OFFSETS[j]) - place(OFFSETS[start]));
            let reach = size * 10f64.powi(step.scale);
            // Each vertex moves on its own (faces stretch, turn and cross each other).
            for v in &mut vertices {
                *v += shift + reach * (rng.vec3() - 0.5);
            }
            for _ in 0..step.collapse {
                let [a, b, _] = faces[rng.next_u64() as usize % faces.len()];
                vertices[b as usize] = vertices[a as usize];
            }
            mesh.set_vertices(&vertices).unwrap();
            let fresh = TriangleMesh::new(&vertices, &faces).unwrap();
            prop_assert_eq!(mesh.hittable_face_count(), fresh.hittable_face_count());
            prop_assert_eq!(mesh.bounding_box(), fresh.bounding_box());
            prop_assert!(mesh.cost().now.is_finite() && mesh.cost().now > 0.0);
            for ray in rays_at(&vertices, &faces, &mut rng, size) {
                let hit = mesh.hit(&ray, FORWARD).map(|h| (h.primitive, h.t));
                prop_assert_eq!(hit, loop_over_faces(&mesh, &ray, FORWARD, |_| true).map(|h| (h.primitive, h.t)), "tree and loop differ");
                prop_assert_eq!(
                    hit,
                    fresh.hit(&ray, FORWARD).map(|h| (h.primitive, h.t)),
                    "refitted and fresh meshes differ"
                );
                prop_assert_eq!(mesh.occluded(&ray, FORWARD), hit.is_some());
            }
            for face in mesh.faces() {
                let [a, b, c] = faces[face.index() as usize];
                prop_assert_eq!(face.indices(), [a, b, c]);
                prop_assert_eq!(face.corners(), [a, b, c].map(|i| vertices[i as usize]));
            }
            // The same areas summed in two orders (the two trees'): each sum of n positive
            // terms is within gamma(n - 1) of the exact one, relative to it.
            let (a, b) = (mesh.area(), fresh.area());
            prop_assert!((a - b).abs() <= 2.0 * support::gamma(faces.len() as u32) * a, "{a} vs {b}");
        }
    }

    /// The same for a tree of mixed objects (quads, triangles, spheres, and planes that are
    /// unbounded and tested on every ray) whose objects move, jump far away, turn into
    /// planes and back: after every update the tree finds the object the loop over them
    /// finds, by the number it was given, and `occluded` agrees with `hit`.
    #[test]
    fn a_moving_tree_answers_as_its_objects_after_every_update(
        seed in any::<u64>(),
        start in 0..OFFSETS.len(),
        count in 1usize..40,
        steps in prop::collection::vec(step(), 1..6),
    ) {
        let mut rng = SplitMix::new(seed);
        prop_assume!(meaningful(OFFSETS[start], SIZE));
        // Object `k` is made from its own seed, where the scene sits plus its own shift,
        // and is a plane or not: so the caller's list and the tree's slots can be made
        // alike at any time.
        let seeds: Vec<u64> = (0..count).map(|_| rng.next_u64()).collect();
        let mut shifts = vec![DVec3::ZERO; count];
        let mut planes: Vec<bool> = (0..count).map(|k| k % 13 == 12).collect();
        let mut offset = DVec3::splat(OFFSETS[start]);
        let make = |k: usize, offset: DVec3, shifts: &[DVec3], planes: &[bool]| {
            object(seeds[k], offset + shifts[k], planes[k])
        };
        let mut tree = Bvh::new((0..count).map(|k| make(k, offset, &shifts, &planes)).collect());
        for step in steps {
            if let Some(j) = step.jump
                && meaningful(OFFSETS[j], SIZE)
            {
                offset = DVec3::splat(OFFSETS[j]);
            }
            let reach = SIZE * 10f64.powi(step.scale);
            for shift in &mut shifts {
                *shift += reach * (rng.vec3() - 0.5);
            }
            for _ in 0..step.collapse {
                let k = rng.next_u64() as usize % count;
                planes[k] = !planes[k];
            }
            let order: Vec<usize> = (0..tree.len()).map(|i| tree.original_index(i)).collect();
            tree.update(|slots| {
                for (slot, &k) in slots.iter_mut().zip(&order) {
                    *slot = make(k, offset, &shifts, &planes);
                }
            });
            let objects: Vec<Box<dyn Hittable>> =
                (0..count).map(|k| make(k, offset, &shifts, &planes)).collect();
            let bbox = objects.iter().fold(hitkit::Aabb::EMPTY, |b, o| b.union(&o.bounding_box()));
            prop_assert_eq!(tree.bounding_box(), bbox);
            prop_assert!(tree.cost().now.is_finite());
            let numbers: Vec<usize> = (0..count).collect();
            agrees_with_the_loop(&tree, &objects, &numbers, offset, &mut rng, 48)?;
        }
    }
}

/// One change to a tree in a random sequence.
#[derive(Clone, Copy, Debug)]
enum Change {
    /// A new object (a plane, unbounded, where the flag says so: one in 8).
    Insert(bool),
    /// The object of this number (modulo one past the numbers given: some never were,
    /// some are removed already).
    Remove(usize),
    /// Every object moves by up to `10^scale` of the scene's size; the scene may jump.
    Move(Step),
    Rebuild,
    /// `Bvh::optimize` with this share of the leaves.
    Optimize(f64),
}

fn change() -> impl Strategy<Value = Change> {
    prop_oneof![
        4 => any::<u8>().prop_map(|b| Change::Insert(b % 8 == 0)),
        4 => any::<usize>().prop_map(Change::Remove),
        1 => step().prop_map(Change::Move),
        1 => Just(Change::Rebuild),
        2 => prop_oneof![Just(0.0), 0.0..1.0, Just(1.0)].prop_map(Change::Optimize),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Inserts, removes, moves, rebuilds and optimizations in a random sequence, from a tree of 0 to 30
    /// objects (quads, triangles, spheres, planes) at offsets to 1e12: after each, the tree
    /// finds the object (by number) and the `t` that the loop over the live objects finds,
    /// ties going to the smaller number; `occluded` agrees; removing answers with the
    /// object of that number, once; numbers are never given twice.
    #[test]
    fn inserts_and_removes_answer_as_the_loop(
        seed in any::<u64>(),
        start in 0..OFFSETS.len(),
        count in 0usize..30,
        changes in prop::collection::vec(change(), 1..40),
    ) {
        let mut rng = SplitMix::new(seed);
        prop_assume!(meaningful(OFFSETS[start], SIZE));
        let mut offset = DVec3::splat(OFFSETS[start]);
        // Object `k` (its number) is made from its seed, where the scene sits plus its own
        // shift, and is a plane or not.
        let mut seeds: Vec<u64> = Vec::new();
        let mut shifts: Vec<DVec3> = Vec::new();
        let mut planes: Vec<bool> = Vec::new();
        let make = object;
        for k in 0..count {
            seeds.push(rng.next_u64());
            shifts.push(DVec3::ZERO);
            planes.push(k % 11 == 10);
        }
        let mut live: Vec<bool> = vec![true; count];
        let mut tree = Bvh::new(
            (0..count).map(|k| make(seeds[k], offset + shifts[k], planes[k])).collect(),
        );
        for change in changes {
            match change {
                Change::Insert(plane) => {
                    seeds.push(rng.next_u64());
                    shifts.push(DVec3::ZERO);
                    planes.push(plane);
                    live.push(true);
                    let k = seeds.len() - 1;
                    prop_assert_eq!(tree.insert(make(seeds[k], offset, plane)), k);
                }
                Change::Remove(pick) => {
                    let k = pick % (seeds.len() + 1);
                    let removed = tree.remove(k);
                    let expected = live.get(k).copied().unwrap_or(false);
                    prop_assert_eq!(removed.is_some(), expected);
                    if let Some(object) = removed {
                        let made = make(seeds[k], offset + shifts[k], planes[k]);
                        prop_assert_eq!(object.bounding_box(), made.bounding_box());
                        live[k] = false;
                    }
                }
                Change::Move(step) => {
                    if let Some(j) = step.jump
                        && meaningful(OFFSETS[j], SIZE)
                    {
                        offset = DVec3::splat(OFFSETS[j]);
                    }
                    let reach = SIZE * 10f64.powi(step.scale);
                    for shift in &mut shifts {
                        *shift += reach * (rng.vec3() - 0.5);
                    }
                    let order: Vec<usize> = (0..tree.len()).map(|i| tree.original_index(i)).collect();
                    tree.update(|slots| {
                        for (slot, &k) in slots.iter_mut().zip(&order) {
                            *slot = make(seeds[k], offset + shifts[k], planes[k]);
                        }
                    });
                }
                Change::Rebuild => tree.rebuild(),
                Change::Optimize(share) => tree.optimize(share),
            }
            let numbers: Vec<usize> = (0..seeds.len()).filter(|&k| live[k]).collect();
            prop_assert_eq!(tree.len(), numbers.len());
            let objects: Vec<Box<dyn Hittable>> = numbers
                .iter()
                .map(|&k| make(seeds[k], offset + shifts[k], planes[k]))
                .collect();
            prop_assert!(tree.cost().now.is_finite());
            agrees_with_the_loop(&tree, &objects, &numbers, offset, &mut rng, 24)?;
        }
    }
}

/// Bad vertices are refused with the build's errors, and leave the mesh as it was.
#[test]
fn bad_updates_are_errors_and_change_nothing() {
    let (vertices, faces) = icosphere(1);
    let mut mesh = TriangleMesh::new(&vertices, &faces).unwrap();
    let ray = Ray::new(DVec3::new(0.1, 0.2, 5.0), DVec3::NEG_Z);
    let before = mesh.hit(&ray, FORWARD).map(|h| (h.primitive, h.t));
    assert!(before.is_some());

    let mut nan = vertices.clone();
    nan[7].y = f64::NAN;
    assert_eq!(
        mesh.set_vertices(&nan),
        Err(GeometryError::NonFiniteElement {
            what: "vertex",
            index: 7
        })
    );
    assert_eq!(
        mesh.set_vertices(&vertices[1..]),
        Err(GeometryError::LengthMismatch {
            what: "vertices",
            expected: vertices.len(),
            found: vertices.len() - 1,
        })
    );
    let mut huge = vertices.clone();
    huge[3] = DVec3::splat(1e300);
    assert_eq!(mesh.set_vertices(&huge), Err(GeometryError::OutOfRange));
    assert_eq!(mesh.hit(&ray, FORWARD).map(|h| (h.primitive, h.t)), before);
    assert_eq!(mesh.cost().ratio(), 1.0);
}

/// Normals, uvs and material survive a rebuild that an update forces (a face turning
/// degenerate), and `set_normals` replaces them.
#[test]
fn normals_uvs_and_material_survive_a_forced_rebuild() {
    let (mut vertices, faces) = icosphere(1);
    let normals: Vec<DVec3> = vertices.iter().map(|v| v.normalize()).collect();
    let mut mesh = TriangleMesh::new(&vertices, &faces)
        .unwrap()
        .with_normals(&normals)
        .unwrap()
        .with_material(hitkit::MaterialId(3));
    let [a, b, _] = faces[0];
    vertices[b as usize] = vertices[a as usize];
    mesh.set_vertices(&vertices).unwrap();
    // The two faces on the edge from `a` to `b` collapse; the tree is rebuilt without them.
    assert_eq!(mesh.hittable_face_count(), faces.len() - 2);
    let ray = Ray::new(DVec3::new(0.1, 0.2, 5.0), DVec3::NEG_Z);
    let hit = mesh.hit(&ray, FORWARD).unwrap();
    assert_eq!(hit.material, hitkit::MaterialId(3));
    let face = mesh
        .faces()
        .find(|f| Some(f.index()) == hit.primitive)
        .unwrap();
    let shading = hit.shading_normal;
    // Interpolated from the face's own corners' normals: within the cone they span.
    for i in face.indices() {
        assert!(
            shading.dot(normals[i as usize]) > 0.9,
            "{shading} vs {}",
            normals[i as usize]
        );
    }
    let tilted = DVec3::new(1.0, 2.0, 2.0) / 3.0;
    let flipped = vec![tilted; normals.len()];
    mesh.set_normals(&flipped).unwrap();
    assert_eq!(mesh.hit(&ray, FORWARD).unwrap().shading_normal, tilted);
    assert!(mesh.set_normals(&flipped[1..]).is_err());
}
