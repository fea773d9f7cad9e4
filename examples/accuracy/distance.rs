//! The contract's yardstick: how far a point lies from the true planar shape, and how far a
//! reported hit may lie from it (`tests/contract.rs`, clause 1).

use hitkit::glam::DVec3;

use crate::frame::QuadSpec;

/// The contract's bound is `2^-CONTRACT_EXPONENT M / s^2`.
pub const CONTRACT_EXPONENT: i32 = 43;

/// Which shape a `(q, u, v)` stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outline {
    /// Corners `q`, `q + u`, `q + u + v`, `q + v`.
    Parallelogram,
    /// Corners `q`, `q + u`, `q + v`.
    Triangle,
}

impl Outline {
    /// The shape's name in the printed text.
    pub fn name(self) -> &'static str {
        match self {
            Outline::Parallelogram => "parallelogram",
            Outline::Triangle => "triangle",
        }
    }

    /// The corners of the shape `s`, in order around `u x v` (the last repeats the first
    /// for a triangle, whose fourth slot is unused: see [`Outline::corner_count`]).
    pub fn corners(self, s: &QuadSpec) -> [DVec3; 4] {
        match self {
            Outline::Parallelogram => [s.q, s.q + s.u, s.q + s.u + s.v, s.q + s.v],
            Outline::Triangle => [s.q, s.q + s.u, s.q + s.v, s.q],
        }
    }

    /// How many of [`Outline::corners`] are corners.
    pub fn corner_count(self) -> usize {
        match self {
            Outline::Parallelogram => 4,
            Outline::Triangle => 3,
        }
    }

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

/// The contract's bound on how far a reported hit may lie from the true shape:
/// `2^-43 M / s^2`, `M = |q|_inf + |u|_inf + |v|_inf`, `s` the sine of the angle between `u`
/// and `v`.
pub fn contract_bound(s: &QuadSpec) -> f64 {
    let m = s.q.abs().max_element() + s.u.abs().max_element() + s.v.abs().max_element();
    let sine = s.u.cross(s.v).length() / (s.u.length() * s.v.length());
    m / (sine * sine) * 2f64.powi(-CONTRACT_EXPONENT)
}

/// Whether `p`, a reported hit on the shape `s`, lies farther from it than the contract's
/// bound.
pub fn is_false_hit(outline: Outline, s: &QuadSpec, p: DVec3) -> bool {
    outline.distance(s, p) > contract_bound(s)
}

/// The distance from `p` to the segment from `a` to `b`.
fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let e = b - a;
    let k = ((p - a).dot(e) / e.dot(e)).clamp(0.0, 1.0);
    (p - (a + k * e)).length()
}

/// The distance from `p` to a convex planar polygon in 3D (corners in order, on one
/// plane): `|height|` over the plane where `p`'s projection is inside, else the distance
/// to the nearest edge.
fn to_polygon(p: DVec3, corners: &[DVec3]) -> f64 {
    let n = (corners[1] - corners[0])
        .cross(corners[2] - corners[0])
        .normalize();
    let count = corners.len();
    let edge = |i: usize| (corners[i], corners[(i + 1) % count]);
    let inside = (0..count).all(|i| {
        let (a, b) = edge(i);
        (b - a).cross(p - a).dot(n) >= 0.0
    });
    if inside {
        return n.dot(p - corners[0]).abs();
    }
    (0..count)
        .map(|i| {
            let (a, b) = edge(i);
            to_segment(p, a, b)
        })
        .fold(f64::INFINITY, f64::min)
}
