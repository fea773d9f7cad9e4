//! Part 2: image error against render time for the Cornell box, its light sampled by area
//! and by solid angle, against a reference rendered with many more samples (and a different
//! seed, so that its samples are independent of the images it judges).

use std::time::Instant;

use hitkit::Sampling;
use hitkit_render::render::{Rendered, Settings, luminance, render};
use hitkit_render::scenes::cornell_scene;

/// Sample counts of the images judged.
pub const SAMPLE_COUNTS: [usize; 5] = [1, 4, 16, 64, 256];
/// Bounces per path at most (Russian roulette ends most paths long before).
pub const MAX_DEPTH: usize = 50;
const SEED: u64 = 1;
/// The reference's seed: independent of the images' samples.
const REFERENCE_SEED: u64 = 2;
/// The reference gets as many samples (a multiple of 1024, within these bounds) as fit in
/// about this many seconds, judged from the time of the largest image.
const REFERENCE_SECONDS: f64 = 20.0;
const REFERENCE_SAMPLES: (usize, usize) = (1024, 16384);

/// One sample count: for area and for solid-angle sampling of the light, the seconds the
/// image took and the RMS over pixels of its luminance difference to the reference.
pub struct ErrorRow {
    pub samples: usize,
    pub area: (f64, f64),
    pub solid_angle: (f64, f64),
}

/// What part 2 measured.
pub struct ErrorReport {
    pub width: usize,
    pub rows: Vec<ErrorRow>,
    pub reference_samples: usize,
    pub reference_seconds: f64,
    /// RMS over pixels of the reference's own standard error (from its per-pixel variance).
    pub reference_noise: f64,
    pub reference_mean: f64,
}

/// Renders the Cornell box at `width` with `samples` per pixel on every core; the image
/// and the seconds it took.
fn timed_render(
    width: usize,
    samples: usize,
    seed: u64,
    sampling: Sampling,
) -> Result<(Rendered, f64), String> {
    let scene = cornell_scene(width, sampling);
    let settings = Settings {
        samples,
        max_depth: MAX_DEPTH,
        roulette: true,
        seed,
        threads: 0,
        progress: false,
    };
    let start = Instant::now();
    let image = render(&scene, &settings, scene.effects())?;
    Ok((image, start.elapsed().as_secs_f64()))
}

/// RMS over pixels of the difference in linear luminance.
fn rms_luminance_error(image: &Rendered, reference: &Rendered) -> f64 {
    let n = image.pixels.len().max(1) as f64;
    let sum: f64 = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| (luminance(*a) - luminance(*b)).powi(2))
        .sum();
    (sum / n).sqrt()
}

/// The most samples, a multiple of 1024 within [`REFERENCE_SAMPLES`] (and at most `cap`),
/// whose render should take at most [`REFERENCE_SECONDS`], given that `samples` took
/// `seconds`.
fn reference_samples(samples: usize, seconds: f64, cap: usize) -> usize {
    let per_sample = seconds / samples.max(1) as f64;
    let fits = (REFERENCE_SECONDS / per_sample.max(1e-12)).min(1e9) as usize / 1024 * 1024;
    fits.clamp(REFERENCE_SAMPLES.0, REFERENCE_SAMPLES.1)
        .min(cap)
}

/// Renders the images and the reference, and compares them. `quick` uses a smaller image
/// and reference (a smoke test).
pub fn measure(width: usize, quick: bool) -> Result<ErrorReport, String> {
    let mut images = Vec::new();
    for samples in SAMPLE_COUNTS {
        let area = timed_render(width, samples, SEED, Sampling::Area)?;
        let solid_angle = timed_render(width, samples, SEED, Sampling::SolidAngle)?;
        images.push((samples, area, solid_angle));
    }
    let (last_samples, last_seconds) = images
        .last()
        .map_or((1, 1.0), |(samples, (_, seconds), _)| (*samples, *seconds));
    let cap = if quick { 512 } else { usize::MAX };
    let reference_samples = reference_samples(last_samples, last_seconds, cap);
    let (reference, reference_seconds) =
        timed_render(width, reference_samples, REFERENCE_SEED, Sampling::Area)?;
    let n = reference.pixels.len().max(1) as f64;
    let reference_noise = (reference.variance.iter().sum::<f64>() / n).sqrt();
    let reference_mean = reference.mean_luminance().0;
    let judge =
        |(image, seconds): (Rendered, f64)| (seconds, rms_luminance_error(&image, &reference));
    let rows = images
        .into_iter()
        .map(|(samples, area, solid_angle)| ErrorRow {
            samples,
            area: judge(area),
            solid_angle: judge(solid_angle),
        })
        .collect();
    Ok(ErrorReport {
        width,
        rows,
        reference_samples,
        reference_seconds,
        reference_noise,
        reference_mean,
    })
}
