//! `--lights`: what picking among many lights costs: hitkit's `LightTree` against a
//! power-weighted `Mixture` of the same lights, per next-event sample (`sample_light`: the
//! pick, the light's own sample, the first light surface along it and the density) and per
//! density query (`light_pdf`), from shading points with normals, as the number of lights
//! grows; and the tree's build time and memory per light.

use hitkit_render::workloads;
use std::hint::black_box;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Emission, LightTree, Mixture, PdfHittable, Quad, ShadingContext};

use super::{Args, IN_USE, median_time, reset_peak};
use std::sync::atomic::Ordering::Relaxed;

/// Light counts of the table's rows.
const COUNTS: [usize; 4] = [10, 1_000, 100_000, 1_000_000];

/// Shading points per row (each with a random normal), and the density queries of the
/// mixture at the largest counts, where each visits every light.
const POINTS: usize = 10_000;
const MIXTURE_QUERIES_AT_MOST: usize = 100_000_000;

/// A sample's direction, or the zero vector where there is none.
fn direction(light: &impl PdfHittable, at: &ShadingContext, u: DVec2) -> DVec3 {
    light
        .sample_light(at, u)
        .map_or(DVec3::ZERO, |s| s.direction)
}

/// `n` small panels, 1 cm to 10 cm across, facing every way, spread through a cube of 100 m,
/// with powers over four decades; the same for every seed.
fn lights(n: usize, seed: u64) -> (Vec<Quad>, Vec<f64>, Vec<Emission>) {
    let mut rng = workloads::SplitMix::new(seed);
    let (mut quads, mut powers, mut emission) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..n {
        let at = 100.0 * rng.vec3();
        let normal = (rng.vec3() - 0.5).normalize_or(DVec3::Y);
        let (u, v) = normal.any_orthonormal_pair();
        let size = 0.01 + 0.09 * rng.vec3().x;
        quads.push(Quad::new(at, size * u, size * v).expect("a valid panel"));
        powers.push(10f64.powf(4.0 * rng.vec3().x));
        emission.push(Emission::OneSide(u.cross(v)));
    }
    (quads, powers, emission)
}

/// One row per count of [`COUNTS`]: build time, bytes per light, and nanoseconds per sample
/// and per density query for the tree (with the shading normal) and the mixture.
pub(super) fn run(args: &Args) -> Vec<String> {
    let mut rows = Vec::new();
    for n in COUNTS {
        eprintln!("{n} lights");
        let (quads, powers, emission) = lights(n, args.seed);
        let mut rng = workloads::SplitMix::new(args.seed.wrapping_add(1));
        let points: Vec<(ShadingContext, DVec2)> = (0..POINTS)
            .map(|_| {
                let p = 100.0 * rng.vec3();
                let normal = (rng.vec3() - 0.5).normalize_or(DVec3::Y);
                let u = rng.vec3();
                (ShadingContext::on_surface(p, normal), DVec2::new(u.x, u.y))
            })
            .collect();
        // The tree's heap, measured by the counting allocator (the lights' own `Vec` too).
        let base = reset_peak();
        let (build, tree) = median_time(
            args.runs,
            || quads.clone(),
            |quads| LightTree::new(quads, &powers, &emission).expect("valid lights"),
        );
        let kept = IN_USE.load(Relaxed).saturating_sub(base);
        let mixture = Mixture::new(quads.clone(), &powers).expect("positive powers");
        let per = |t: std::time::Duration, count: usize| t.as_secs_f64() * 1e9 / count as f64;
        // Samples, then densities of the sampled directions, through the tree.
        let (tree_sample, directions) = median_time(
            args.runs,
            || (),
            |()| {
                points
                    .iter()
                    .map(|(at, u)| direction(&tree, at, *u))
                    .collect::<Vec<_>>()
            },
        );
        let (tree_pdf, densities) = median_time(
            args.runs,
            || (),
            |()| {
                points
                    .iter()
                    .zip(&directions)
                    .map(|((at, _), &d)| tree.light_pdf(at, d))
                    .collect::<Vec<f64>>()
            },
        );
        assert!(
            densities.iter().all(|&pdf| pdf.is_finite() && pdf >= 0.0),
            "densities are numbers"
        );
        // A mixture's sample finds the first light along its direction and its density,
        // each visiting every light: at most this many queries in all.
        let queries = (MIXTURE_QUERIES_AT_MOST / n).clamp(1, POINTS);
        let (mixture_sample, mixture_directions) = median_time(
            args.runs,
            || (),
            |()| {
                points[..queries]
                    .iter()
                    .map(|(at, u)| direction(&mixture, at, *u))
                    .collect::<Vec<_>>()
            },
        );
        let (mixture_pdf, _) = median_time(
            args.runs,
            || (),
            |()| {
                points[..queries]
                    .iter()
                    .zip(&mixture_directions)
                    .map(|((at, _), &d)| black_box(mixture.light_pdf(at, d)))
                    .sum::<f64>()
            },
        );
        rows.push(format!(
            "| {n} | {:.1} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} ({queries} queries) |",
            build.as_secs_f64() * 1e3,
            kept as f64 / n as f64,
            per(tree_sample, POINTS),
            per(tree_pdf, POINTS),
            per(mixture_sample, queries),
            per(mixture_pdf, queries),
        ));
    }
    rows
}

/// Prints the table.
pub(super) fn print(rows: &[String], args: &Args) {
    println!(
        "{}; single-threaded; median of {} runs; {POINTS} shading points with random normals (the mixture's queries at most {MIXTURE_QUERIES_AT_MOST} light visits) in a 100 m cube of small panels facing every way, powers over four decades; the tree's bytes include the lights it holds ({} bytes a `Quad`)\n",
        workloads::machine(),
        args.runs,
        std::mem::size_of::<Quad>()
    );
    println!(
        "| lights | tree build ms | tree bytes per light | tree sample_light ns | tree light_pdf ns | mixture sample_light ns | mixture light_pdf ns |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    rows.iter().for_each(|r| println!("{r}"));
}
