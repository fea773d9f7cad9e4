//! A list of lights as one light: a uniform mixture whose density integrates to 1, whose
//! samples hit one of the lights, and whose density is the mean of theirs.

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Bvh, Disk, Hittable, Interval, PdfHittable, Quad, Ray, Sphere, Triangle};
use support::SplitMix;

fn lights() -> Vec<Box<dyn PdfHittable>> {
    vec![
        Box::new(Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X, DVec3::Z).unwrap()),
        Box::new(
            Quad::with_interior(
                DVec3::new(1.5, 1.0, 0.0),
                DVec3::Y * 0.5,
                DVec3::Z * 0.5,
                Disk,
            )
            .unwrap(),
        ),
        Box::new(
            Quad::with_interior(DVec3::new(0.0, -2.0, 1.0), DVec3::X, DVec3::Z, Triangle).unwrap(),
        ),
        Box::new(Sphere::new(DVec3::new(-2.0, 0.0, 0.0), 0.5).unwrap()),
    ]
}

/// Monte Carlo over uniform directions: the mean of 4 pi pdf is 1 within 5 standard
/// errors (from the sample variance).
#[test]
fn the_mixture_density_integrates_to_one() {
    let lights = lights();
    let mut rng = SplitMix::new(1);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let x = 4.0 * std::f64::consts::PI * lights.pdf_value(DVec3::ZERO, rng.direction());
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
            l.hit(&Ray::new(DVec3::ZERO, d), Interval::new(0.0, f64::INFINITY))
                .is_some()
        });
        picked[index.expect("a sampled direction hits a light")] += 1;
    }
    // Each light is picked about a quarter of the time (4000 draws: sd about 27).
    assert!(
        picked.iter().all(|&k| (850..=1150).contains(&k)),
        "{picked:?}"
    );
    // A BVH of lights is the same mixture; an empty list has density 0.
    let quads: Vec<Quad> = (0..3)
        .map(|i| Quad::new(DVec3::new(f64::from(i), 2.0, 0.0), DVec3::X, DVec3::Z).unwrap())
        .collect();
    let d = DVec3::new(1.5, 2.0, 0.5);
    assert_eq!(
        Bvh::new(quads.clone()).pdf_value(DVec3::ZERO, d),
        quads.pdf_value(DVec3::ZERO, d)
    );
    let none: Vec<Quad> = Vec::new();
    assert_eq!(none.pdf_value(DVec3::ZERO, d), 0.0);
    assert_eq!(
        none.sample_direction(DVec3::ZERO, DVec2::splat(0.5)),
        DVec3::ZERO
    );
}
