//! The contract's yardstick, shared by `tests/contract.rs` and the accuracy example: how far
//! a point lies from a planar shape, and how far a reported hit may lie from it (clause 1:
//! `2^-43 M / s^2`).

use hitkit::glam::DVec3;

/// The contract's bound is `2^-CONTRACT_EXPONENT M / s^2`.
pub const CONTRACT_EXPONENT: i32 = 43;

/// The contract's bound on how far a reported hit may lie from the true planar shape of
/// `(q, u, v)`: `2^-43 M / s^2`, `M = |q|_inf + |u|_inf + |v|_inf`, `s` the sine of the angle
/// between `u` and `v`.
pub fn planar_bound(q: DVec3, u: DVec3, v: DVec3) -> f64 {
    let m = q.abs().max_element() + u.abs().max_element() + v.abs().max_element();
    let s = u.cross(v).length() / (u.length() * v.length());
    m / (s * s) * 2f64.powi(-CONTRACT_EXPONENT)
}

/// The distance from `p` to the segment from `a` to `b`.
pub fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let e = b - a;
    let k = ((p - a).dot(e) / e.dot(e)).clamp(0.0, 1.0);
    (p - (a + k * e)).length()
}

/// The distance from `p` to a convex planar polygon in 3D (corners in order, on one
/// plane): `|height|` over the plane where `p`'s projection is inside, else the distance
/// to the nearest edge.
pub fn to_polygon(p: DVec3, corners: &[DVec3]) -> f64 {
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
