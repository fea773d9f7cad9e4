//! Light sampling: what makes a shape a light a path tracer can aim at.
//!
//! - [`SampleInterior`] (`interior.rs`): an interior's area and area-uniform points, which
//!   make a [`Quad`](crate::Quad) of it a [`PdfHittable`](crate::PdfHittable); the
//!   [`Polygon`]s that also have a solid-angle sampler.
//! - [`Sampling`] (`sampling.rs`): how a quad light chooses directions, by solid angle or
//!   by area.
//! - `spherical.rs`: the solid-angle samplers of rectangles and triangles.
//! - `uniform.rs`: a slice, `Vec` or [`Bvh`](crate::Bvh) of lights as their uniform
//!   mixture; [`Mixture`] (`mixture.rs`): lights picked by weight.
//! - `RandomDirection` (`random.rs`, the `rand` feature): a light sampled with a `rand`
//!   generator.
//!
//! Each shape's own [`PdfHittable`](crate::PdfHittable) implementation lives beside the
//! shape ([`Quad`](crate::Quad), [`Sphere`](crate::Sphere),
//! [`Transformed`](crate::Transformed)); this module holds what they share.

mod interior;
mod mixture;
#[cfg(feature = "rand")]
mod random;
mod sampling;
mod spherical;
mod uniform;

pub use interior::{Polygon, SampleInterior};
pub use mixture::Mixture;
#[cfg(feature = "rand")]
pub use random::RandomDirection;
pub use sampling::Sampling;
pub(crate) use spherical::{Spherical, View};
