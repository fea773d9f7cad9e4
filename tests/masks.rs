//! Visibility masks: a ray sees the objects whose mask shares a bit with its own. A `Bvh`
//! and a list answer as the loop over the objects the ray sees, in `hit` and `occluded`,
//! passing over the others without a test; masks that meet everything change nothing; a
//! mask reaches objects inside instances.

mod support;

use hitkit::glam::{DQuat, DVec3};
use hitkit::{Bvh, Hittable, Interval, Masked, Ray, Sphere, Transformed};
use support::SplitMix;

const FORWARD: Interval = Interval::FORWARD;

/// Balls in a box 20 wide, each with a mask of four random bits of eight.
fn balls(rng: &mut SplitMix, n: usize) -> Vec<Masked<Sphere>> {
    (0..n)
        .map(|_| {
            let mask = (0..4).fold(0u32, |m, _| m | 1 << (rng.next_u64() % 8));
            let ball = Sphere::new(20.0 * (rng.vec3() - 0.5), 0.3 + rng.next_f64()).unwrap();
            Masked::new(ball, mask)
        })
        .collect()
}

fn random_ray(rng: &mut SplitMix) -> Ray {
    Ray::new(30.0 * (rng.vec3() - 0.5), rng.direction())
}

#[test]
fn a_tree_and_a_list_answer_as_the_loop_over_what_the_ray_sees() {
    let mut rng = SplitMix::new(21);
    let objects = balls(&mut rng, 300);
    let tree = Bvh::new(objects.clone());
    let mut passed_over = 0;
    for _ in 0..3000 {
        let ray = random_ray(&mut rng).with_mask(1 << (rng.next_u64() % 8));
        let seen: Vec<Sphere> = objects
            .iter()
            .filter(|o| o.mask() & ray.mask != 0)
            .map(|o| *o.object())
            .collect();
        let expected = support::brute_force(&seen, &ray, FORWARD).map(|(_, h)| h);
        assert_eq!(tree.hit(&ray, FORWARD), expected, "{ray:?}");
        assert_eq!(objects.hit(&ray, FORWARD), expected, "{ray:?}");
        assert_eq!(tree.occluded(&ray, FORWARD), expected.is_some());
        assert_eq!(objects.occluded(&ray, FORWARD), expected.is_some());
        let everything = support::brute_force(&objects, &ray.with_mask(u32::MAX), FORWARD);
        passed_over += usize::from(everything.map(|(_, h)| h.t) != expected.map(|h| h.t));
    }
    // Masks changed the answer on many rays: the test means something.
    assert!(passed_over > 300, "{passed_over}");
}

#[test]
fn objects_a_ray_does_not_see_cost_it_no_test() {
    let mut rng = SplitMix::new(22);
    let objects = balls(&mut rng, 300);
    let tree = Bvh::new(objects.clone());
    let (mut nodes, mut seen_tests) = (0, 0);
    for _ in 0..500 {
        let ray = random_ray(&mut rng);
        let blind = tree.hit_visits(&ray.with_mask(0), FORWARD);
        assert_eq!(blind.tests, 0);
        assert_eq!(tree.occluded_visits(&ray.with_mask(0), FORWARD).tests, 0);
        nodes += blind.nodes;
        seen_tests += tree.hit_visits(&ray, FORWARD).tests;
    }
    // The walk went on (masks are per object, not per node), and seeing rays test objects.
    assert!(nodes > 0 && seen_tests > 0);
}

#[test]
fn masks_that_meet_everything_change_nothing() {
    let mut rng = SplitMix::new(23);
    let objects = balls(&mut rng, 200);
    let plain: Vec<Sphere> = objects.iter().map(|o| *o.object()).collect();
    let (masked, unmasked) = (Bvh::new(objects.clone()), Bvh::new(plain));
    for _ in 0..2000 {
        let ray = random_ray(&mut rng);
        assert_eq!(masked.hit(&ray, FORWARD), unmasked.hit(&ray, FORWARD));
        assert_eq!(
            masked.occluded(&ray, FORWARD),
            unmasked.occluded(&ray, FORWARD)
        );
    }
}

#[test]
fn a_mask_reaches_inside_instances_and_nested_trees() {
    // A tree of turned instances, each of a tree of masked balls: the ray's mask passes
    // through the instance's move into the object's space.
    let mut rng = SplitMix::new(24);
    let inner = std::sync::Arc::new(Bvh::new(balls(&mut rng, 40)));
    let instances: Vec<_> = (0..10)
        .map(|_| {
            let turn = DQuat::from_axis_angle(rng.direction(), 6.0 * rng.next_f64());
            Transformed::new(inner.clone(), turn, 40.0 * (rng.vec3() - 0.5)).unwrap()
        })
        .collect();
    let outer = Bvh::new(instances.clone());
    let mut differs = 0;
    for _ in 0..2000 {
        let ray = Ray::new(60.0 * (rng.vec3() - 0.5), rng.direction());
        let masked = ray.with_mask(1 << (rng.next_u64() % 8));
        let hit = outer.hit(&masked, FORWARD);
        assert_eq!(
            hit,
            support::brute_force(&instances, &masked, FORWARD).map(|(_, h)| h)
        );
        assert_eq!(outer.occluded(&masked, FORWARD), hit.is_some());
        differs += usize::from(hit.map(|h| h.t) != outer.hit(&ray, FORWARD).map(|h| h.t));
    }
    assert!(differs > 50, "{differs}");
}

#[test]
fn a_masked_light_is_sampled_as_the_light() {
    use hitkit::PdfHittable;
    use hitkit::glam::DVec2;
    let ball = Sphere::new(DVec3::new(0.0, 5.0, 0.0), 1.0).unwrap();
    let lamp = Masked::new(ball, 0b10);
    let u = DVec2::new(0.3, 0.7);
    let d = lamp.sample_direction(DVec3::ZERO, u);
    assert_eq!(d, ball.sample_direction(DVec3::ZERO, u));
    assert_eq!(
        lamp.pdf_value(DVec3::ZERO, d),
        ball.pdf_value(DVec3::ZERO, d)
    );
}

/// Masks nested through wrappers and containers mean their AND, asked directly, through a
/// list or through a `Bvh`: a ball under random stacks of `Masked` (masks of a few of
/// eight bits), instances, trees, lists and boxes, seen by a ray aimed at it exactly where
/// the ray's mask meets every mask of the stack together, in `hit`, `find` (through the
/// containers) and `occluded` alike. Before masks narrowed the ray inside, a `Masked` of a
/// `Masked` was hit directly by a ray meeting both masks apart, and passed over by a list
/// whose check took their AND.
#[test]
fn nested_masks_mean_their_and_through_every_container() {
    let mut rng = SplitMix::new(48);
    let (mut seen, mut unseen, mut apart) = (0, 0, 0);
    for _ in 0..3000 {
        let ball = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0).unwrap();
        let mut object: Box<dyn Hittable> = Box::new(ball);
        let mut masks = Vec::new();
        for _ in 0..1 + rng.next_u64() % 5 {
            object = match rng.next_u64() % 5 {
                0 | 1 => {
                    let mask = (0..3).fold(0u32, |m, _| m | 1 << (rng.next_u64() % 8));
                    masks.push(mask);
                    Box::new(Masked::new(object, mask))
                }
                2 => Box::new(Transformed::new(object, DQuat::IDENTITY, DVec3::ZERO).unwrap()),
                3 => Box::new(Bvh::new(vec![object])),
                _ => Box::new(vec![object]),
            };
        }
        let all = masks.iter().fold(u32::MAX, |m, &k| m & k);
        for _ in 0..8 {
            let mask = (0..3).fold(0u32, |m, _| m | 1 << (rng.next_u64() % 8));
            let ray = Ray::new(DVec3::ZERO, DVec3::NEG_Z).with_mask(mask);
            let expected = mask & all != 0;
            let list = vec![&object];
            let tree = Bvh::new(vec![&object]);
            for (what, hit) in [
                ("direct", object.hit(&ray, FORWARD)),
                ("list", list.hit(&ray, FORWARD)),
                ("tree", tree.hit(&ray, FORWARD)),
            ] {
                assert_eq!(
                    hit.map(|h| h.t),
                    expected.then_some(4.0),
                    "{what} {masks:?} {mask:b}"
                );
            }
            for (what, occluded) in [
                ("direct", object.occluded(&ray, FORWARD)),
                ("list", list.occluded(&ray, FORWARD)),
                ("tree", tree.occluded(&ray, FORWARD)),
            ] {
                assert_eq!(occluded, expected, "{what} occluded {masks:?} {mask:b}");
            }
            seen += usize::from(expected);
            unseen += usize::from(!expected);
            // The case that differed: the ray meets every mask apart, not their AND.
            apart += usize::from(!expected && masks.iter().all(|&k| mask & k != 0));
        }
    }
    assert!(
        seen > 1000 && unseen > 1000 && apart > 100,
        "{seen} {unseen} {apart}"
    );
}

/// A spawned ray keeps the mask of the ray that made the hit: `spawn_ray` and
/// `spawn_ray_to` from a hit found directly, through a list, a `Bvh`, an instance and
/// `Masked` wrappers (whose narrowing of the ray inside does not reach the record), and
/// from a record made during a search (an instance's) alike. Before, spawned rays saw
/// everything, whatever their parent saw.
#[test]
fn spawned_rays_keep_the_mask_of_the_ray_that_made_the_hit() {
    let ball = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0).unwrap();
    let turned = Transformed::new(ball, DQuat::from_rotation_z(0.3), DVec3::ZERO).unwrap();
    let objects: Vec<Box<dyn Hittable>> = vec![
        Box::new(ball),
        Box::new(Masked::new(ball, 0b0110)),
        Box::new(Masked::new(Masked::new(ball, 0b0111), 0b1110)),
        Box::new(turned),
        Box::new(Masked::new(turned, 0b0010)),
        Box::new(
            Transformed::new(Masked::new(ball, 0b0110), DQuat::IDENTITY, DVec3::ZERO).unwrap(),
        ),
    ];
    let light = Sphere::new(DVec3::new(0.0, 10.0, -5.0), 1.0).unwrap();
    let target = light
        .hit(&Ray::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Y), FORWARD)
        .unwrap();
    for object in &objects {
        for mask in [0b0010u32, 0b0110, u32::MAX] {
            let ray = Ray::new(DVec3::ZERO, DVec3::NEG_Z).with_mask(mask);
            let list = vec![object];
            let tree = Bvh::new(vec![object]);
            for hit in [
                object.hit(&ray, FORWARD),
                list.hit(&ray, FORWARD),
                tree.hit(&ray, FORWARD),
            ] {
                let hit = hit.expect("every object meets these masks");
                assert_eq!(hit.mask, mask);
                assert_eq!(hit.spawn_ray(DVec3::Z).mask, mask);
                assert_eq!(hit.spawn_ray_to(&target).0.mask, mask);
            }
        }
    }
}

/// A mask never changes sampling: a lamp (a quad, a ball, a mesh of two faces) under random
/// stacks of wrappers (rigid and affine instances, boxes, `Arc`s, a `Vec`, a `Mixture` and
/// a `LightTree`, each of the stack and a second lamp), with `Masked` of random masks (0
/// among them) put in at random places, samples, and gives `light_pdf`, bit for bit as the
/// same stack without them: `sample_light` finds the light's surface whatever the masks.
/// Before, a lamp masked from every ray under an instance, a mixture or a tree sampled
/// nothing where it was picked.
#[test]
fn masks_never_change_sampling_through_any_wrapper() {
    use hitkit::glam::{DAffine3, DMat3, DVec2};
    use hitkit::{Emission, LightTree, Mixture, PdfHittable, Quad, ShadingContext, TriangleMesh};
    use std::sync::Arc;
    type Light = Box<dyn PdfHittable>;

    let mut rng = SplitMix::new(4803);
    let mut compared = 0;
    for trial in 0..600 {
        let lamp = move || -> Light {
            match trial % 3 {
                0 => Box::new(
                    Quad::new(DVec3::new(-1.0, 4.0, -1.0), 2.0 * DVec3::X, 2.0 * DVec3::Z).unwrap(),
                ),
                1 => Box::new(Sphere::new(DVec3::new(0.5, 5.0, 0.0), 1.0).unwrap()),
                _ => Box::new(
                    TriangleMesh::new(
                        &[
                            DVec3::new(-1.0, 4.0, -1.0),
                            DVec3::new(1.0, 4.0, -1.0),
                            DVec3::new(1.0, 4.5, 1.0),
                            DVec3::new(-1.0, 4.0, 1.0),
                        ],
                        &[[0, 1, 2], [0, 2, 3]],
                    )
                    .unwrap(),
                ),
            }
        };
        let other = || -> Light {
            Box::new(Quad::new(DVec3::new(3.0, 6.0, -1.0), DVec3::Z, DVec3::X).unwrap())
        };
        // The plan, drawn once: (wrapper, mask put outside it or not).
        let plan: Vec<(u64, Option<u32>)> = (0..1 + rng.next_u64() % 4)
            .map(|_| {
                let kind = rng.next_u64() % 7;
                let mask = match rng.next_u64() % 3 {
                    0 => None,
                    1 => Some(0),
                    _ => Some(1 << (rng.next_u64() % 8)),
                };
                (kind, mask)
            })
            .collect();
        let turn = DMat3::from_quat(DQuat::from_axis_angle(
            rng.direction(),
            6.0 * rng.next_f64(),
        ));
        let shift = 4.0 * (rng.vec3() - 0.5);
        let stretch = DMat3::from_diagonal(DVec3::new(1.0, 0.5, 3.0)) * turn;
        let build = |with_masks: bool| -> Light {
            let mut light: Light = lamp();
            if with_masks {
                light = Box::new(Masked::new(light, 0));
            }
            for &(kind, mask) in &plan {
                light = match kind {
                    0 => Box::new(Transformed::new(light, DQuat::from_mat3(&turn), shift).unwrap()),
                    1 => Box::new(
                        Transformed::affine(light, DAffine3::from_mat3_translation(stretch, shift))
                            .unwrap(),
                    ),
                    2 => Box::new(Arc::new(light)),
                    3 => Box::new(vec![light, other()]),
                    4 => Box::new(Mixture::new(vec![light, other()], &[3.0, 1.0]).unwrap()),
                    5 => Box::new(
                        LightTree::new(
                            vec![light, other()],
                            &[2.0, 1.0],
                            &[Emission::Everywhere, Emission::OneSide(DVec3::NEG_Y)],
                        )
                        .unwrap(),
                    ),
                    _ => Box::new(light),
                };
                if let (true, Some(mask)) = (with_masks, mask) {
                    light = Box::new(Masked::new(light, mask));
                }
            }
            light
        };
        let (masked, plain) = (build(true), build(false));
        for _ in 0..8 {
            let point = 3.0 * (rng.vec3() - 0.5);
            let at = if rng.next_u64().is_multiple_of(2) {
                ShadingContext::at(point)
            } else {
                ShadingContext::on_surface(point, rng.direction())
            };
            let u = DVec2::new(rng.next_f64(), rng.next_f64());
            let sample = plain.sample_light(&at, u);
            assert_eq!(masked.sample_light(&at, u), sample, "{plan:?} {at:?} {u}");
            for d in [sample.map_or(DVec3::Y, |s| s.direction), rng.direction()] {
                assert_eq!(
                    masked.light_pdf(&at, d),
                    plain.light_pdf(&at, d),
                    "{plan:?}"
                );
            }
            compared += usize::from(sample.is_some());
        }
    }
    // Most samples reach a light (the test compares surfaces, not only `None`s).
    assert!(compared > 2000, "{compared}");
}
