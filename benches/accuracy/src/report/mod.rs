//! The report: the Markdown tables, the notes on where failures are, and the SVG plot,
//! printed from what the rows measured.

pub mod plot;

use std::path::{Path, PathBuf};

use crate::rows::box_tests::BoxNotes;
use crate::rows::distance::CONTRACT_EXPONENT;
use crate::rows::render_error::{self, ErrorReport};
use crate::rows::samplers::{self, SamplerRow};
use crate::rows::tally::{Failure, Row};
use crate::workloads::{Workloads, inside};

/// How many parts of the workloads to list per row and kind of failure.
const PARTS_SHOWN: usize = 6;

/// A count, or "–" for a workload the row does not run.
fn cell(count: Option<u64>) -> String {
    count.map_or_else(|| "–".to_string(), |n| n.to_string())
}

/// What the columns count and time, from the constants the rows use.
pub fn print_columns(workloads: &Workloads, repetitions: usize) {
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
         {inside}, the typical ray of a render. Median of {repetitions} \
         repetitions, one thread. \"–\": the row does not run that workload.\n",
        exponent = CONTRACT_EXPONENT,
        box_rays = workloads.edges.boxes.rays.len(),
        inside = inside::describe(),
    );
}

/// The Markdown table of part 1.
pub fn print_table(rows: &[Row]) {
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
            escape(&row.choice),
            escape(&row.fixes),
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
pub fn print_notes(rows: &[Row], notes: &BoxNotes) {
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
pub fn write_plot(rows: &[Row], dir: &Path, machine: &str) -> Result<PathBuf, String> {
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
pub fn print_errors(report: &ErrorReport) {
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
        depth = render_error::MAX_DEPTH,
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

/// The light-sampling table.
pub fn print_samplers(rows: &[SamplerRow]) {
    println!("{}\n", samplers::describe());
    println!(
        "| shape | height | area: variance | area: ns | solid angle: variance | solid angle: ns | variance ratio |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for row in rows {
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
}
