//! The integrator and the parallel loop over pixels.

use std::f64::consts::PI;
use std::io::IsTerminal;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{HitRecord, Hittable, Interval, PdfHittable, Ray, ShadingContext};
use indicatif::{ProgressBar, ProgressStyle};
use rand::rngs::SmallRng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

use crate::camera::Camera;
use crate::material::{Scatter, cosine_direction};
use crate::{Color, Effects, Scene};

/// How to render, as opposed to what.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub samples: usize,
    pub max_depth: usize,
    /// End paths by Russian roulette after `ROULETTE_FROM` bounces (unbiased, and fewer
    /// bounces per path); without it every path runs until it escapes, is absorbed or
    /// reaches `max_depth`, as in the book's renderer.
    pub roulette: bool,
    pub seed: u64,
    /// Worker threads; 0 for one per core.
    pub threads: usize,
    /// Show a progress bar (on stderr) when stdout is a terminal.
    pub progress: bool,
}

/// A rendered image in linear RGB, with what a test needs to judge it.
pub struct Rendered {
    pub width: usize,
    pub height: usize,
    /// Mean radiance of each pixel, row by row from the top.
    pub pixels: Vec<Color>,
    /// Estimated variance of each pixel's mean luminance (sample variance / samples).
    pub variance: Vec<f64>,
}

impl Rendered {
    /// The mean luminance of the image and the standard error of that mean (pixels are
    /// independent: the variances of their means add).
    pub fn mean_luminance(&self) -> (f64, f64) {
        let n = self.pixels.len() as f64;
        let mean = self.pixels.iter().map(|c| luminance(*c)).sum::<f64>() / n;
        let variance = self.variance.iter().sum::<f64>() / (n * n);
        (mean, variance.sqrt())
    }
}

/// Bounces after which Russian roulette may end a path: it continues with probability
/// `p` (the throughput's largest channel, at most 0.95) and is divided by `p` when it does,
/// so the estimate stays unbiased.
const ROULETTE_FROM: usize = 3;

/// Renders `scene` with exactly the effects `effects` (normally `scene.effects()`): the
/// choice picks one monomorphized integrator for the whole image, so nothing is decided
/// per ray.
pub fn render<W: Hittable>(
    scene: &Scene<W>,
    settings: &Settings,
    effects: Effects,
) -> Result<Rendered, String> {
    // Four switches, sixteen integrators: each knows at compile time what it skips.
    macro_rules! dispatch {
        ($($bg:literal $em:literal $ls:literal $lens:literal),*) => {
            match (effects.background, effects.emission, effects.light_sampling, effects.defocus) {
                $(($bg, $em, $ls, $lens) => render_with::<W, $bg, $em, $ls, $lens>(scene, settings),)*
            }
        };
    }
    dispatch!(
        false false false false, false false false true, false false true false, false false true true,
        false true false false, false true false true, false true true false, false true true true,
        true false false false, true false false true, true false true false, true false true true,
        true true false false, true true false true, true true true false, true true true true
    )
}

fn render_with<
    W: Hittable,
    const BG: bool,
    const EMIT: bool,
    const LIGHTS: bool,
    const LENS: bool,
>(
    scene: &Scene<W>,
    settings: &Settings,
) -> Result<Rendered, String> {
    let (width, height) = (scene.camera.width, scene.camera.height);
    let camera = Camera::new(&scene.camera);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(settings.threads)
        .build()
        .map_err(|e| format!("cannot start {} threads: {e}", settings.threads))?;
    let bar = if settings.progress && std::io::stdout().is_terminal() {
        let bar = ProgressBar::new(height as u64);
        if let Ok(style) = ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} rows, {eta} left",
        ) {
            bar.set_style(style);
        }
        bar
    } else {
        ProgressBar::hidden()
    };

    let rows: Vec<Vec<(Color, f64)>> = pool.install(|| {
        (0..height)
            .into_par_iter()
            .map(|j| {
                let row = (0..width)
                    .map(|i| pixel::<W, EMIT, BG, LIGHTS, LENS>(scene, &camera, settings, i, j))
                    .collect();
                bar.inc(1);
                row
            })
            .collect()
    });
    bar.finish_and_clear();
    let (pixels, variance) = rows.into_iter().flatten().unzip();
    Ok(Rendered {
        width,
        height,
        pixels,
        variance,
    })
}

/// Every sample of pixel (i, j), from a generator seeded by the seed and the pixel alone,
/// so that the image does not depend on how pixels are spread over threads.
fn pixel<W: Hittable, const EMIT: bool, const BG: bool, const LIGHTS: bool, const LENS: bool>(
    scene: &Scene<W>,
    camera: &Camera,
    settings: &Settings,
    i: usize,
    j: usize,
) -> (Color, f64) {
    let index = (j * scene.camera.width + i) as u64;
    let mut rng =
        SmallRng::seed_from_u64(settings.seed ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let (mut sum, mut sum_l, mut sum_l2) = (Color::ZERO, 0.0, 0.0);
    for _ in 0..settings.samples {
        let ray = camera.ray::<LENS>(i, j, &mut rng);
        let c = radiance::<W, BG, EMIT, LIGHTS>(scene, ray, settings, &mut rng);
        let l = luminance(c);
        sum += c;
        sum_l += l;
        sum_l2 += l * l;
    }
    let n = settings.samples as f64;
    let variance = if settings.samples > 1 {
        (sum_l2 - sum_l * sum_l / n).max(0.0) / (n - 1.0) / n
    } else {
        0.0
    };
    (sum / n, variance)
}

/// The radiance arriving along `ray`: a path traced iteratively.
#[inline]
fn radiance<W: Hittable, const BG: bool, const EMIT: bool, const LIGHTS: bool>(
    scene: &Scene<W>,
    mut ray: Ray,
    settings: &Settings,
    rng: &mut SmallRng,
) -> Color {
    let mut color = Color::ZERO;
    let mut throughput = Color::ONE;
    // With next-event estimation: where the last bounce was drawn from a diffuse
    // material, the context it left and that direction's density, to weigh the emission
    // it finds against the lights' sampler (multiple importance sampling).
    let mut drawn: Option<(ShadingContext, f64)> = None;
    for depth in 0..settings.max_depth {
        // Borrowed, not moved out of the option: moving it copies the record (152 bytes)
        // through memcpy on every bounce, about 4% of the quads scene's time.
        let found = scene.world.hit(&ray, Interval::FORWARD);
        let Some(hit) = found.as_ref() else {
            if BG {
                color += throughput * scene.background.color(ray.direction);
            }
            break;
        };
        let material = &scene.materials[hit.material.0 as usize];
        if EMIT {
            let emitted = material.emitted(hit);
            let weight = match (&drawn, &scene.lights) {
                (Some((at, pdf)), Some(lights)) if emitted != Color::ZERO => {
                    power_heuristic(*pdf, lights.light_pdf(at, ray.direction))
                }
                _ => 1.0,
            };
            color += throughput * emitted * weight;
        }
        drawn = None;
        let direction = match material.scatter(ray.direction, hit, rng) {
            Scatter::None => break,
            Scatter::Specular(direction, attenuation) => {
                throughput *= attenuation;
                direction
            }
            // (With every effect forced on, a scene may have no lights to sample.)
            Scatter::Diffuse(albedo) if LIGHTS && scene.next_event && scene.lights.is_some() => {
                let lights = scene.lights.as_deref().expect("the guard checked");
                let at = ShadingContext::from(hit);
                let u = DVec2::new(rng.random(), rng.random());
                color += throughput * albedo * next_event(scene, lights, hit, &at, u);
                // And a cosine-weighted bounce, whose emission `drawn` weighs.
                let direction = cosine_direction(hit.normal, rng);
                drawn = Some((at, direction.dot(hit.normal).max(0.0) / PI));
                throughput *= albedo;
                direction
            }
            Scatter::Diffuse(albedo) if LIGHTS && scene.lights.is_some() => {
                // Half the samples toward a light, half cosine-weighted; the weight is the
                // Lambertian density over the mixture's.
                let lights = scene.lights.as_deref().expect("the guard checked");
                let direction = if rng.random::<f64>() < 0.5 {
                    let u = DVec2::new(rng.random(), rng.random());
                    lights.sample_direction(hit.point, u)
                } else {
                    cosine_direction(hit.normal, rng)
                };
                let cos = direction.normalize().dot(hit.normal);
                if cos.is_nan() || cos <= 0.0 {
                    break; // below the surface: the Lambertian density there is 0
                }
                let light_pdf = lights.pdf_value(hit.point, direction);
                let mixture = 0.5 * cos / PI + 0.5 * light_pdf;
                throughput *= albedo * (cos / PI / mixture);
                direction
            }
            Scatter::Diffuse(albedo) => {
                throughput *= albedo;
                // Around the shading normal (a mesh's interpolated one); where that tilts
                // the lobe below the surface, the direction is mirrored back above it.
                let d = cosine_direction(hit.shading_normal, rng);
                let below = d.dot(hit.normal);
                if below < 0.0 {
                    d - 2.0 * below * hit.normal
                } else {
                    d
                }
            }
        };
        // The camera's mask is for the camera's rays: a bounce sees everything (a lamp the
        // camera does not see still lights what a bounce finds).
        ray = hit.spawn_ray(direction).with_mask(u32::MAX);
        if settings.roulette && depth >= ROULETTE_FROM {
            let p = throughput.max_element().min(0.95);
            if p.is_nan() || rng.random::<f64>() >= p {
                break;
            }
            throughput /= p;
        }
    }
    color
}

/// The light a Lambertian surface of albedo 1 at `hit` receives from one point sampled
/// on `lights`, visible through a shadow ray, weighed against the cosine-weighted bounce
/// that could have found the same point (the power heuristic).
#[inline]
fn next_event<W: Hittable>(
    scene: &Scene<W>,
    lights: &dyn PdfHittable,
    hit: &HitRecord,
    at: &ShadingContext,
    u: DVec2,
) -> Color {
    let Some(sample) = lights.sample_light(at, u) else {
        return Color::ZERO;
    };
    let cos = sample.direction.dot(hit.normal);
    let emitted = scene.materials[sample.record.material.0 as usize].emitted(&sample.record);
    if cos <= 0.0 || emitted == Color::ZERO {
        return Color::ZERO;
    }
    let (shadow, range) = hit.spawn_ray_to(&sample.record);
    if scene.world.occluded(&shadow.with_mask(u32::MAX), range) {
        return Color::ZERO;
    }
    // A point, spot or sun: no bounce finds it, so its sample has all the weight.
    let weight = if sample.delta {
        1.0
    } else {
        power_heuristic(sample.pdf, cos / PI)
    };
    emitted * (cos / PI * weight / sample.pdf)
}

/// The weight of a sample drawn with density `f` against another strategy's density `g`
/// for the same point (Veach's power heuristic, exponent 2).
#[inline]
fn power_heuristic(f: f64, g: f64) -> f64 {
    let (f2, g2) = (f * f, g * g);
    if f2 + g2 > 0.0 { f2 / (f2 + g2) } else { 0.0 }
}

/// Rec. 709 luminance.
#[inline]
pub fn luminance(c: Color) -> f64 {
    c.dot(DVec3::new(0.2126, 0.7152, 0.0722))
}
