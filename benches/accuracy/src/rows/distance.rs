//! The contract's yardstick on the workloads' shapes: which shape a `(q, u, v)` stands for,
//! and whether a reported hit lies farther from it than the contract allows (clause 1;
//! the distance and the bound are `hitkit_render::distance`, shared with
//! `tests/contract.rs`).

use hitkit::glam::DVec3;

use crate::workloads::frame::{Outline, QuadSpec};
pub use hitkit_render::distance::CONTRACT_EXPONENT;
use hitkit_render::distance::{planar_bound, to_polygon};

impl Outline {
    /// The distance from `p` to the shape `s` (the exact parallelogram or triangle that
    /// `(q, u, v)` describe).
    ///
    /// Computed in `f64`. Its own error is far below the contract's bound at the sizes and
    /// offsets the workloads use: the corners `q + u` and `q + u + v` round by at most two
    /// ulps of `M` (about `2^-51 M`); the differences `p - corner` of a point near the shape
    /// are exact or round by an ulp of themselves; and the normal's direction, from a cross
    /// product of edges, is off by a few ulps over `s`, which tilts the height of a point
    /// near the shape (within `2 M` of its corners) by about `2^-50 M / s`. All of this is
    /// under `2^-48 M / s`, at most `1/32` of `2^-43 M / s^2`.
    pub fn distance(self, s: &QuadSpec, p: DVec3) -> f64 {
        let all = self.corners(s);
        to_polygon(p, &all[..self.corner_count()])
    }
}

/// Whether `p`, a reported hit on the shape `s`, lies farther from it than the contract's
/// bound.
pub fn is_false_hit(outline: Outline, s: &QuadSpec, p: DVec3) -> bool {
    outline.distance(s, p) > planar_bound(s.q, s.u, s.v)
}
