//! A list of lights as one light: a uniform or weighted mixture whose density integrates to
//! 1, whose samples hit one of the lights, and whose density is the weighted mean of
//! theirs; weighted by power, it estimates the light arriving with less variance.

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{GeometryError, Hittable, Interval, Mixture, PdfHittable, Quad, Ray};
use support::SplitMix;

fn lights() -> Vec<Box<dyn PdfHittable>> {
    support::four_lights()
}

/// Monte Carlo over uniform directions: the mean of 4 pi pdf is 1 within 5 standard
/// errors (from the sample variance).
fn assert_integrates_to_one(light: &dyn PdfHittable, seed: u64) {
    let mut rng = SplitMix::new(seed);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let x = 4.0 * std::f64::consts::PI * light.pdf_value(DVec3::ZERO, rng.direction());
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / f64::from(n);
    let se = ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt();
    assert!(
        (mean - 1.0).abs() <= 5.0 * se && se < 0.03,
        "{mean} +- {se}"
    );
}

#[test]
fn the_mixture_density_integrates_to_one() {
    assert_integrates_to_one(&lights(), 1);
}

#[test]
fn mixture_samples_hit_a_light_with_the_mean_density() {
    let lights = lights();
    let mut rng = SplitMix::new(2);
    let mut picked = [0usize; 4];
    for _ in 0..4000 {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        let d = lights.sample_direction(DVec3::ZERO, u);
        let pdf = lights.pdf_value(DVec3::ZERO, d);
        assert!(pdf > 0.0 && pdf.is_finite());
        let mean: f64 = lights
            .iter()
            .map(|l| l.pdf_value(DVec3::ZERO, d))
            .sum::<f64>()
            / 4.0;
        assert_eq!(pdf, mean);
        let index = lights.iter().position(|l| {
            l.hit(&Ray::new(DVec3::ZERO, d), Interval::FORWARD)
                .is_some()
        });
        picked[index.expect("a sampled direction hits a light")] += 1;
    }
    // Each light is picked about a quarter of the time (4000 draws: sd about 27).
    assert!(
        picked.iter().all(|&k| (850..=1150).contains(&k)),
        "{picked:?}"
    );
    // An empty list has density 0.
    let d = DVec3::new(1.5, 2.0, 0.5);
    let none: Vec<Quad> = Vec::new();
    assert_eq!(none.pdf_value(DVec3::ZERO, d), 0.0);
    assert_eq!(
        none.sample_direction(DVec3::ZERO, DVec2::splat(0.5)),
        DVec3::ZERO
    );
}

const WEIGHTS: [f64; 4] = [4.0, 1.0, 0.0, 3.0];

#[test]
fn a_weighted_mixture_integrates_to_one_and_picks_lights_by_weight() {
    let mixture = Mixture::new(lights(), &WEIGHTS).unwrap();
    assert_integrates_to_one(&mixture, 3);
    let mut rng = SplitMix::new(4);
    let n = 8000;
    let mut picked = [0usize; 4];
    for _ in 0..n {
        let d = mixture.sample_direction(DVec3::ZERO, DVec2::new(rng.next_f64(), rng.next_f64()));
        let pdf = mixture.pdf_value(DVec3::ZERO, d);
        let weighted: f64 = (0..4)
            .map(|i| mixture.probability(i) * mixture.lights()[i].pdf_value(DVec3::ZERO, d))
            .sum();
        assert!(pdf > 0.0 && pdf.is_finite());
        // The same products summed in the same order (a weight of 0 adds an exact 0).
        assert_eq!(pdf, weighted);
        let index = mixture.lights().iter().position(|l| {
            l.hit(&Ray::new(DVec3::ZERO, d), Interval::FORWARD)
                .is_some()
        });
        picked[index.expect("a sampled direction hits a light")] += 1;
    }
    // Binomial counts: within 5 standard deviations sqrt(n p (1 - p)) of n p; the light of
    // weight 0 is never picked.
    for (i, &count) in picked.iter().enumerate() {
        let p = WEIGHTS[i] / 8.0;
        assert_eq!(mixture.probability(i), p);
        let sd = (n as f64 * p * (1.0 - p)).sqrt();
        assert!(
            (count as f64 - n as f64 * p).abs() <= 5.0 * sd,
            "light {i}: {count} of {n}, expected {}",
            n as f64 * p
        );
    }
    // The endpoints of u.x pick the first and the last light of non-zero weight.
    for (x, light) in [(0.0, 0), (1.0, 3), (f64::NAN, 0)] {
        let d = mixture.sample_direction(DVec3::ZERO, DVec2::new(x, 0.5));
        assert!(
            mixture.lights()[light].pdf_value(DVec3::ZERO, d) > 0.0,
            "u.x = {x}"
        );
    }
}

/// A bright and a dim light of the same size on either side: the light arriving at the
/// origin, `sum radiance cos / pdf`, estimated with the two picked by power and picked
/// uniformly. Both are unbiased (the same mean within 5 standard errors), and the power
/// weights, which follow the integrand, cut the variance.
#[test]
fn power_weights_cut_the_variance_of_unequal_lights() {
    let quads = vec![
        Quad::new(DVec3::new(-0.5, 1.0, -0.5), DVec3::X, DVec3::Z).unwrap(),
        Quad::new(DVec3::new(-0.5, -1.0, -0.5), DVec3::X, DVec3::Z).unwrap(),
    ];
    let radiance = [20.0, 1.0];
    let power = [radiance[0] * quads[0].area(), radiance[1] * quads[1].area()];
    let by_power = Mixture::new(quads.clone(), &power).unwrap();
    let uniform = Mixture::uniform(quads);
    let estimate = |mixture: &Mixture<Quad>, seed| {
        let mut rng = SplitMix::new(seed);
        let n = 50_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let d =
                mixture.sample_direction(DVec3::ZERO, DVec2::new(rng.next_f64(), rng.next_f64()));
            let pdf = mixture.pdf_value(DVec3::ZERO, d);
            let light = usize::from(d.y < 0.0);
            let x = radiance[light] * d.normalize().y.abs() / pdf;
            sum += x;
            sum2 += x * x;
        }
        let mean = sum / f64::from(n);
        let variance = sum2 / f64::from(n) - mean * mean;
        (mean, variance, (variance / f64::from(n)).sqrt())
    };
    let (weighted, var_w, se_w) = estimate(&by_power, 5);
    let (even, var_u, se_u) = estimate(&uniform, 6);
    assert!(
        (weighted - even).abs() <= 5.0 * (se_w * se_w + se_u * se_u).sqrt(),
        "{weighted} +- {se_w} vs {even} +- {se_u}"
    );
    assert!(
        var_w < 0.5 * var_u,
        "variance {var_w} by power, {var_u} uniform"
    );
}

#[test]
fn bad_weights_are_refused_and_an_empty_mixture_is_dark() {
    let quad = || Quad::new(DVec3::Y, DVec3::X, DVec3::Z).unwrap();
    for (weights, expected) in [
        (
            vec![1.0],
            GeometryError::LengthMismatch {
                what: "weights",
                expected: 2,
                found: 1,
            },
        ),
        (
            vec![1.0, f64::NAN],
            GeometryError::NonFinite { what: "weight" },
        ),
        (
            vec![1.0, f64::INFINITY],
            GeometryError::NonFinite { what: "weight" },
        ),
        (
            vec![1.0, -1.0],
            GeometryError::InvalidParameter {
                what: "weight",
                value: -1.0,
                domain: "[0, infinity)",
            },
        ),
        (
            vec![0.0, 0.0],
            GeometryError::InvalidParameter {
                what: "sum of weights",
                value: 0.0,
                domain: "(0, infinity)",
            },
        ),
    ] {
        assert_eq!(
            Mixture::new(vec![quad(), quad()], &weights).unwrap_err(),
            expected
        );
    }
    // Weights near f64::MAX do not overflow their sum.
    let huge = Mixture::new(vec![quad(), quad()], &[f64::MAX, f64::MAX]).unwrap();
    assert_eq!(huge.probability(1), 0.5);
    let empty = Mixture::<Quad>::uniform(Vec::new());
    assert_eq!(empty.pdf_value(DVec3::ZERO, DVec3::Y), 0.0);
    assert_eq!(
        empty.sample_direction(DVec3::ZERO, DVec2::splat(0.5)),
        DVec3::ZERO
    );
}

/// A `LightSample` says which light it is on: the light of that index in the tree, the
/// mixture or the list that sampled it (through an instance and a mask around it) finds
/// the sampled point along the sample's direction, at its distance. What a textured
/// emitter's lookup needs to know, where the record alone does not say.
#[test]
fn a_sample_names_its_light() {
    use hitkit::glam::{DQuat, DVec2, DVec3};
    use hitkit::{
        Emission, Hittable, Interval, LightTree, Masked, Mixture, PdfHittable, Quad, Ray,
        ShadingContext, Transformed,
    };
    let lamps: Vec<Quad> = (0..12)
        .map(|i| {
            let x = f64::from(i) * 1.5 - 8.0;
            Quad::new(
                DVec3::new(x, 4.0 + 0.1 * f64::from(i % 3), -1.0),
                DVec3::X,
                DVec3::Z,
            )
            .unwrap()
        })
        .collect();
    let emission = vec![Emission::BothSides(DVec3::Y); lamps.len()];
    let powers: Vec<f64> = (0..lamps.len()).map(|i| 1.0 + i as f64).collect();
    let samplers: Vec<Box<dyn PdfHittable>> = vec![
        Box::new(LightTree::new(lamps.clone(), &powers, &emission).unwrap()),
        Box::new(Mixture::new(lamps.clone(), &powers).unwrap()),
        Box::new(lamps.clone()),
        Box::new(
            Transformed::new(
                Masked::new(
                    LightTree::new(lamps.clone(), &powers, &emission).unwrap(),
                    0,
                ),
                DQuat::IDENTITY,
                DVec3::ZERO,
            )
            .unwrap(),
        ),
    ];
    let mut rng = support::SplitMix::new(4907);
    for sampler in &samplers {
        let mut named = vec![0; lamps.len()];
        for _ in 0..2000 {
            let at = ShadingContext::on_surface(
                DVec3::new(16.0 * rng.next_f64() - 8.0, 0.0, 2.0 * rng.next_f64() - 1.0),
                DVec3::Y,
            );
            let u = DVec2::new(rng.next_f64(), rng.next_f64());
            let Some(sample) = sampler.sample_light(&at, u) else {
                continue;
            };
            let ray = Ray::new(at.point, sample.direction);
            let hit = lamps[sample.light]
                .hit(&ray, Interval::FORWARD)
                .expect("the named light");
            assert_eq!(hit.t, sample.distance);
            named[sample.light] += 1;
        }
        // Every light was named (the index is not always 0).
        assert!(named.iter().all(|&n| n > 0), "{named:?}");
    }
}

/// `LightTree::pick` and `Mixture::pick`: the frequency of each light among the picks of
/// stratified numbers is its probability (to within five standard deviations), the pick's
/// probability is `probability` bit for bit, what is left of the number is in `[0, 1)`,
/// and next-event estimation by the pick (the light's own density times the pick's
/// probability) agrees with `sample_light`'s full density (irradiance within four
/// standard errors).
#[test]
fn a_pick_has_the_probability_it_says() {
    use hitkit::glam::{DVec2, DVec3};
    use hitkit::{Emission, LightTree, Mixture, PdfHittable, Quad, ShadingContext};
    let lamps: Vec<Quad> = (0..9)
        .map(|i| {
            let (x, z) = (f64::from(i % 3) * 3.0 - 3.0, f64::from(i / 3) * 3.0 - 3.0);
            let size = 0.5 + 0.25 * f64::from(i % 4);
            Quad::new(
                DVec3::new(x, 3.0 + 0.5 * f64::from(i % 2), z),
                DVec3::X * size,
                DVec3::Z * size,
            )
            .unwrap()
        })
        .collect();
    let powers: Vec<f64> = (0..lamps.len()).map(|i| 1.0 + (i * 7 % 5) as f64).collect();
    let tree = LightTree::new(
        lamps.clone(),
        &powers,
        &vec![Emission::OneSide(DVec3::NEG_Y); lamps.len()],
    )
    .unwrap();
    let mixture = Mixture::new(lamps.clone(), &powers).unwrap();
    const N: usize = 60_000;
    let mut rng = support::SplitMix::new(5002);
    for point in [
        DVec3::new(0.3, 0.0, -0.2),
        DVec3::new(-4.0, 0.0, 3.5),
        DVec3::new(2.0, 1.0, 2.0),
    ] {
        let at = ShadingContext::on_surface(point, DVec3::Y);
        let mut counts = [vec![0usize; lamps.len()], vec![0usize; lamps.len()]];
        // The least and greatest of what is left of `u`, per light: all of [0, 1).
        let mut rests = [
            vec![(1.0f64, 0.0f64); lamps.len()],
            vec![(1.0f64, 0.0f64); lamps.len()],
        ];
        let (mut by_pick, mut by_density) = (Vec::new(), Vec::new());
        for k in 0..N {
            let u = (k as f64 + rng.next_f64()) / N as f64;
            let v = rng.next_f64();
            for (which, pick) in [tree.pick(&at, u), mixture.pick(u)].into_iter().enumerate() {
                let pick = pick.expect("every lamp faces the point");
                assert!((0.0..1.0).contains(&pick.rest), "{pick:?}");
                let expected = if which == 0 {
                    tree.probability(&at, pick.light)
                } else {
                    mixture.probability(pick.light)
                };
                assert_eq!(pick.probability, expected);
                counts[which][pick.light] += 1;
                let (low, high) = &mut rests[which][pick.light];
                (*low, *high) = (low.min(pick.rest), high.max(pick.rest));
            }
            // Irradiance at the point: by the tree's pick and the lamp's own density, and
            // by the tree's full density.
            let pick = tree.pick(&at, u).unwrap();
            by_pick.push(
                lamps[pick.light]
                    .sample_light(&at, DVec2::new(pick.rest, v))
                    .map_or(0.0, |s| s.direction.y / (pick.probability * s.pdf)),
            );
            by_density.push(
                tree.sample_light(&at, DVec2::new(rng.next_f64(), rng.next_f64()))
                    .map_or(0.0, |s| s.direction.y / s.pdf),
            );
        }
        for (which, counts) in counts.iter().enumerate() {
            for (i, &count) in counts.iter().enumerate() {
                let p = if which == 0 {
                    tree.probability(&at, i)
                } else {
                    mixture.probability(i)
                };
                let sigma = (N as f64 * p * (1.0 - p)).sqrt();
                assert!(
                    (count as f64 - N as f64 * p).abs() <= 5.0 * sigma + 1.0,
                    "{which} {i}: {count} for {p}"
                );
            }
        }
        for (which, rests) in rests.iter().enumerate() {
            for (i, &(low, high)) in rests.iter().enumerate() {
                assert!(
                    low < 0.01 && high > 0.99,
                    "{which} {i}: rest from {low} to {high}"
                );
            }
        }
        support::assert_same_mean(
            support::mean_and_error(&by_pick),
            support::mean_and_error(&by_density),
            "irradiance",
        );
    }
}
