//! `--halls`: the light tree against pbrt-v4's BVH light sampler (written from the book, in
//! `hitkit_render::pbrt_lights`) and the power mixture, on halls of many lamps seen from
//! the floor: the variance of each sampler's choice of lamp across units of length, and
//! the relative mean squared error times time of next-event estimation of the floor's
//! irradiance. With `--picks`, the pick alone: nanoseconds a pick of the tree and of
//! pbrt-v4's sampler.

use std::hint::black_box;
use std::time::Instant;

use hitkit::glam::DVec2;
use hitkit::{Mixture, PdfHittable, ShadingContext};
use hitkit_render::halls::{self, Hall, Lamps, mean_choice_variance};
use hitkit_render::workloads::{self, SplitMix};

use super::Args;

/// Lamp counts.
const COUNTS: [usize; 2] = [1_000, 10_000];
/// Units of length the halls are measured in.
const SCALES: [f64; 5] = [0.01, 0.1, 1.0, 10.0, 100.0];
/// Floor points for the choice's variance (each asks every lamp's probability).
const VARIANCE_POINTS: usize = 200;
/// Floor points for the error of the estimates, and samples per point.
const ESTIMATE_POINTS: usize = 2_000;
const SPP: [usize; 2] = [16, 64];

/// The halls `--scene` names (all without it).
fn chosen(args: &Args) -> impl Iterator<Item = Hall> + '_ {
    Hall::ALL.into_iter().filter(|h| {
        args.scene
            .as_ref()
            .is_none_or(|s| h.name().contains(s.as_str()))
    })
}

/// One row per hall and count: the choice's variance of the tree at every scale (from
/// receivers of either side, then of one side), then pbrt's at every scale.
pub(super) fn variance_rows(args: &Args) -> Vec<String> {
    let mut rows = Vec::new();
    for hall in chosen(args) {
        for n in COUNTS {
            let (mut tree_row, mut one_sided_row, mut pbrt_row) =
                (Vec::new(), Vec::new(), Vec::new());
            for scale in SCALES {
                let lamps = halls::lamps(hall, n, scale, args.seed);
                let points = halls::points(hall, VARIANCE_POINTS, scale, args.seed);
                let t = lamps.tree();
                let b = lamps.pbrt();
                tree_row.push(mean_choice_variance(&lamps, &points, |at, i| {
                    t.probability(at, i)
                }));
                one_sided_row.push(mean_choice_variance(&lamps, &points, |at, i| {
                    t.probability_reflecting(at, i)
                }));
                pbrt_row.push(mean_choice_variance(&lamps, &points, |at, i| {
                    b.probability(at, i)
                }));
            }
            let cells = |r: &[f64]| {
                r.iter()
                    .map(|v| format!("{v:.3}"))
                    .collect::<Vec<_>>()
                    .join(" | ")
            };
            rows.push(format!(
                "| {} | {n} | light tree | {} |",
                hall.name(),
                cells(&tree_row)
            ));
            rows.push(format!(
                "| {} | {n} | light tree, one-sided receivers | {} |",
                hall.name(),
                cells(&one_sided_row)
            ));
            rows.push(format!(
                "| {} | {n} | pbrt-v4 BVH | {} |",
                hall.name(),
                cells(&pbrt_row)
            ));
        }
    }
    rows
}

/// The floor's irradiance at `at` by next-event estimation: `spp` samples, each a light
/// picked by `pick` (its index, probability and the rest of `u`), a point on it sampled by
/// its own density, and the lamp's radiance times the cosine at the floor over both.
fn estimate(
    lamps: &Lamps,
    at: &ShadingContext,
    spp: usize,
    rng: &mut SplitMix,
    pick: impl Fn(f64) -> Option<(usize, f64, f64)>,
) -> f64 {
    let n = at.normal.expect("a floor point");
    let mut sum = 0.0;
    for _ in 0..spp {
        let (u, v) = (rng.next_f64(), rng.next_f64());
        let Some((i, p, rest)) = pick(u) else {
            continue;
        };
        let Some(s) = lamps.quads[i].sample_light(at, DVec2::new(rest, v)) else {
            continue;
        };
        // One-sided lamps: light only where the sample sees the lamp's front.
        let cos_light = -s.direction.dot(lamps.normals[i]);
        let cos = s.direction.dot(n);
        if cos_light > 0.0 && cos > 0.0 && s.pdf > 0.0 {
            sum += lamps.radiance(i) * cos / (p * s.pdf);
        }
    }
    sum / spp as f64
}

/// The relative mean squared error of the estimates over the floor points, the seconds
/// they took, and their product.
fn error_and_time(
    lamps: &Lamps,
    points: &[ShadingContext],
    exact: &[f64],
    spp: usize,
    seed: u64,
    pick: impl Fn(&ShadingContext, f64) -> Option<(usize, f64, f64)>,
) -> (f64, f64) {
    let mut rng = SplitMix::new(seed);
    let start = Instant::now();
    let estimates: Vec<f64> = points
        .iter()
        .map(|at| black_box(estimate(lamps, at, spp, &mut rng, |u| pick(at, u))))
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    let mse = estimates
        .iter()
        .zip(exact)
        .map(|(e, x)| ((e - x) / x).powi(2))
        .sum::<f64>()
        / points.len() as f64;
    (mse, seconds)
}

/// One row per hall, count, spp and sampler: relative MSE, seconds, their product, and the
/// product over pbrt's (each sampler's time the median of `args.runs`, in alternation).
pub(super) fn estimate_rows(args: &Args) -> Vec<String> {
    let mut rows = Vec::new();
    for hall in chosen(args) {
        for n in COUNTS {
            let lamps = halls::lamps(hall, n, 1.0, args.seed);
            let points = halls::points(hall, ESTIMATE_POINTS, 1.0, args.seed);
            let exact: Vec<f64> = points
                .iter()
                .map(|at| {
                    (0..lamps.quads.len())
                        .map(|i| halls::irradiance(&lamps, i, at))
                        .sum()
                })
                .collect();
            let t = lamps.tree();
            let b = lamps.pbrt();
            let mixture = Mixture::new(lamps.quads.clone(), &lamps.powers).expect("powers");
            for spp in SPP {
                let mut results: [Vec<(f64, f64)>; 4] = Default::default();
                for run in 0..args.runs {
                    let seed = args.seed.wrapping_add(run as u64);
                    // Each run starts with another sampler, so that none is always the
                    // first after the exact irradiance's computation.
                    for k in 0..4 {
                        let which = (k + run) % 4;
                        let measured = match which {
                            0 => error_and_time(&lamps, &points, &exact, spp, seed, |at, u| {
                                t.pick(at, u).map(|p| (p.light, p.probability, p.rest))
                            }),
                            1 => error_and_time(&lamps, &points, &exact, spp, seed, |at, u| {
                                b.pick(at, u)
                            }),
                            2 => error_and_time(&lamps, &points, &exact, spp, seed, |_, u| {
                                mixture.pick(u).map(|p| (p.light, p.probability, p.rest))
                            }),
                            _ => error_and_time(&lamps, &points, &exact, spp, seed, |at, u| {
                                t.pick_reflecting(at, u)
                                    .map(|p| (p.light, p.probability, p.rest))
                            }),
                        };
                        results[which].push(measured);
                    }
                }
                let summary: Vec<(f64, f64)> = results
                    .iter()
                    .map(|r| {
                        let mut times: Vec<f64> = r.iter().map(|x| x.1).collect();
                        times.sort_by(f64::total_cmp);
                        let mse = r.iter().map(|x| x.0).sum::<f64>() / r.len() as f64;
                        (mse, times[times.len() / 2])
                    })
                    .collect();
                let anchor = summary[1].0 * summary[1].1;
                for (name, (mse, secs)) in [
                    "light tree, pick",
                    "pbrt-v4 BVH",
                    "power mixture, pick",
                    "light tree, one-sided, pick",
                ]
                .iter()
                .zip(&summary)
                {
                    rows.push(format!(
                        "| {} | {n} | {spp} | {name} | {mse:.4} | {:.1} | {:.3} | {:.2}x |",
                        hall.name(),
                        secs * 1e3,
                        mse * secs * 1e3,
                        mse * secs / anchor
                    ));
                }
            }
        }
    }
    rows
}

/// Prints both tables.
pub(super) fn print(args: &Args) {
    println!(
        "{}; single-threaded; seed {:#x}\n",
        workloads::machine(),
        args.seed
    );
    println!(
        "Variance of the choice of lamp (`sum f_i^2 / p_i / F^2 - 1`, mean over {VARIANCE_POINTS} floor points, wall points for the walls hall), every length times the scale:\n"
    );
    println!("| hall | lamps | sampler | 0.01 | 0.1 | 1 | 10 | 100 |");
    println!("|---|---:|---|---:|---:|---:|---:|---:|");
    variance_rows(args).iter().for_each(|r| println!("{r}"));
    println!(
        "\nNext-event estimation of the irradiance at {ESTIMATE_POINTS} floor points (on the walls for the walls hall; scale 1, no occluders): relative MSE (mean of {} runs), ms (median), their product, and the product over pbrt-v4's:\n",
        args.runs
    );
    println!("| hall | lamps | spp | sampler | rel. MSE | ms | MSE x ms | vs pbrt-v4 |");
    println!("|---|---:|---:|---|---:|---:|---:|---:|");
    estimate_rows(args).iter().for_each(|r| println!("{r}"));
}

/// Floor points and picks at each for `--picks`.
const PICK_POINTS: usize = 200;
const PICKS: usize = 500;

/// `PICKS` picks of the tree at each point (`u` spread over `[0, 1)`): a function of its
/// own, for callgrind's `--toggle-collect=*tree_picks*`.
#[inline(never)]
fn tree_picks(tree: &hitkit::LightTree<hitkit::Quad>, points: &[ShadingContext]) -> f64 {
    let mut sum = 0.0;
    for (i, at) in points.iter().enumerate() {
        for j in 0..PICKS {
            let u = ((i * 7919 + j * 104_729) % 100_000) as f64 / 100_000.0;
            if let Some(p) = tree.pick(at, u) {
                sum += p.probability + p.light as f64;
            }
        }
    }
    sum
}

/// [`tree_picks`] of pbrt-v4's sampler (`--toggle-collect=*pbrt_picks*`).
#[inline(never)]
fn pbrt_picks(b: &hitkit_render::pbrt_lights::PbrtLightBvh, points: &[ShadingContext]) -> f64 {
    let mut sum = 0.0;
    for (i, at) in points.iter().enumerate() {
        for j in 0..PICKS {
            let u = ((i * 7919 + j * 104_729) % 100_000) as f64 / 100_000.0;
            if let Some((light, p, _)) = b.pick(at, u) {
                sum += p + light as f64;
            }
        }
    }
    sum
}

/// `--halls --picks`: nanoseconds a pick, the tree's and pbrt-v4's, medians of `args.runs`
/// in alternation (each run starting with the other), and their ratio.
pub(super) fn print_picks(args: &Args) {
    println!(
        "{}; single-threaded; {PICK_POINTS} floor points (wall points for the walls hall), {PICKS} picks each; median of {} runs in alternation\n",
        workloads::machine(),
        args.runs
    );
    println!("| hall | lamps | tree ns a pick | pbrt-v4 ns a pick | tree / pbrt |");
    println!("|---|---:|---:|---:|---:|");
    for hall in chosen(args) {
        for n in COUNTS {
            let lamps = halls::lamps(hall, n, 1.0, args.seed);
            let points = halls::points(hall, PICK_POINTS, 1.0, args.seed);
            let (t, b) = (lamps.tree(), lamps.pbrt());
            let (mut tree, mut pbrt) = (Vec::new(), Vec::new());
            for run in 0..args.runs.max(1) {
                for k in 0..2 {
                    let start = Instant::now();
                    if (k + run) % 2 == 0 {
                        black_box(tree_picks(&t, &points));
                        tree.push(start.elapsed().as_secs_f64());
                    } else {
                        black_box(pbrt_picks(&b, &points));
                        pbrt.push(start.elapsed().as_secs_f64());
                    }
                }
            }
            let median = |v: &mut Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2] * 1e9 / (PICK_POINTS * PICKS) as f64
            };
            let (a, c) = (median(&mut tree), median(&mut pbrt));
            println!(
                "| {} | {n} | {a:.1} | {c:.1} | {:.2}x |",
                hall.name(),
                a / c
            );
        }
    }
}
