//! A `Bvh` of shapes built from arbitrary numbers answers every arbitrary ray as the loop
//! over its objects (clause 3): the same object, the same record; `occluded` as whether
//! the loop finds a hit; no object accepts a hit its own box rejects; nothing NaN.

#![no_main]

use std::sync::Arc;

use hitkit::{Bvh, Hittable};
use hitkit_fuzz::{Spec, TreeInput, check_record, closest};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|input: TreeInput| {
    let objects: Vec<Arc<dyn Hittable>> = input.shapes.iter().filter_map(Spec::shape).collect();
    let bvh = Bvh::new(objects.clone());
    let list: Vec<&dyn Hittable> = objects.iter().map(|o| o.as_ref()).collect();
    assert!(!bvh.bounding_box().min().is_nan() && !bvh.bounding_box().max().is_nan());
    for spec in &input.rays {
        let (ray, ray_t) = spec.get();
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
