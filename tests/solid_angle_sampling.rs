//! Rectangles sampled by the solid angle they subtend (Ureña et al. 2013): the density
//! integrates to 1, samples hit the light, the sampler follows its density, and near a
//! light it estimates irradiance with lower variance than area sampling, to the same mean.

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Hittable, Interval, PdfHittable, Quad, Ray, Triangle};
use support::SplitMix;

/// A unit square light at the origin in the plane z = 0, facing +z.
fn square() -> Quad {
    Quad::new(DVec3::new(-0.5, -0.5, 0.0), DVec3::X, DVec3::Y).unwrap()
}

/// The same square as two triangles: a uniform mixture of two half-squares, each sampled
/// over its area, is area sampling of the square (each point drawn with density
/// `1 / area`), which rectangles themselves no longer use near the light.
fn square_by_area() -> Vec<Quad<Triangle>> {
    vec![
        Quad::with_interior(DVec3::new(-0.5, -0.5, 0.0), DVec3::X, DVec3::Y, Triangle).unwrap(),
        Quad::with_interior(DVec3::new(0.5, 0.5, 0.0), -DVec3::X, -DVec3::Y, Triangle).unwrap(),
    ]
}

/// Mean and standard error of `n` draws.
fn stats(n: usize, mut draw: impl FnMut() -> f64) -> (f64, f64) {
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let x = draw();
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / n as f64;
    (
        mean,
        ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

#[test]
fn the_density_integrates_to_one_and_samples_hit_the_light() {
    let light = square();
    let mut rng = SplitMix::new(1);
    for origin in [
        DVec3::new(0.0, 0.0, 0.3),
        DVec3::new(0.4, -0.2, 0.8),
        DVec3::new(1.5, 0.0, 0.5),
        DVec3::new(0.0, 0.3, -0.4),
    ] {
        let (mean, se) = stats(300_000, || {
            4.0 * std::f64::consts::PI * light.pdf_value(origin, rng.direction())
        });
        assert!(
            (mean - 1.0).abs() <= 5.0 * se && se < 0.03,
            "from {origin}: {mean} +- {se}"
        );
        for _ in 0..2000 {
            let d = light.sample_direction(origin, DVec2::new(rng.next_f64(), rng.next_f64()));
            let pdf = light.pdf_value(origin, d);
            assert!(
                pdf > 0.0 && pdf.is_finite(),
                "from {origin}: {d} has density {pdf}"
            );
            assert!(
                light
                    .hit(&Ray::new(origin, d), Interval::new(0.0, f64::INFINITY))
                    .is_some()
            );
        }
    }
}

/// The irradiance `E = integral of cos` over the light, estimated by solid-angle samples
/// (`cos / pdf`) and by area samples: the same mean within 5 standard errors, and, near the
/// light, a smaller variance per sample for solid-angle sampling. Also, against uniform
/// directions over the sphere, a check that the sampler draws what its density says.
#[test]
fn solid_angle_sampling_agrees_with_area_sampling_with_less_variance_near_the_light() {
    let (light, by_area) = (square(), square_by_area());
    let mut rng = SplitMix::new(2);
    for height in [0.01, 0.1, 1.0, 10.0] {
        let origin = DVec3::new(0.1, -0.2, height);
        let estimate = |light: &dyn PdfHittable, rng: &mut SplitMix| {
            let d = light.sample_direction(origin, DVec2::new(rng.next_f64(), rng.next_f64()));
            let pdf = light.pdf_value(origin, d);
            if pdf > 0.0 {
                -d.normalize().z / pdf
            } else {
                0.0
            }
        };
        let n = 100_000;
        let (spherical, se_s) = stats(n, || estimate(&light, &mut rng));
        let (area, se_a) = stats(n, || estimate(&by_area, &mut rng));
        assert!(
            (spherical - area).abs() <= 5.0 * (se_s * se_s + se_a * se_a).sqrt(),
            "height {height}: {spherical} +- {se_s} vs {area} +- {se_a}"
        );
        if height <= 0.1 {
            assert!(
                se_s < 0.5 * se_a,
                "height {height}: solid angle {se_s} vs area {se_a}"
            );
        }
        // Uniform directions, counting those that reach the light: the same integral.
        if height <= 1.0 {
            let (uniform, se_u) = stats(400_000, || {
                let d = rng.direction();
                let hits = light
                    .hit(&Ray::new(origin, d), Interval::new(0.0, f64::INFINITY))
                    .is_some();
                if hits {
                    -d.z * 4.0 * std::f64::consts::PI
                } else {
                    0.0
                }
            });
            assert!(
                (spherical - uniform).abs() <= 5.0 * (se_s * se_s + se_u * se_u).sqrt(),
                "height {height}: {spherical} vs uniform {uniform} +- {se_u}"
            );
        }
    }
}
