//! A `Bvh` of shapes built from arbitrary numbers answers every arbitrary ray as the loop
//! over its objects (clause 3): the same object, the same record; `occluded` as whether
//! the loop finds a hit; no object accepts a hit its own box rejects; nothing NaN. With a
//! crowd, copies of the shapes about one point or along one line join them (the walk's
//! worst case: every child of every node entered), and the rays aim at the point.

#![no_main]

use std::sync::Arc;

use hitkit::{Bvh, Hittable};
use hitkit_fuzz::{Spec, TreeInput, check_record, closest, rays};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|input: TreeInput| {
    let mut specs = input.shapes.clone();
    if let Some(crowd) = &input.crowd
        && !specs.is_empty()
    {
        // The shapes' copies, in turn, about the crowd's point and along its line.
        let copies =
            (0..crowd.count()).map(|i| input.shapes[i % input.shapes.len()].moved(&crowd.map(i)));
        specs.extend(copies);
    }
    let objects: Vec<Arc<dyn Hittable>> = specs.iter().filter_map(Spec::shape).collect();
    let bvh = Bvh::new(objects.clone());
    let list: Vec<&dyn Hittable> = objects.iter().map(|o| o.as_ref()).collect();
    assert!(!bvh.bounding_box().min().is_nan() && !bvh.bounding_box().max().is_nan());
    for (ray, ray_t) in rays(&input.rays, input.crowd.as_ref()) {
        let expected = closest(&list, &ray, ray_t);
        let found = bvh.hit_with_index(&ray, ray_t);
        assert_eq!(
            found.map(|(i, h)| (i, h.t.to_bits(), h.point, h.normal, h.front_face)),
            expected.map(|(i, h)| (i, h.t.to_bits(), h.point, h.normal, h.front_face)),
            "the tree and the loop disagree on {ray:?} over {ray_t:?}"
        );
        assert_eq!(
            bvh.occluded(&ray, ray_t),
            expected.is_some(),
            "occluded on {ray:?}"
        );
        if let Some((i, hit)) = expected {
            check_record(&hit, ray_t, "tree");
            assert!(
                objects[i].bounding_box().hit(&ray, ray_t),
                "object {i} hit outside its box on {ray:?}"
            );
        }
    }
});
