//! What each of hitkit's accuracy choices fixes and what it costs, measured in one process
//! on the same hard-case workloads: the book's quad test, hitkit's well-conditioned plane
//! test with exact edges, its watertight default, spawned-ray offsets against `t_min`, and
//! box-test variants. Prints a Markdown table and writes `accuracy.svg` (failures against
//! cost); then measures the Cornell box's image error against render time.
//!
//! `cargo run --release --example accuracy`; `-- --help` lists the options.

mod common;

#[path = "accuracy/book.rs"]
mod book;
#[path = "accuracy/box_tests.rs"]
mod box_tests;
#[path = "accuracy/boxes.rs"]
mod boxes;
#[path = "accuracy/degenerate.rs"]
mod degenerate;
#[path = "accuracy/edges.rs"]
mod edges;
#[path = "accuracy/frame.rs"]
mod frame;
#[path = "accuracy/geometry.rs"]
mod geometry;
#[path = "accuracy/plot.rs"]
mod plot;
#[path = "accuracy/rendering.rs"]
mod rendering;
#[path = "accuracy/samplers.rs"]
mod samplers;
#[path = "../benches/peers/src/scene.rs"]
#[allow(dead_code)] // the shared random stream and the machine's name are what this uses
mod scene;
#[path = "accuracy/spawn.rs"]
mod spawn;
#[path = "accuracy/tally.rs"]
mod tally;

use std::path::PathBuf;
use std::process::ExitCode;

use box_tests::BoxNotes;
use geometry::{RayCounts, Workloads};
use rendering::ErrorReport;
use tally::{Failure, Row, short};

/// Timed repetitions of each workload; the table shows their median.
const REPETITIONS: usize = 7;
/// The Cornell box's width (and height) in part 2.
const RENDER_WIDTH: usize = 100;
/// How many places to list per row and kind of failure.
const PLACES_SHOWN: usize = 4;

/// The command line.
#[derive(Clone, Debug)]
struct Options {
    output_dir: PathBuf,
    quick: bool,
}

const USAGE: &str = "\
Measures what each of hitkit's accuracy choices fixes (failure counts on hard-case
workloads) and what it costs (ns per ray), prints a Markdown table, writes accuracy.svg,
then measures the Cornell box's image error against render time.

Usage: cargo run --release --example accuracy -- [OPTIONS]

Options:
  --output-dir DIR  where to write accuracy.svg (created if missing) [default: .]
  --quick           a few rays and a small reference image: a smoke test, not numbers
                    to publish
  -h, --help        this text";

impl Options {
    /// `Ok(None)` for `--help`.
    fn parse(args: impl IntoIterator<Item = String>) -> Result<Option<Self>, String> {
        let mut options = Self {
            output_dir: PathBuf::from("."),
            quick: false,
        };
        let mut args = args.into_iter();
        while let Some(arg) = args.next() {
            match arg.as_str() {
                "-h" | "--help" => return Ok(None),
                "--quick" => options.quick = true,
                "--output-dir" => {
                    let dir = args
                        .next()
                        .ok_or("--output-dir needs a value: the directory to write into")?;
                    options.output_dir = PathBuf::from(dir);
                }
                other => match other.strip_prefix("--output-dir=") {
                    Some(dir) if !dir.is_empty() => options.output_dir = PathBuf::from(dir),
                    Some(_) => return Err("--output-dir= needs a directory".to_string()),
                    None => return Err(format!("unknown option `{other}`")),
                },
            }
        }
        Ok(Some(options))
    }
}

/// A count, or "–" for a workload the row does not run.
fn cell(count: Option<u64>) -> String {
    count.map_or_else(|| "–".to_string(), |n| n.to_string())
}

/// The printed description of the workloads and columns.
fn print_workloads(workloads: &Workloads, repetitions: usize) {
    let counts = RayCounts::of(workloads);
    println!(
        "Workloads (seed {:#x}, deterministic; every row runs on exactly the same rays):\n",
        frame::SEED
    );
    println!(
        "- **edges** ({} rays): a unit box under a random rotation, built in world space as six \
         quads each from its own corner (`q` one of the face's corners, `u` and `v` differences \
         of corners), at (offset x scale) {}. Corners are `offset + R * local corner` with `R`'s \
         columns rounded to a power-of-two grid so that every corner is an exact sum: the faces \
         close exactly (`q + u + v` is the fourth corner). Rays from outside, entering the box, \
         aimed at points on its edges (`corner + s (other corner - corner)`) and at its corners; \
         plus rays at the shared edge of two coplanar quads (each built from its far corner) and \
         at the shared diagonal of two triangles, on the same kind of grid and placements. \
         **Crack**: the ray hits none of the shapes.",
        counts.edges,
        geometry::placements()
    );
    println!(
        "- **spawn** ({} hits, two spawned rays each): a square quad of size S under a random \
         rotation, hit from below, and a second one {gap} S above it, at offsets 0 to 1e12 and \
         sizes 1e-2 to 1e4 (every pair where the gap, {gap} S, is at least 1e-13 of the offset: \
         hundreds of ulps). From each hit, a random direction back down (should hit nothing) \
         and one up (should hit the quad above). **Self-hit**: a spawned ray hits the quad it \
         left; **lost**: the upward ray misses the quad above (or the first hit is missed).",
        counts.spawn,
        gap = short(spawn::SPAWN_GAP)
    );
    println!(
        "- **degenerate** ({} rays): unit quads at offsets 0, 1e3, 1e6; rays aimed well inside \
         with direction lengths 1e-12 to 1e9, grazing rays at 1e-2 to 1e-12 rad to the plane \
         (where rounding of the origin cannot move the crossing out), and zero directions. \
         **Lost**: a ray that should hit misses.",
        counts.degenerate
    );
    println!(
        "- **boxes** ({} rays): axis-aligned unit squares (flat boxes) at offsets 0 to 6e11, \
         rays lying in their boxes' slab planes with 0 and -0.0 direction components (across \
         an edge, at a corner), perpendicular and slanted. **Lost**: hitkit's quad test accepts \
         the square, the box test rejects its box.",
        counts.boxes
    );
    println!(
        "- **NaNs**: hits whose t, point, normal or (alpha, beta) is NaN, on every workload the \
         row runs.\n- **ns per ray**: the book, well-conditioned and watertight rows on the edges \
         workload's box rays (closest of six faces); the spawn rows per traced ray of the spawn \
         workload; the box rows per box test. Median of {repetitions} repetitions, one thread. \
         \"–\": the row does not run that workload.\n"
    );
}

/// The Markdown table of part 1.
fn print_table(rows: &[Row]) {
    println!("| choice | what it fixes | cracks | self-hits | lost hits | NaNs | ns per ray |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    for row in rows {
        let t = &row.measured.tally;
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.1} |",
            row.choice,
            row.fixes,
            cell(t.count(Failure::Crack)),
            cell(t.count(Failure::SelfHit)),
            cell(t.count(Failure::Lost)),
            cell(t.count(Failure::Nan)),
            row.measured.ns_per_ray
        );
    }
    println!();
}

/// Notes under the table: the box tests' NaNs and where each row's failures are.
fn print_notes(rows: &[Row], notes: &BoxNotes, counts: &RayCounts) {
    let rounded: Vec<String> = rows
        .iter()
        .filter_map(|r| {
            let (boxes, coplanar) = r.measured.rounded_cracks?;
            Some(format!("{} {boxes} and {coplanar}", r.choice))
        })
        .collect();
    println!(
        "Not in the table: the boxes, and the coplanar pairs, with each corner computed as \
         `offset + R * local corner` and rounded on its own do not close: a quad's `q + u + v` \
         misses the fourth corner by up to an ulp of the coordinates ({ulp:.1e} at 1e12), a gap \
         in the geometry that no intersection test can close (shapes must share their edges' \
         corners). Rays that hit nothing, at the boxes' edges and corners ({} rays) and at the \
         pairs' shared edge ({} rays): {}.\n",
        counts.rounded_boxes,
        counts.rounded_coplanar,
        rounded.join("; "),
        ulp = 1e12f64.next_up() - 1e12,
    );
    println!(
        "The book's slab test computed a NaN slab distance (0 * inf) on {} of the {} box rays; \
         hitkit's quad test rejected {} of the rays built to meet their square (those are not \
         counted).\n",
        notes.book_nan_rays, notes.rays, notes.leaf_rejected
    );
    println!("Where the failures are (placements as offset x size):\n");
    for row in rows.iter().filter(|r| r.measured.tally.total() > 0) {
        let tally = &row.measured.tally;
        let kinds: Vec<String> = Failure::ALL
            .into_iter()
            .filter(|&kind| tally.count(kind).unwrap_or(0) > 0)
            .map(|kind| {
                let places = tally.places(kind);
                let mut shown: Vec<String> = places.iter().take(PLACES_SHOWN).cloned().collect();
                if places.len() > PLACES_SHOWN {
                    shown.push(format!("{} more", places.len() - PLACES_SHOWN));
                }
                format!(
                    "{} {}: {}",
                    tally.count(kind).unwrap_or(0),
                    kind.label(),
                    shown.join(", ")
                )
            })
            .collect();
        println!("- {}: {}", row.choice, kinds.join("; "));
    }
    println!();
}

/// Writes the plot of part 1 into `dir`; its path.
fn write_plot(rows: &[Row], dir: &std::path::Path, machine: &str) -> Result<PathBuf, String> {
    let points: Vec<plot::Point> = rows
        .iter()
        .map(|row| plot::Point {
            label: row.choice.replace('`', ""),
            ns_per_ray: row.measured.ns_per_ray,
            failures: row.measured.tally.total(),
        })
        .collect();
    let title = format!("hitkit accuracy choices: failures against cost ({machine})");
    let path = dir.join("accuracy.svg");
    std::fs::write(&path, plot::svg(&points, &title))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path)
}

/// The Markdown of part 2.
fn print_errors(report: &ErrorReport) {
    let noise = report.reference_noise;
    println!(
        "`cornell_scene({w}, sampling)`: {w}x{w}, all cores, depth {depth}, the effects the \
         scene calls for, its light sampled with `Sampling::Area` and with \
         `Sampling::SolidAngle`. Reference: {} samples per pixel (area sampling) with an \
         independent seed, rendered in {:.1} s, mean luminance {:.4}. Its own noise (RMS over \
         pixels of its standard error, from its per-pixel sample variance) is {noise:.4}; it \
         adds to every RMS error against it in quadrature, and the table takes it out: \
         sqrt(RMS^2 - {noise:.4}^2).\n",
        report.reference_samples,
        report.reference_seconds,
        report.reference_mean,
        w = report.width,
        depth = rendering::MAX_DEPTH,
    );
    println!(
        "| samples per pixel | area: seconds | area: RMS error | solid angle: seconds | solid \
         angle: RMS error |"
    );
    println!("|---:|---:|---:|---:|---:|");
    let corrected = |rms: f64| (rms * rms - noise * noise).max(0.0).sqrt();
    for row in &report.rows {
        println!(
            "| {} | {:.3} | {:.4} | {:.3} | {:.4} |",
            row.samples,
            row.area.0,
            corrected(row.area.1),
            row.solid_angle.0,
            corrected(row.solid_angle.1)
        );
    }
}

/// Runs both parts; an error message for anything that went wrong.
fn run(options: &Options) -> Result<(), String> {
    if options.output_dir.exists() && !options.output_dir.is_dir() {
        return Err(format!(
            "--output-dir: {} is not a directory",
            options.output_dir.display()
        ));
    }
    std::fs::create_dir_all(&options.output_dir).map_err(|e| {
        format!(
            "cannot use {} as the output directory: {e}",
            options.output_dir.display()
        )
    })?;
    let machine = scene::machine();
    println!("# What each accuracy choice fixes and what it costs\n");
    println!("Machine: {machine}.\n");
    println!("## Geometry\n");
    let size = if options.quick { 0.05 } else { 1.0 };
    let workloads = Workloads::generate(size);
    let repetitions = if options.quick { 1 } else { REPETITIONS };
    print_workloads(&workloads, repetitions);
    let (rows, notes) = geometry::measure(&workloads, repetitions)?;
    print_table(&rows);
    print_notes(&rows, &notes, &RayCounts::of(&workloads));
    let path = write_plot(&rows, &options.output_dir, &machine)?;
    println!("Plot: {}\n", path.display());

    println!("## Light sampling: area against solid angle\n");
    println!(
        "A unit square light (corners (-0.5, -0.5, 0) and (0.5, 0.5, 0)) and its lower-left \
         half, a triangle, seen from a point (0.1, -0.2) at each height; the irradiance \
         estimate cos / pdf, its variance per sample and the time per sample (direction and \
         density; median of 5 runs), with `Sampling::Area` and with the default \
         `Sampling::SolidAngle`.\n"
    );
    println!(
        "| shape | height | area: variance | area: ns | solid angle: variance | solid angle: ns | variance ratio |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for row in samplers::measure_all(options.quick) {
        println!(
            "| {} | {} | {:.4e} | {:.1} | {:.4e} | {:.1} | {:.3} |",
            row.shape,
            row.height,
            row.area.0,
            row.area.1,
            row.solid_angle.0,
            row.solid_angle.1,
            row.solid_angle.0 / row.area.0
        );
    }
    println!();

    println!("## Image error against time: the Cornell box\n");
    let width = if options.quick { 32 } else { RENDER_WIDTH };
    print_errors(&rendering::measure(width, options.quick)?);
    Ok(())
}

fn main() -> ExitCode {
    let options = match Options::parse(std::env::args().skip(1)) {
        Ok(Some(options)) => options,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}\n\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
