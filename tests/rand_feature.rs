//! The `rand` feature: any light sampled with a `rand` generator, through a trait object
//! too, gives the direction `sample_direction` gives for the same two numbers, and its
//! density.
#![cfg(feature = "rand")]

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{PdfHittable, RandomDirection};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

#[test]
fn random_direction_is_sample_direction_of_the_generators_numbers() {
    let lights = support::four_lights();
    let origin = DVec3::new(0.1, 0.2, -0.3);
    let mut rng = SmallRng::seed_from_u64(11);
    let mut twin = rng.clone();
    let mut hits = 0;
    for _ in 0..1000 {
        let (direction, pdf) = lights.random_direction(origin, &mut rng);
        let scale = 1.0 / (1u64 << 53) as f64;
        let u = DVec2::new(
            (twin.next_u64() >> 11) as f64 * scale,
            (twin.next_u64() >> 11) as f64 * scale,
        );
        assert_eq!(direction, lights.sample_direction(origin, u));
        assert_eq!(pdf, lights.pdf_value(origin, direction));
        assert!(pdf.is_finite() && pdf >= 0.0);
        hits += usize::from(pdf > 0.0);
        // A trait object takes the same generator.
        let light: &dyn PdfHittable = lights[0].as_ref();
        let (d, p) = light.random_direction(origin, &mut twin.clone());
        assert_eq!(p, light.pdf_value(origin, d));
    }
    // Every light sees the origin: nearly every sample aims at one.
    assert!(hits > 990, "{hits}");
}

/// The `rand09` feature: the same with a `rand` 0.9 generator, bit for bit as
/// `sample_direction` of its numbers.
#[cfg(feature = "rand09")]
#[test]
fn a_rand_09_generator_samples_the_same_way() {
    use hitkit::RandomDirection09;
    use rand09::{RngCore, SeedableRng};
    let lights = support::four_lights();
    let origin = DVec3::new(0.1, 0.2, -0.3);
    let mut rng = rand09::rngs::SmallRng::seed_from_u64(11);
    let mut twin = rng.clone();
    for _ in 0..1000 {
        let (direction, pdf) = RandomDirection09::random_direction(&lights, origin, &mut rng);
        let scale = 1.0 / (1u64 << 53) as f64;
        let u = DVec2::new(
            (twin.next_u64() >> 11) as f64 * scale,
            (twin.next_u64() >> 11) as f64 * scale,
        );
        assert_eq!(direction, lights.sample_direction(origin, u));
        assert_eq!(pdf, lights.pdf_value(origin, direction));
    }
}

/// `random_light` is `sample_light` of the generator's two numbers, for both versions of
/// `rand`: the same sample, bit for bit.
#[test]
fn random_light_is_sample_light_of_the_generators_numbers() {
    use hitkit::ShadingContext;
    let lights = support::four_lights();
    let at = ShadingContext::on_surface(
        DVec3::new(0.1, 0.2, -0.3),
        DVec3::new(0.0, 1.0, 0.2).normalize(),
    );
    let mut rng = SmallRng::seed_from_u64(12);
    let mut twin = rng.clone();
    let mut sampled = 0;
    for _ in 0..1000 {
        let sample = lights.random_light(&at, &mut rng);
        let scale = 1.0 / (1u64 << 53) as f64;
        let u = DVec2::new(
            (twin.next_u64() >> 11) as f64 * scale,
            (twin.next_u64() >> 11) as f64 * scale,
        );
        assert_eq!(sample, lights.sample_light(&at, u));
        sampled += usize::from(sample.is_some_and(|s| s.pdf > 0.0));
    }
    assert!(sampled > 500, "{sampled}");
    #[cfg(feature = "rand09")]
    {
        use hitkit::RandomDirection09;
        use rand09::{RngCore, SeedableRng};
        let mut rng = rand09::rngs::SmallRng::seed_from_u64(13);
        let mut twin = rng.clone();
        for _ in 0..100 {
            let sample = RandomDirection09::random_light(&lights, &at, &mut rng);
            let scale = 1.0 / (1u64 << 53) as f64;
            let u = DVec2::new(
                (twin.next_u64() >> 11) as f64 * scale,
                (twin.next_u64() >> 11) as f64 * scale,
            );
            assert_eq!(sample, lights.sample_light(&at, u));
        }
    }
}
