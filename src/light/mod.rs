//! Light sampling: what makes a shape a light a path tracer can aim at.
//!
//! - [`SampleInterior`] (`area.rs`): an interior's area and area-uniform points, which
//!   make a [`Quad`](crate::Quad) of it a [`PdfHittable`](crate::PdfHittable); the
//!   [`Polygon`]s that also have a solid-angle sampler.
//! - [`Sampling`] (`sampling.rs`): how a quad light chooses directions, by solid angle or
//!   by area; `spherical.rs`: the solid-angle samplers of rectangles and triangles.
//! - [`ShadingContext`] and [`LightSample`] (`sample.rs`): next-event estimation's view of
//!   any light.
//! - `uniform.rs`: a slice or `Vec` of lights as their uniform mixture; [`Mixture`]
//!   (`mixture.rs`): lights picked by weight; [`LightTree`] (`tree/`): lights picked by
//!   their importance from the shading point (its build, its cluster bounds, its walk).
//! - `RandomDirection` and `RandomDirection09` (`random.rs`, the `rand` and `rand09`
//!   features): a light sampled with a `rand` generator.
//!
//! Each shape's own [`PdfHittable`](crate::PdfHittable) implementation lives beside the
//! shape ([`Quad`](crate::Quad), [`Sphere`](crate::Sphere),
//! [`Transformed`](crate::Transformed), [`TriangleMesh`](crate::TriangleMesh)); this
//! module holds what they share.

mod area;
mod mixture;
#[cfg(any(feature = "rand", feature = "rand09"))]
mod random;
mod sample;
mod sampling;
mod spherical;
mod tree;
mod uniform;

pub use area::{Polygon, SampleInterior};
pub use mixture::Mixture;
#[cfg(feature = "rand")]
pub use random::RandomDirection;
#[cfg(feature = "rand09")]
pub use random::RandomDirection09;
pub use sample::{LightSample, ShadingContext};
pub use sampling::Sampling;
pub(crate) use spherical::{Spherical, View};
#[cfg(feature = "gltf")]
pub(crate) use tree::Emitters;
pub use tree::{Emission, LightTree};

use glam::{DVec2, DVec3};

/// How far a light's sampler retreats toward the middle of its shape, in turn, when a
/// direction it drew does not reach the shape by the test its density goes by: the first
/// (1, no retreat) is the sample itself, and for every `u` inside `[0, 1)^2` by more than
/// rounding it is the one returned, so the distribution is unchanged but for the few
/// directions that rounding aims just past an edge (a sampler's first point `(0, 0)`, a
/// triangle's corner, a sphere's silhouette), which would have density 0 (the contract's
/// clause 6). Each later factor moves the sample a larger share of the way in; the last
/// (0) aims at the middle itself.
const RETREAT: [f64; 6] = [
    1.0,
    1.0 - 1.0 / (1u64 << 40) as f64,
    1.0 - 1.0 / (1u64 << 24) as f64,
    1.0 - 1.0 / (1u64 << 12) as f64,
    0.5,
    0.0,
];

/// The first of `sample(k)`, for the factors `k` of [`RETREAT`], that `reaches`; the first
/// sample if none does (a shape too small or far to aim at from `origin`, which has
/// density 0 there in every direction).
#[inline]
pub(crate) fn reaching(
    mut sample: impl FnMut(f64) -> DVec3,
    reaches: impl Fn(DVec3) -> bool,
) -> DVec3 {
    let first = sample(RETREAT[0]);
    if reaches(first) {
        return first;
    }
    RETREAT[1..]
        .iter()
        .map(|&k| sample(k))
        .find(|&d| reaches(d))
        .unwrap_or(first)
}

/// `v` as a unit vector, for any finite, non-zero `v` (scaled first, so that its square
/// neither over- nor underflows); `None` for a zero or non-finite one.
pub(crate) fn direction_of(v: DVec3) -> Option<DVec3> {
    let (unit, length) = crate::math::unit_and_length(v);
    (length > 0.0 && unit.is_finite()).then_some(unit)
}

/// `d` as a unit vector (the zero vector as itself): what every light's
/// `sample_direction` returns, tested for reaching the light after this rounding.
#[inline]
pub(crate) fn unit(d: DVec3) -> DVec3 {
    let squared = d.length_squared();
    if squared.is_normal() && squared < f64::INFINITY {
        // One division for the three components: within an ulp or two of `d / |d|`.
        d * (1.0 / crate::math::sqrt(squared))
    } else if d == DVec3::ZERO || !d.is_finite() {
        d
    } else {
        // A length whose square over- or underflows: scaled first.
        crate::math::unit_and_length(d).0
    }
}

/// `u` moved toward the middle of the unit square by the factor `k` of [`RETREAT`]; `u`
/// itself, bit for bit, for `k = 1`.
#[inline]
pub(crate) fn toward_middle(u: DVec2, k: f64) -> DVec2 {
    if k == 1.0 {
        u
    } else {
        DVec2::splat(0.5) + (u - DVec2::splat(0.5)) * k
    }
}
