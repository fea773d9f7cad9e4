//! The light tree's choice of lamp on halls of many lamps (`hitkit_render::halls`): it does
//! not depend on the unit of length, it is at least as sharp as pbrt-v4's BVH light sampler
//! (`hitkit_render::pbrt_lights`, written from the book), and next-event estimation by its
//! picks is unbiased against each lamp's exact irradiance.

mod support;

use hitkit::glam::DVec2;
use hitkit::{PdfHittable, ShadingContext};
use hitkit_render::halls::{self, Hall, mean_choice_variance};
use support::{SplitMix, mean_and_error};

const LAMPS: usize = 1_000;
const SEED: u64 = 0x5eed;

/// Every length times a power of two (exact in floating point, down to 2^-7 and up to
/// 2^7): every probability is the same, bit for bit. The importance divides a power by a
/// squared distance clamped at a squared length, and bounds cosines by ratios of lengths:
/// each scales exactly. (pbrt-v4's clamp compares a length with a squared length; its
/// choices move with the unit.)
#[test]
fn the_choice_does_not_depend_on_the_unit() {
    for hall in Hall::ALL {
        let lamps = halls::lamps(hall, LAMPS, 1.0, SEED);
        let points = halls::points(hall, 8, 1.0, SEED);
        let unit = lamps.tree();
        for k in [-7, -3, 3, 7] {
            let scale = 2f64.powi(k);
            let scaled = halls::lamps(hall, LAMPS, scale, SEED).tree();
            for at in &points {
                let there = ShadingContext::on_surface(at.point * scale, at.normal.unwrap());
                for i in 0..lamps.quads.len() {
                    assert_eq!(
                        scaled.probability(&there, i),
                        unit.probability(at, i),
                        "{} hall at scale 2^{k}, lamp {i}",
                        hall.name()
                    );
                }
            }
        }
    }
}

/// On each hall, the variance of the tree's choice of lamp (the relative variance of one
/// sample's estimate of the total unoccluded irradiance, mean over 40 floor points, wall
/// points on the walls hall) is at most pbrt-v4's at scale 1, where pbrt's clamp is
/// lightest; and at scale 0.01, pbrt's is more than twice the tree's (its clamp then
/// dominates the distance). On the walls hall the tree's was six times pbrt's before a
/// point inside a cluster's box divided by its half-diagonal rather than the distance to
/// its centre (a wall point amid the wall's own lamps took their sibling's share). From
/// one-sided receivers, the choice is sharper where lamps lie behind them, and the same
/// elsewhere.
#[test]
fn the_choice_is_at_least_as_sharp_as_pbrt_v4s() {
    for hall in Hall::ALL {
        for scale in [1.0, 0.01] {
            let lamps = halls::lamps(hall, LAMPS, scale, SEED);
            let points = halls::points(hall, 40, scale, SEED);
            let (t, b) = (lamps.tree(), lamps.pbrt());
            let ours = mean_choice_variance(&lamps, &points, |at, i| t.probability(at, i));
            let theirs = mean_choice_variance(&lamps, &points, |at, i| b.probability(at, i));
            let one_sided =
                mean_choice_variance(&lamps, &points, |at, i| t.probability_reflecting(at, i));
            let name = hall.name();
            // Where lamps lie behind the receivers (the walls hall's next rooms), a
            // one-sided receiver's choice is the sharper; elsewhere, the same.
            if hall == Hall::Walls {
                assert!(one_sided < ours, "{name}: {one_sided} against {ours}");
            } else {
                assert_eq!(one_sided, ours, "{name}");
            }
            if scale == 1.0 {
                assert!(ours <= theirs, "{name}: {ours} against pbrt-v4's {theirs}");
            } else {
                assert!(
                    2.0 * ours < theirs,
                    "{name} at {scale}: {ours} against {theirs}"
                );
            }
        }
    }
}

/// Next-event estimation by `LightTree::pick` and the picked lamp's own density, at floor
/// points of each hall: the mean of 4,000 samples within 4 standard errors of the exact
/// irradiance (Lambert's formula summed over the lamps). A probability off by a factor,
/// or a lamp that lights the point and is never picked, moves the mean by many.
#[test]
fn next_event_estimation_by_pick_is_unbiased() {
    let mut rng = SplitMix::new(SEED);
    for hall in Hall::ALL {
        let lamps = halls::lamps(hall, LAMPS, 1.0, SEED);
        let t = lamps.tree();
        // From receivers of either side, and of one side (the walls hall's lamps beyond a
        // wall never picked there).
        let points = halls::points(hall, 4, 1.0, SEED);
        let sides = points.iter().flat_map(|at| [(*at, false), (*at, true)]);
        for (at, one_sided) in sides {
            let exact: f64 = (0..lamps.quads.len())
                .map(|i| halls::irradiance(&lamps, i, &at))
                .sum();
            let n = at.normal.unwrap();
            let samples: Vec<f64> = (0..4_000)
                .map(|_| {
                    // (From one side, a walk may end on no light: a node none of whose
                    // lights can light the point.)
                    let x = rng.next_f64();
                    let pick = if one_sided {
                        t.pick_reflecting(&at, x)
                    } else {
                        t.pick(&at, x)
                    };
                    let Some(pick) = pick else {
                        return 0.0;
                    };
                    let i = pick.light;
                    let u = DVec2::new(pick.rest, rng.next_f64());
                    let Some(s) = lamps.quads[i].sample_light(&at, u) else {
                        return 0.0;
                    };
                    let (cos_lamp, cos) = (-s.direction.dot(lamps.normals[i]), s.direction.dot(n));
                    if cos_lamp > 0.0 && cos > 0.0 {
                        lamps.radiance(i) * cos / (pick.probability * s.pdf)
                    } else {
                        0.0
                    }
                })
                .collect();
            let (mean, error) = mean_and_error(&samples);
            assert!(
                (mean - exact).abs() <= 4.0 * error,
                "{} hall at {}: {mean} +- {error} against {exact}",
                hall.name(),
                at.point
            );
        }
    }
}
