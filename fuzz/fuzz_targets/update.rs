//! A `Bvh` changed by arbitrary inserts, removals, moves, optimizations and rebuilds answers
//! every ray as the loop over the objects it holds (by their numbers), as a tree built
//! anew over them would. With a crowd, copies of the first ball are inserted first, about
//! one point or along one line, and the rays aim there.

#![no_main]

use std::collections::BTreeMap;

use hitkit::glam::DVec3;
use hitkit::{Bvh, Hittable, Sphere};
use hitkit_fuzz::{Num, Op, UpdateInput, V, check_record, closest, rays};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|input: UpdateInput| {
    let ball = |(c, r): &(V, Num)| Sphere::new(c.get(), r.0).ok();
    let start: Vec<Sphere> = input.start.iter().filter_map(ball).collect();
    // The live objects by number, as the tree numbers them.
    let mut live: BTreeMap<usize, Sphere> = start.iter().copied().enumerate().collect();
    let mut bvh = Bvh::new(start);
    if let (Some(crowd), Some(first)) = (&input.crowd, input.start.first()) {
        // Copies of the first ball inserted one by one, about the crowd's point and along
        // its line: coincident, nested (each inside the last) or strung out.
        for i in 0..crowd.count() {
            let map = crowd.map(i);
            let (c, r) = (first.0.get(), first.1.0);
            let copy = (
                V::of(map.transform_point3(c)),
                Num(r * map.matrix3.x_axis.length()),
            );
            if let Some(s) = ball(&copy) {
                live.insert(bvh.insert(s), s);
            }
        }
    }
    for op in input.ops.iter().take(64) {
        match op {
            Op::Insert(c, r) => {
                if let Some(s) = ball(&(*c, *r)) {
                    live.insert(bvh.insert(s), s);
                }
            }
            Op::Remove(k) => {
                let number = usize::from(*k) % (live.keys().last().map_or(1, |n| n + 2));
                assert_eq!(bvh.remove(number).is_some(), live.remove(&number).is_some());
            }
            Op::Move(offset) => {
                let moved = |s: &Sphere, odd: bool| {
                    let d = if odd { offset.get() } else { DVec3::ZERO };
                    Sphere::new(s.center() + d, s.radius()).ok()
                };
                // Only where every sphere stays valid (a move past f64's range is not one).
                let next: Option<BTreeMap<usize, Sphere>> = live
                    .iter()
                    .map(|(&n, s)| Some((n, moved(s, n % 2 == 1)?)))
                    .collect();
                if let Some(next) = next {
                    let numbers: Vec<usize> =
                        (0..bvh.len()).map(|i| bvh.original_index(i)).collect();
                    bvh.update(|objects| {
                        for (o, n) in objects.iter_mut().zip(&numbers) {
                            *o = next[n];
                        }
                    });
                    live = next;
                }
            }
            Op::Optimize(share) => bvh.optimize(f64::from(*share) / 255.0),
            Op::Rebuild => bvh.rebuild(),
        }
        assert_eq!(bvh.len(), live.len());
    }
    let numbers: Vec<usize> = live.keys().copied().collect();
    let list: Vec<&Sphere> = live.values().collect();
    let rebuilt = Bvh::new(live.values().copied().collect::<Vec<_>>());
    for (ray, ray_t) in rays(&input.rays, input.crowd.as_ref()) {
        let expected = closest(&list, &ray, ray_t);
        let found = bvh.hit_with_index(&ray, ray_t);
        assert_eq!(
            found.map(|(n, h)| (n, h.t.to_bits())),
            expected.map(|(i, h)| (numbers[i], h.t.to_bits())),
            "the changed tree and the loop disagree on {ray:?} over {ray_t:?}"
        );
        assert_eq!(
            rebuilt.hit(&ray, ray_t).map(|h| h.t.to_bits()),
            found.map(|(_, h)| h.t.to_bits()),
            "the changed tree and a new one disagree on {ray:?}"
        );
        assert_eq!(bvh.occluded(&ray, ray_t), expected.is_some());
        if let Some((_, hit)) = found {
            check_record(&hit, ray_t, "updated tree");
        }
    }
});
