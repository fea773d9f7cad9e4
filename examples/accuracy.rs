//! What each of hitkit's accuracy choices fixes and what it costs, measured in one process
//! on the same hard-case workloads: the book's quad test, hitkit's well-conditioned plane
//! test with exact edges, 0.1.0's default (widened in `(alpha, beta)`), today's default
//! (the crossing region), spawned-ray offsets against `t_min`, and box-test variants. Prints
//! a Markdown table and writes `accuracy.svg` (failures against cost); then measures the
//! Cornell box's image error against render time.
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
#[path = "accuracy/distance.rs"]
mod distance;
#[path = "accuracy/edges.rs"]
mod edges;
#[path = "accuracy/frame.rs"]
mod frame;
#[path = "accuracy/geometry.rs"]
mod geometry;
#[path = "accuracy/grazing.rs"]
mod grazing;
#[path = "accuracy/plot.rs"]
mod plot;
#[path = "accuracy/rendering.rs"]
mod rendering;
#[path = "accuracy/samplers.rs"]
mod samplers;
#[path = "../tests/support/scene.rs"]
#[allow(dead_code)] // the shared random stream and the machine's name are what this uses
mod scene;
#[path = "accuracy/spawn.rs"]
mod spawn;
#[path = "accuracy/tally.rs"]
mod tally;
#[path = "accuracy/widened.rs"]
mod widened;

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
/// How many parts of the workloads to list per row and kind of failure.
const PARTS_SHOWN: usize = 6;

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

/// `first to last` of a list of numbers, as the text prints them.
fn span(values: &[f64]) -> String {
    match values {
        [] => String::new(),
        [only] => short(*only),
        [first, .., last] => format!("{} to {}", short(*first), short(*last)),
    }
}

/// `10^lo to 10^hi`, as the text prints them.
fn decades((lo, hi): (f64, f64)) -> String {
    format!("{} to {}", short(10f64.powf(lo)), short(10f64.powf(hi)))
}

/// The printed description of the workloads and columns.
fn print_workloads(workloads: &Workloads, repetitions: usize) {
    let counts = RayCounts::of(workloads);
    let farthest = edges::PLACEMENTS
        .iter()
        .map(|&(offset, _)| offset)
        .fold(0.0, f64::max);
    println!(
        "Workloads (seed {:#x}, deterministic; every row runs on exactly the same rays):\n",
        frame::SEED
    );
    println!(
        "- **edges** ({} rays): a unit box under a random rotation, built in world space as six \
         quads each from its own corner (`q` one of the face's corners, `u` and `v` differences \
         of corners), at (offset x scale) {placements}. Corners are `offset + R * local corner` \
         with `R`'s columns rounded to a power-of-two grid so that every corner is an exact \
         sum: the faces close exactly (`q + u + v` is the fourth corner). Rays from {start} \
         scale units outside, entering the box (cosine at least {inward} with the inward normal \
         of each face they aim at), aimed at points on its edges (`corner + s (other corner - \
         corner)`, `s` in [{margin}, {far_margin}]) and at its corners ({} rays); plus rays at \
         the shared edge of two coplanar quads (each built from its far corner; {} rays) and at \
         the shared diagonal of two triangles ({} rays), on the same kind of grid and \
         placements. The same boxes ({} rays) and coplanar pairs ({} rays) again with each \
         corner computed as `offset + R * local corner` and rounded on its own, as a box built \
         face by face in world space is: a quad's `q + u + v` then misses the fourth corner by \
         up to an ulp of the coordinates ({ulp:.1e} at {farthest}). And rays from far away, \
         {far_distances} scale units, at the same edge and corner points of the exact ({} \
         rays) and rounded ({} rays) boxes, entering as the near rays do: their origins round \
         by an ulp of that distance, which can move them off the edge to either side, so each \
         is aimed {inset} times that rounding (and the target's) inside the box, still within \
         a few ulps of its edge. **Crack**: the ray hits none of the shapes.",
        counts.edges,
        counts.boxes[0],
        counts.shared[0],
        counts.shared[2],
        counts.boxes[1],
        counts.shared[1],
        counts.far[0],
        counts.far[1],
        placements = geometry::placements(),
        start = short(edges::START_DISTANCE),
        inward = edges::INWARD_COSINE,
        margin = edges::EDGE_MARGIN,
        far_margin = 1.0 - edges::EDGE_MARGIN,
        ulp = farthest.next_up() - farthest,
        farthest = short(farthest),
        far_distances = decades(edges::FAR_EXPONENTS),
        inset = short(edges::FAR_INSET),
    );
    println!(
        "- **grazing** ({} rays): at the same placements, {per_kind} parallelograms and \
         {per_kind} triangles each ({shapes} shapes), built from `(q, u, v)` with `|u|` and \
         `|v|` of {lo_len} to {hi_len} scale units at {lo_angle} to {hi_angle} degrees to each \
         other, under a random rotation. Rays aimed at points of the shape's plane outside it \
         by {outside} scale units (as rounding of the target allows), beside an edge or (one \
         in {corner}) past a corner: {} arriving along the plane at slopes of {slopes}, from either side, from \
         {start} scale units before the target; and {} from {far_distances} scale units away, \
         crossing the plane at a cosine of at least {crossing}. **False hit**: a hit whose \
         point lies farther from the shape than the contract's bound (below); a ray that \
         passes within the bound of the shape may hit it.",
        counts.grazing[0] + counts.grazing[1],
        counts.grazing[0],
        counts.grazing[1],
        per_kind = grazing::SHAPES_PER_KIND,
        shapes = counts.grazing_shapes,
        lo_len = grazing::EDGE_LENGTHS.0,
        hi_len = grazing::EDGE_LENGTHS.1,
        lo_angle = grazing::UV_ANGLES.0,
        hi_angle = grazing::UV_ANGLES.1,
        outside = decades(grazing::OUTSIDE_EXPONENTS),
        corner = grazing::PAST_CORNER_ONE_IN,
        slopes = decades((grazing::SLOPE_EXPONENTS.1, grazing::SLOPE_EXPONENTS.0)),
        start = short(edges::START_DISTANCE),
        far_distances = decades(edges::FAR_EXPONENTS),
        crossing = frame::CROSSING_COSINE,
    );
    println!(
        "- **spawn** ({} hits, two spawned rays each): a square quad of size S under a random \
         rotation, hit from below, and a second one {gap} S above it, at offsets {offsets} and \
         sizes {sizes} (every pair where the gap, {gap} S, is at least {min_gap} of the \
         offset: hundreds of ulps). From each hit, a random direction back down (should hit \
         nothing) and one up (should hit the quad above). **Self-hit**: a spawned ray hits the \
         quad it left; **lost**: the upward ray misses the quad above (or the first hit is \
         missed).",
        counts.spawn,
        gap = short(spawn::SPAWN_GAP),
        offsets = span(&spawn::SPAWN_OFFSETS),
        sizes = span(&spawn::SPAWN_SIZES),
        min_gap = short(spawn::MIN_GAP),
    );
    let lengths: Vec<f64> = degenerate::DIRECTION_EXPONENTS
        .iter()
        .map(|&e| 10f64.powi(e))
        .collect();
    println!(
        "- **degenerate** ({} rays): unit quads at offsets {offsets}; rays aimed well inside \
         with direction lengths {lengths}, grazing rays at {angles} rad to the plane (where \
         rounding of the origin cannot move the crossing out), and zero directions. \
         **Lost**: a ray that should hit misses.",
        counts.degenerate,
        offsets = degenerate::DEGENERATE_OFFSETS
            .iter()
            .map(|&x| short(x))
            .collect::<Vec<_>>()
            .join(", "),
        lengths = span(&lengths),
        angles = span(&degenerate::GRAZING_ANGLES),
    );
    println!(
        "- **boxes** ({} rays): axis-aligned unit squares (flat boxes) at offsets {offsets}, \
         rays lying in their boxes' slab planes with 0 and -0.0 direction components (across \
         an edge, at a corner), perpendicular and slanted. **Lost**: hitkit's quad test accepts \
         the square, the box test rejects its box.",
        counts.box_rays,
        offsets = span(&boxes::BOX_OFFSETS),
    );
    println!(
        "- **False hits** are counted on the edges, grazing and degenerate workloads: a hit \
         whose point (`HitRecord::point`) lies farther from the true shape it reports (the \
         exact parallelogram or triangle of its `q`, `u`, `v`) than the contract's bound \
         `2^-{exponent} M / s^2`, `M = |q|_inf + |u|_inf + |v|_inf`, `s` the sine of the angle \
         between `u` and `v` (the distance is computed in f64, whose own error is far below \
         the bound here).\n- **NaNs**: hits whose t, point, normal or (alpha, beta) is NaN, \
         on every workload the row runs.\n- **ns per ray**: the quad-test rows on the edges \
         workload's box rays from near with exact corners ({box_rays} rays, closest of six \
         faces), the worst case for a watertight test (every ray is within rounding of an \
         edge); the spawn rows per traced ray of the spawn workload; the box rows per box \
         test. **ns per ray, through faces**: the quad-test rows on the same boxes, with \
         {inside} rays per box from 3 box sizes away toward random points within 0.35 box \
         sizes of its centre, the typical ray of a render. Median of {repetitions} \
         repetitions, one thread. \"–\": the row does not run that workload.\n",
        exponent = distance::CONTRACT_EXPONENT,
        box_rays = counts.boxes[0],
        inside = geometry::INSIDE_RAYS,
    );
}

/// The Markdown table of part 1.
fn print_table(rows: &[Row]) {
    println!(
        "| choice | what it fixes | cracks | false hits | self-hits | lost hits | NaNs | ns per ray | ns per ray, through faces |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for row in rows {
        let t = &row.measured.tally;
        // A `|` in a cell (`|n.d|`) would end it.
        let escape = |text: &str| text.replace('|', "\\|");
        println!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.1} | {} |",
            escape(row.choice),
            escape(row.fixes),
            cell(t.count(Failure::Crack)),
            cell(t.count(Failure::FalseHit)),
            cell(t.count(Failure::SelfHit)),
            cell(t.count(Failure::Lost)),
            cell(t.count(Failure::Nan)),
            row.measured.ns_per_ray,
            row.measured
                .ns_per_inside_ray
                .map_or_else(|| "–".to_string(), |ns| format!("{ns:.1}")),
        );
    }
    println!();
}

/// Notes under the table: the box tests' NaNs and where each row's failures are.
fn print_notes(rows: &[Row], notes: &BoxNotes) {
    println!(
        "The book's slab test computed a NaN slab distance (0 * inf) on {} of the {} box rays; \
         hitkit's quad test rejected {} of the rays built to meet their square (those are not \
         counted).\n",
        notes.book_nan_rays, notes.rays, notes.leaf_rejected
    );
    println!(
        "Where the failures are, by part of a workload, with the placement (offset x size, or \
         offset) that has most of them:\n"
    );
    for row in rows.iter().filter(|r| r.measured.tally.total() > 0) {
        let tally = &row.measured.tally;
        let kinds: Vec<String> = Failure::ALL
            .into_iter()
            .filter(|&kind| tally.count(kind).unwrap_or(0) > 0)
            .map(|kind| {
                let parts = tally.parts(kind);
                let mut shown: Vec<String> = parts
                    .iter()
                    .take(PARTS_SHOWN)
                    .map(|p| {
                        format!(
                            "{} {} (most at {}: {})",
                            p.name, p.count, p.worst.0, p.worst.1
                        )
                    })
                    .collect();
                if parts.len() > PARTS_SHOWN {
                    let rest: u64 = parts[PARTS_SHOWN..].iter().map(|p| p.count).sum();
                    shown.push(format!("{} more parts {rest}", parts.len() - PARTS_SHOWN));
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
    print_notes(&rows, &notes);
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
