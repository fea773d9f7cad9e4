//! The BVH answers exactly as a brute-force loop over its objects: same t, same object, on
//! every ray; and stays correct on degenerate input.

mod support;

use std::sync::Arc;

use hitkit::glam::DVec3;
use hitkit::{Bvh, Disk, HitRecord, Hittable, Interval, Plane, Quad, Ray, Ring, Triangle};
use proptest::prelude::*;
use support::brute_force;
use support::distance::{planar_bound, to_polygon};

const FORWARD: Interval = Interval::FORWARD;

fn v3(range: f64) -> impl Strategy<Value = DVec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// A random shape's kind and frame: mostly quads, triangles, disks and rings, with an
/// infinite plane one time in twenty.
type Spec = (usize, DVec3, DVec3, DVec3, f64);

fn spec() -> impl Strategy<Value = Spec> {
    (0usize..20, v3(10.0), v3(2.0), v3(2.0), 0.0f64..0.9)
}

fn make(&(kind, q, u, v, inner): &Spec) -> Option<Box<dyn Hittable>> {
    Some(match kind {
        0 => Box::new(Plane::new(q, u, v).ok()?),
        1..=5 => Box::new(Quad::new(q, u, v).ok()?),
        6..=10 => Box::new(Quad::with_interior(q, u, v, Triangle).ok()?),
        11..=14 => Box::new(Quad::with_interior(q, u, v, Disk).ok()?),
        _ => Box::new(Quad::with_interior(q, u, v, Ring::new(inner).unwrap()).ok()?),
    })
}

/// Rays from inside and around the scene; some aimed at shape corners, some axis-aligned
/// (zero direction components), some with finite ranges.
fn ray() -> impl Strategy<Value = (Ray, Interval)> {
    let direction = prop_oneof![
        3 => v3(1.0),
        1 => (0usize..3, prop::bool::ANY).prop_map(|(axis, neg)| {
            let mut d = DVec3::ZERO;
            d[axis] = if neg { -1.0 } else { 1.0 };
            d
        }),
    ];
    let range = prop_oneof![3 => Just(FORWARD), 1 => (0.0f64..5.0, 5.0f64..40.0).prop_map(|(a, b)| Interval::new(a, b))];
    (v3(15.0), direction, range).prop_map(|(o, d, r)| (Ray::new(o, d), r))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn closest_hit_equals_brute_force(specs in prop::collection::vec(spec(), 0..120), rays in prop::collection::vec(ray(), 32)) {
        let objects: Vec<Box<dyn Hittable>> = specs.iter().filter_map(make).collect();
        let reference: Vec<Option<(usize, HitRecord)>> = rays.iter().map(|(r, i)| brute_force(&objects, r, *i)).collect();
        let occluded: Vec<bool> = rays.iter().map(|(r, i)| objects.iter().any(|o| o.hit(r, *i).is_some())).collect();
        let bvh = Bvh::new(objects);
        for (((ray, interval), expect), occl) in rays.iter().zip(reference).zip(occluded) {
            let got = bvh.hit_with_index(ray, *interval);
            prop_assert_eq!(got.map(|(i, h)| (i, h.t)), expect.map(|(i, h)| (i, h.t)), "ray {:?}", ray);
            prop_assert_eq!(got.map(|(_, h)| h), expect.map(|(_, h)| h));
            prop_assert_eq!(bvh.occluded(ray, *interval), occl);
        }
    }

    /// Rays aimed at points well inside shapes of a scene 1e9 from the origin hit the same
    /// objects as in the unshifted scene, but where they pass another shape's edge within
    /// what every shape widens by at 1e9 (its tolerance, about 1e-6 here: clause 2): then the
    /// shape the shifted scene names must lie within clause 1's bound, at 1e9, of its hit.
    #[test]
    fn a_scene_shifted_1e9_hits_the_same_objects(seed_shapes in prop::collection::vec((v3(10.0), v3(2.0), v3(2.0)), 1..60), picks in prop::collection::vec((any::<prop::sample::Index>(), 0.1f64..0.4, 0.1f64..0.4, v3(20.0)), 16)) {
        let shift = DVec3::new(1e9, -1e9, 1e9);
        let build = |offset: DVec3| -> Vec<Quad<Triangle>> {
            seed_shapes.iter().filter_map(|&(q, u, v)| Quad::with_interior(q + offset, u, v, Triangle).ok()).collect()
        };
        let (near, far) = (build(DVec3::ZERO), build(shift));
        prop_assume!(!near.is_empty() && near.len() == far.len());
        let frames: Vec<_> = near.iter().map(|q| (q.plane().q(), q.plane().u(), q.plane().v())).collect();
        let (near, far) = (Bvh::new(near), Bvh::new(far));
        for (pick, a, b, from) in picks {
            let (q, u, v) = frames[pick.index(frames.len())];
            // Well inside the triangle: alpha, beta >= 0.1, alpha + beta <= 0.8.
            let target = q + (a * u + b * v);
            let origin = target + from;
            prop_assume!(from.length() > 1.0);
            let ray0 = Ray::new(origin, target - origin);
            let ray1 = Ray::new(origin + shift, target - origin);
            let (h0, h1) = (near.hit_with_index(&ray0, FORWARD), far.hit_with_index(&ray1, FORWARD));
            prop_assert!(h0.is_some() && h1.is_some(), "aimed inside a shape");
            if let (Some((i, _)), Some((j, hit))) = (&h0, &h1)
                && i != j
            {
                let (q, u, v) = frames[*j];
                let bound = planar_bound(q + shift, u, v);
                let off = to_polygon(hit.point - shift, &[q, q + u, q + v]);
                prop_assert!(off <= bound, "shape {} hit {:e} from it (bound {:e})", j, off, bound);
            }
        }
    }
}

#[test]
fn an_empty_bvh_hits_nothing() {
    let bvh: Bvh<Quad> = Bvh::new(Vec::new());
    assert!(bvh.is_empty());
    assert_eq!(bvh.len(), 0);
    assert!(
        bvh.hit(&Ray::new(DVec3::ZERO, DVec3::X), Interval::UNIVERSE)
            .is_none()
    );
    assert!(!bvh.occluded(&Ray::new(DVec3::ZERO, DVec3::X), Interval::UNIVERSE));
    assert!(bvh.bounding_box().is_empty());
}

#[test]
fn a_one_object_bvh_is_that_object() {
    let quad = Quad::new(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let bvh = Bvh::new(vec![quad]);
    let ray = Ray::new(DVec3::new(0.5, 0.5, 1.0), DVec3::NEG_Z);
    assert_eq!(bvh.hit(&ray, FORWARD), quad.hit(&ray, FORWARD));
    assert_eq!(bvh.hit_with_index(&ray, FORWARD).unwrap().0, 0);
    assert!(
        bvh.hit(&Ray::new(DVec3::new(2.0, 0.5, 1.0), DVec3::NEG_Z), FORWARD)
            .is_none()
    );
    assert_eq!(bvh.bounding_box(), quad.bounding_box());
}

#[test]
fn coincident_objects_build_and_answer_with_the_first() {
    // 100,000 copies of the same quad: every centroid coincides, so SAH has nothing to
    // split on and the build must fall back to splitting by count.
    let quad = Quad::new(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let bvh = Bvh::new(vec![quad; 100_000]);
    assert_eq!(bvh.len(), 100_000);
    let ray = Ray::new(DVec3::new(0.25, 0.75, 1.0), DVec3::NEG_Z);
    let (index, hit) = bvh.hit_with_index(&ray, FORWARD).unwrap();
    assert_eq!((index, hit.t), (0, 1.0), "ties go to the first object");
    assert!(bvh.occluded(&ray, FORWARD));
    assert!(
        bvh.hit(&Ray::new(DVec3::new(1.5, 0.5, 1.0), DVec3::NEG_Z), FORWARD)
            .is_none()
    );
}

#[test]
fn unbounded_objects_live_beside_the_tree() {
    let objects: Vec<Box<dyn Hittable>> = vec![
        Box::new(Quad::new(DVec3::new(0.0, 0.0, -1.0), DVec3::X, DVec3::Y).unwrap()),
        Box::new(
            Plane::new(
                DVec3::new(0.0, 0.0, -5.0),
                DVec3::X,
                DVec3::new(0.0, 1.0, 0.1),
            )
            .unwrap(),
        ),
        Box::new(Quad::new(DVec3::new(0.0, 0.0, -2.0), DVec3::X, DVec3::Y).unwrap()),
    ];
    let bvh = Bvh::new(objects);
    assert!(!bvh.bounding_box().is_bounded());
    let hit = |x: f64| {
        bvh.hit_with_index(&Ray::new(DVec3::new(x, 0.5, 0.0), DVec3::NEG_Z), FORWARD)
            .map(|h| h.0)
    };
    assert_eq!(hit(0.5), Some(0));
    assert_eq!(hit(50.0), Some(1));
    // Original positions are kept through the reordering.
    assert!((0..3).all(|i| (0..3).any(|j| bvh.original_index(j) == i)));
}

#[test]
fn bvhs_nest_and_hold_trait_objects() {
    let row = |z: f64| -> Bvh<Quad> {
        Bvh::new(
            (0..50)
                .map(|i| Quad::new(DVec3::new(f64::from(i), 0.0, z), DVec3::X, DVec3::Y).unwrap())
                .collect(),
        )
    };
    let nested = Bvh::new(vec![row(-1.0), row(-2.0), row(-3.0)]);
    let ray = Ray::new(DVec3::new(10.5, 0.5, 0.0), DVec3::NEG_Z);
    assert_eq!(
        nested.hit_with_index(&ray, FORWARD).map(|(i, h)| (i, h.t)),
        Some((0, 1.0))
    );
    assert_eq!(
        nested
            .hit_with_index(&ray, Interval::new(1.5, 10.0))
            .map(|(i, h)| (i, h.t)),
        Some((1, 2.0))
    );
    let dynamic: Bvh<Arc<dyn Hittable>> = Bvh::new(vec![
        Arc::new(row(-1.0)),
        Arc::new(Quad::new(DVec3::new(10.0, 0.0, -0.5), DVec3::X, DVec3::Y).unwrap()),
    ]);
    assert_eq!(
        dynamic.hit_with_index(&ray, FORWARD).map(|(i, _)| i),
        Some(1)
    );
    let boxed: Bvh<Box<dyn Hittable>> = Bvh::new(vec![Box::new(row(-1.0)), Box::new(nested)]);
    assert_eq!(boxed.hit(&ray, FORWARD).map(|h| h.t), Some(1.0));
}

#[test]
fn axis_parallel_rays_in_slab_planes_are_not_lost() {
    // A grid of unit quads in the plane z = 0, edges on integer coordinates; rays lying in
    // the plane x = 3 (a slab plane of many boxes) with zero and negative-zero components.
    let quads: Vec<Quad> = (0..8)
        .flat_map(|i| {
            (0..8).map(move |j| {
                Quad::new(
                    DVec3::new(f64::from(i), f64::from(j), 0.0),
                    DVec3::X,
                    DVec3::Y,
                )
                .unwrap()
            })
        })
        .collect();
    let bvh = Bvh::new(quads.clone());
    for zero in [0.0, -0.0] {
        for y in [0.0, 2.0, 2.5, 8.0] {
            let ray = Ray::new(DVec3::new(3.0, y, 4.0), DVec3::new(zero, zero, -1.0));
            let expect = quads.iter().position(|q| q.hit(&ray, FORWARD).is_some());
            assert_eq!(
                bvh.hit_with_index(&ray, FORWARD).map(|h| h.0),
                expect,
                "y = {y}, zero = {zero:?}"
            );
            assert!(expect.is_some());
        }
    }
}

/// `hit_visits` and `occluded_visits` count what the two queries do: a ray above a row of
/// tiles tests the root's boxes and nothing else; one onto a tile tests it among a leaf's
/// few; a shadow ray through a stack of parallel tiles stops at the first it finds, while
/// the closest hit must rule out every tile nearer than its own, and the mesh counts its
/// faces as the tree counts its objects.
#[test]
fn visits_count_what_the_queries_do() {
    let tile = |x: f64, z: f64| Quad::new(DVec3::new(x, 0.0, z), DVec3::X, DVec3::Y).unwrap();
    let row = Bvh::new((0..100).map(|i| tile(f64::from(i), 0.0)).collect());
    let above = Ray::new(DVec3::new(41.5, 5.0, 1.0), DVec3::NEG_Z);
    let missed = row.hit_visits(&above, Interval::FORWARD);
    assert_eq!((missed.nodes, missed.tests), (1, 0));
    let onto = Ray::new(DVec3::new(41.5, 0.5, 1.0), DVec3::NEG_Z);
    let found = row.hit_visits(&onto, Interval::FORWARD);
    assert!(
        found.nodes >= 2 && (1..=8).contains(&found.tests),
        "{found:?}"
    );

    let stack = Bvh::new((0..64).map(|i| tile(0.0, -f64::from(i))).collect());
    let through = Ray::new(DVec3::new(0.5, 0.5, 1.0), DVec3::NEG_Z);
    let closest = stack.hit_visits(&through, Interval::FORWARD);
    let any = stack.occluded_visits(&through, Interval::FORWARD);
    assert!(
        any.tests >= 1 && any.tests <= 8 && any.tests <= closest.tests,
        "{any:?} {closest:?}"
    );
    assert_eq!(stack.occluded_visits(&above, Interval::FORWARD).tests, 0);

    let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
    let mesh = hitkit::TriangleMesh::new(&square, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    let down = Ray::new(DVec3::new(0.7, 0.2, 1.0), DVec3::NEG_Z);
    assert_eq!(mesh.hit_visits(&down, Interval::FORWARD).tests, 2);
    assert_eq!(mesh.occluded_visits(&down, Interval::FORWARD).nodes, 1);
}
