//! The rows: each accuracy choice measured on the workloads (failures counted, time per ray
//! taken). The quad tests (the book's, `Exact`, 0.1.0's widened default, today's default) and
//! the ways of spawning rays are in `quads`, the box tests in `box_tests`; the light
//! samplers and the Cornell box's image error are the second and third tables.

pub mod book;
pub mod box_tests;
pub mod distance;
pub mod quads;
pub mod render_error;
pub mod samplers;
pub mod tally;
pub mod widened;

use box_tests::BoxNotes;
use quads::{
    BookShapes, DefaultShapes, ExactShapes, Spawning, WidenedShapes, shape_row, spawn_offset_row,
};
use tally::{Row, row};

use crate::workloads::Workloads;

/// Every row of the table, in order, and the notes on the box tests.
pub fn measure(workloads: &Workloads, repetitions: usize) -> Result<(Vec<Row>, BoxNotes), String> {
    let book = Spawning::TMin(book::T_MIN);
    let (epsilon, t_min) = (book::PARALLEL_EPSILON, book::T_MIN);
    let mut rows = vec![
        row(
            "book",
            format!(
                "nothing (the baseline: {epsilon:e} parallel test, t = (D - n.o) / n.d, p = o + t \
                 d, t_min = {t_min})"
            ),
            shape_row(&BookShapes, book, workloads, repetitions)?,
        ),
        row(
            "well-conditioned (`Exact`)",
            format!(
                "far-out accuracy: t = n.(q - o) / n.d, p - q = (o - q) + t d; no {epsilon:e} test \
                 or t_min; `spawn_ray`"
            ),
            shape_row(&ExactShapes, Spawning::Offset, workloads, repetitions)?,
        ),
        row(
            "widened in (alpha, beta) (0.1.0 default)",
            "cracks at exactly shared corners: points within the coordinates' error bound, which grows as 1 / |n.d|, count as inside",
            shape_row(&WidenedShapes, Spawning::Offset, workloads, repetitions)?,
        ),
        row(
            "crossing region (default)",
            "cracks (shared corners exact or rounded apart) without false hits: the exact crossing's region, narrow across the ray at any angle; double-double near edges; hits kept in the shape's box",
            shape_row(&DefaultShapes, Spawning::Offset, workloads, repetitions)?,
        ),
        row(
            "spawn offset: `spawn_ray`, t >= 0",
            "self-hits, with no epsilon: the origin moves off by the hit point's error bound",
            spawn_offset_row(workloads, Spawning::Offset, repetitions)?,
        ),
        row(
            format!("spawn offset: hit point, t_min = {t_min}"),
            format!(
                "self-hits where errors stay below {t_min} (the book's way), losing nearer surfaces"
            ),
            spawn_offset_row(workloads, book, repetitions)?,
        ),
    ];
    let (box_rows, notes) = box_tests::box_rows(&workloads.boxes, repetitions)?;
    rows.extend(box_rows);
    Ok((rows, notes))
}
