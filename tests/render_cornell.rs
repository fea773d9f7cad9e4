//! Light sampling must not bias the estimate: the Cornell box rendered with it and without
//! it, and with its light sampled by area and by solid angle, converges to the same mean
//! brightness; near the light, solid-angle sampling estimates the direct light with far
//! less variance per sample. Russian roulette does not bias it either, on the book's own
//! final scene (glass sphere and lamp both sampled as lights).

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{HitRecord, Hittable, Ray, Sampling, ShadingContext};
use hitkit_render::Effects;
use hitkit_render::render::{Settings, render};
use hitkit_render::scenes::{cornell_book_scene, cornell_scene};
use rand::rngs::SmallRng;
use rand::{RngExt, SeedableRng};
use support::assert_same_mean;

const SETTINGS: Settings = Settings {
    samples: 256,
    max_depth: 50,
    roulette: true,
    seed: 0,
    threads: 0,
    progress: false,
};

#[test]
fn light_sampling_and_cosine_sampling_agree_on_the_mean_brightness() {
    let scene = cornell_scene(24, Sampling::Area);
    let sampled = scene.effects();
    assert!(sampled.light_sampling && sampled.emission && !sampled.background);
    let unsampled = Effects {
        light_sampling: false,
        ..sampled
    };
    let settings = |seed| Settings { seed, ..SETTINGS };
    let a = render(&scene, &settings(1), sampled)
        .unwrap()
        .mean_luminance();
    let b = render(&scene, &settings(2), unsampled)
        .unwrap()
        .mean_luminance();
    assert_same_mean(a, b, "with light sampling, without");
    // And light sampling is what makes this scene converge: it cuts the error.
    assert!(
        a.1 < b.1,
        "light sampling {} vs cosine sampling {}",
        a.1,
        b.1
    );
}

#[test]
fn area_and_solid_angle_sampling_agree_on_the_mean_brightness() {
    let image = |sampling, seed| {
        let scene = cornell_scene(24, sampling);
        let settings = Settings { seed, ..SETTINGS };
        render(&scene, &settings, scene.effects())
            .unwrap()
            .mean_luminance()
    };
    assert_same_mean(
        image(Sampling::Area, 3),
        image(Sampling::SolidAngle, 4),
        "area, solid angle",
    );
}

/// The direct light at points on the back and left walls just below the ceiling, 200 to 350
/// units from the lamp and 5 to 55 below its plane, so that they see it at a slant: there
/// area sampling's density `distance^2 / (cos area)` varies several-fold across the lamp,
/// and solid-angle sampling's does not. Both estimate the same mean (5 standard errors), and
/// solid angle with a tenth of the variance per sample or less (measured: about a
/// thousandth).
#[test]
fn solid_angle_sampling_has_less_variance_near_the_light() {
    let n = 20_000;
    let mut rng = SmallRng::seed_from_u64(5);
    for (point, normal) in [
        (DVec3::new(278.0, 550.0, 554.999), -DVec3::Z),
        (DVec3::new(278.0, 500.0, 554.999), -DVec3::Z),
        (DVec3::new(0.001, 550.0, 280.0), DVec3::X),
        (DVec3::new(0.001, 500.0, 280.0), DVec3::X),
    ] {
        let mut direct = |sampling| {
            let scene = cornell_scene(8, sampling);
            let lamp = scene
                .lights
                .as_deref()
                .expect("the Cornell box lists its lamp");
            // A surface at `point` facing `normal`, as a hit on it reports it.
            let surface = HitRecord::new(&Ray::new(point, -normal), 0.0, point, normal);
            let at = ShadingContext::from(&surface);
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..n {
                let u = DVec2::new(rng.random(), rng.random());
                // The lamp emits downward (radiance 15); the boxes may shadow it.
                let x = match lamp.sample_light(&at, u) {
                    Some(sample) if sample.direction.y > 0.0 => {
                        let (shadow, range) = surface.spawn_ray_to(&sample.record);
                        if scene.world.occluded(&shadow, range) {
                            0.0
                        } else {
                            15.0 * sample.direction.dot(normal) / sample.pdf
                        }
                    }
                    _ => 0.0,
                };
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / f64::from(n);
            let variance = sum2 / f64::from(n) - mean * mean;
            (mean, variance, (variance / f64::from(n)).sqrt())
        };
        let (area, var_a, se_a) = direct(Sampling::Area);
        let (solid, var_s, se_s) = direct(Sampling::SolidAngle);
        assert!(
            (area - solid).abs() <= 5.0 * (se_a * se_a + se_s * se_s).sqrt(),
            "at {point}: area {area} +- {se_a}, solid angle {solid} +- {se_s}"
        );
        assert!(area > 0.0, "at {point}: the lamp is in view");
        assert!(
            var_s < 0.1 * var_a,
            "at {point}: variance {var_s} by solid angle, {var_a} by area"
        );
    }
}

#[test]
fn russian_roulette_keeps_the_mean_of_the_books_final_scene() {
    let scene = cornell_book_scene(24);
    let effects = scene.effects();
    assert!(effects.light_sampling && effects.emission && scene.lights.is_some());
    let with = |roulette, seed| {
        let settings = Settings {
            roulette,
            seed,
            ..SETTINGS
        };
        render(&scene, &settings, effects).unwrap().mean_luminance()
    };
    assert_same_mean(with(true, 5), with(false, 6), "with roulette, without");
}
