//! Rectangles and triangles sampled by the solid angle they subtend (Ureña et al. 2013,
//! Arvo 1995): the density integrates to 1, samples hit the light, and near a light it
//! estimates irradiance with lower variance than area sampling, to the same mean.

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Hittable, Interval, PdfHittable, Quad, Ray, Sampling, Triangle};
use support::{SplitMix, gamma};

type Light = Box<dyn PdfHittable>;

/// A unit square light at the origin in the plane z = 0, facing +z, and its lower-left
/// half, each as sampled by default (by solid angle near them) and by area.
fn lights() -> [(&'static str, Light, Light); 2] {
    let q = DVec3::new(-0.5, -0.5, 0.0);
    let square = Quad::new(q, DVec3::X, DVec3::Y).unwrap();
    let triangle = Quad::with_interior(q, DVec3::X, DVec3::Y, Triangle).unwrap();
    [
        (
            "square",
            Box::new(square),
            Box::new(square.with_sampling(Sampling::Area)),
        ),
        (
            "triangle",
            Box::new(triangle),
            Box::new(triangle.with_sampling(Sampling::Area)),
        ),
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

/// The triangle with corners on the three axes subtends one octant from the origin, and the
/// square of side 2 centred 1 above it a sixth of the sphere (a cube face): densities
/// `2 / pi` and `3 / (2 pi)`. Tolerance: the corners are exact; unit vectors, dot and cross
/// products of them leave absolute errors of at most about `gamma(10)` in the numerator and
/// denominator of Van Oosterom and Strackee's `atan2` (both O(1), their hypotenuse at least
/// 1 here), which moves each triangle's angle by at most twice that, plus an ulp of `atan2`;
/// two triangles for the square: within `gamma(32)` relative to angles near `pi / 2`.
#[test]
fn the_density_is_one_over_the_exact_solid_angle() {
    use std::f64::consts::PI;
    let octant = Quad::with_interior(DVec3::X, DVec3::Y - DVec3::X, DVec3::Z - DVec3::X, Triangle);
    let face = Quad::new(DVec3::new(-1.0, -1.0, 1.0), 2.0 * DVec3::X, 2.0 * DVec3::Y);
    for (light, toward, expected) in [
        (&octant.unwrap() as &dyn PdfHittable, DVec3::ONE, 2.0 / PI),
        (&face.unwrap(), DVec3::Z, 3.0 / (2.0 * PI)),
    ] {
        let pdf = light.pdf_value(DVec3::ZERO, toward);
        assert!(
            (pdf - expected).abs() <= gamma(32) * expected,
            "{pdf} vs {expected}: {:e} relative",
            (pdf - expected).abs() / expected
        );
    }
}

#[test]
fn the_density_integrates_to_one_and_samples_hit_the_light() {
    let mut rng = SplitMix::new(1);
    for (name, light, _) in lights() {
        for origin in [
            DVec3::new(0.0, 0.0, 0.3),
            DVec3::new(0.4, -0.2, 0.8),
            DVec3::new(-0.3, -0.3, 0.02),
            DVec3::new(1.5, 0.0, 0.5),
            DVec3::new(0.0, 0.3, -0.4),
        ] {
            let (mean, se) = stats(300_000, || {
                4.0 * std::f64::consts::PI * light.pdf_value(origin, rng.direction())
            });
            assert!(
                (mean - 1.0).abs() <= 5.0 * se && se < 0.03,
                "{name} from {origin}: {mean} +- {se}"
            );
            for _ in 0..2000 {
                let u = DVec2::new(rng.next_f64(), rng.next_f64());
                let d = light.sample_direction(origin, u);
                let pdf = light.pdf_value(origin, d);
                assert!(
                    pdf > 0.0 && pdf.is_finite(),
                    "{name} from {origin}: {d} has density {pdf}"
                );
                assert!(
                    light.hit(&Ray::new(origin, d), Interval::FORWARD).is_some(),
                    "{name} from {origin}: {d} misses"
                );
            }
        }
    }
}

/// The irradiance `E = integral of cos` over the light, estimated by solid-angle samples
/// (`cos / pdf`) and by area samples: the same mean within 5 standard errors, and, near the
/// light, a smaller variance per sample for solid-angle sampling. Also, against uniform
/// directions over the sphere, a check that the sampler draws what its density says.
#[test]
fn solid_angle_sampling_agrees_with_area_sampling_with_less_variance_near_the_light() {
    let mut rng = SplitMix::new(2);
    for (name, light, by_area) in lights() {
        for height in [0.01, 0.1, 1.0, 10.0] {
            let origin = DVec3::new(0.1, -0.2, height);
            let estimate = |light: &dyn PdfHittable, rng: &mut SplitMix| {
                let u = DVec2::new(rng.next_f64(), rng.next_f64());
                let d = light.sample_direction(origin, u);
                let pdf = light.pdf_value(origin, d);
                if pdf > 0.0 {
                    -d.normalize().z / pdf
                } else {
                    0.0
                }
            };
            let n = 100_000;
            let (spherical, se_s) = stats(n, || estimate(light.as_ref(), &mut rng));
            let (area, se_a) = stats(n, || estimate(by_area.as_ref(), &mut rng));
            assert!(
                (spherical - area).abs() <= 5.0 * (se_s * se_s + se_a * se_a).sqrt(),
                "{name} at height {height}: {spherical} +- {se_s} vs {area} +- {se_a}"
            );
            if height <= 0.1 {
                assert!(
                    se_s < 0.5 * se_a,
                    "{name} at height {height}: solid angle {se_s} vs area {se_a}"
                );
            }
            // Uniform directions, counting those that reach the light: the same integral.
            if height <= 1.0 {
                let (uniform, se_u) = stats(400_000, || {
                    let d = rng.direction();
                    let hits = light.hit(&Ray::new(origin, d), Interval::FORWARD).is_some();
                    if hits {
                        -d.z * 4.0 * std::f64::consts::PI
                    } else {
                        0.0
                    }
                });
                assert!(
                    (spherical - uniform).abs() <= 5.0 * (se_s * se_s + se_u * se_u).sqrt(),
                    "{name} at height {height}: {spherical} vs uniform {uniform} +- {se_u}"
                );
            }
        }
    }
}

/// A user's wrapper of an interior: `polygon` says which solid-angle sampler fits, and a
/// wrapper that forwards it (as `Exact` does) is sampled as the shape it wraps; one that
/// does not is sampled by area.
#[test]
fn the_polygon_a_shape_names_decides_its_sampler() {
    use hitkit::custom::{CrossingRegion, Meets, Polygon};
    use hitkit::{Exact, Interior, Parallelogram, SampleInterior};

    struct Wrapped<S>(S, bool);
    impl<S: Interior> Interior for Wrapped<S> {
        fn contains(&self, alpha: f64, beta: f64) -> bool {
            self.0.contains(alpha, beta)
        }
        fn meets(&self, region: &CrossingRegion) -> Meets {
            self.0.meets(region)
        }
    }
    impl<S: SampleInterior> SampleInterior for Wrapped<S> {
        fn area(&self) -> f64 {
            self.0.area()
        }
        fn sample(&self, u: DVec2) -> DVec2 {
            self.0.sample(u)
        }
        fn polygon(&self) -> Option<Polygon> {
            if self.1 { self.0.polygon() } else { None }
        }
    }

    assert_eq!(Parallelogram.polygon(), Some(Polygon::Parallelogram));
    assert_eq!(Triangle.polygon(), Some(Polygon::Triangle));
    assert_eq!(Exact(Triangle).polygon(), Some(Polygon::Triangle));
    assert_eq!(hitkit::Disk.polygon(), None);

    let q = DVec3::new(-0.5, -0.5, 0.0);
    let origin = DVec3::new(0.1, -0.2, 0.3);
    let quad = |shape| Quad::with_interior(q, DVec3::X, DVec3::Y, shape).unwrap();
    let by_solid_angle = quad(Wrapped(Triangle, true));
    let by_area = quad(Wrapped(Triangle, false));
    let u = DVec2::new(0.3, 0.6);
    // The same sample as the plain triangle's (solid angle) and as its area sampling.
    let plain = Quad::with_interior(q, DVec3::X, DVec3::Y, Triangle).unwrap();
    let d = by_solid_angle.sample_direction(origin, u);
    assert_eq!(d, plain.sample_direction(origin, u));
    assert_eq!(
        by_solid_angle.pdf_value(origin, d),
        plain.pdf_value(origin, d)
    );
    let area = plain.with_sampling(Sampling::Area);
    let d = by_area.sample_direction(origin, u);
    assert_eq!(d, area.sample_direction(origin, u));
    assert_eq!(by_area.pdf_value(origin, d), area.pdf_value(origin, d));
    // And the two samplers differ here (the light is near), so the test tells them apart.
    assert_ne!(
        by_solid_angle.sample_direction(origin, u),
        by_area.sample_direction(origin, u)
    );
}
