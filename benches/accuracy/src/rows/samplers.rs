//! Light sampling: area sampling against solid-angle sampling of a unit square light and
//! of half of it (a triangle), seen from several heights above a point near its centre. For each, the variance per sample of the irradiance estimate (`cos / pdf`) and
//! the time per sample (direction and density).

use std::hint::black_box;
use std::time::Instant;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{PdfHittable, Quad, Sampling, Triangle};

/// One row: shape, height, then (variance per sample, ns per sample) for area and solid
/// angle.
pub struct SamplerRow {
    pub shape: &'static str,
    pub height: f64,
    pub area: (f64, f64),
    pub solid_angle: (f64, f64),
}

type Light = Box<dyn PdfHittable>;

/// The square light's corner `q`; its edges are the unit vectors x and y.
const CORNER: DVec3 = DVec3::new(-0.5, -0.5, 0.0);
/// The point under the shading points, in the light's plane.
const BELOW: (f64, f64) = (0.1, -0.2);
/// Heights of the shading points above the light's plane.
const HEIGHTS: [f64; 4] = [0.01, 0.1, 1.0, 10.0];
/// Timed runs per measurement; the median is shown.
const RUNS: usize = 5;

/// What the table measures, from the constants above, for the printed text.
pub fn describe() -> String {
    let far = CORNER + DVec3::X + DVec3::Y;
    format!(
        "A unit square light (corners ({}, {}, {}) and ({}, {}, {})) and its lower-left half, \
         a triangle, seen from a point ({}, {}) at heights {} above it; the irradiance estimate cos / \
         pdf, its variance per sample and the time per sample (direction and density; median \
         of {RUNS} runs), with `Sampling::Area` and with the default `Sampling::SolidAngle`.",
        CORNER.x,
        CORNER.y,
        CORNER.z,
        far.x,
        far.y,
        far.z,
        BELOW.0,
        BELOW.1,
        HEIGHTS.map(|h| h.to_string()).join(", "),
    )
}

/// The unit square and its lower-left half, each as sampled by default (by solid angle
/// where hitkit does so) and by area.
fn lights() -> [(&'static str, Light, Light); 2] {
    let q = CORNER;
    let square = Quad::new(q, DVec3::X, DVec3::Y).expect("a unit square");
    let triangle = Quad::with_interior(q, DVec3::X, DVec3::Y, Triangle).expect("a half square");
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

/// Variance per sample and median ns per sample (of `RUNS` timed runs) of `n` estimates.
fn measure(light: &dyn PdfHittable, origin: DVec3, n: usize) -> (f64, f64) {
    let mut rng = hitkit_render::workloads::SplitMix::new(0x5eed);
    let mut next = move || rng.next_f64();
    let mut estimate = || {
        let d = light.sample_direction(origin, DVec2::new(next(), next()));
        let pdf = light.pdf_value(origin, d);
        if pdf > 0.0 {
            -d.normalize().z / pdf
        } else {
            0.0
        }
    };
    let mut times = Vec::new();
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..RUNS {
        let start = Instant::now();
        for _ in 0..n {
            let x = black_box(estimate());
            sum += x;
            sum2 += x * x;
        }
        times.push(start.elapsed().as_secs_f64() * 1e9 / n as f64);
    }
    times.sort_by(f64::total_cmp);
    let count = (RUNS * n) as f64;
    let mean = sum / count;
    ((sum2 / count - mean * mean).max(0.0), times[RUNS / 2])
}

pub fn measure_all(quick: bool) -> Vec<SamplerRow> {
    let n = if quick { 2_000 } else { 200_000 };
    let mut rows = Vec::new();
    for (shape, solid_angle, area) in lights() {
        for height in HEIGHTS {
            let origin = DVec3::new(BELOW.0, BELOW.1, height);
            rows.push(SamplerRow {
                shape,
                height,
                area: measure(area.as_ref(), origin, n),
                solid_angle: measure(solid_angle.as_ref(), origin, n),
            });
        }
    }
    rows
}
