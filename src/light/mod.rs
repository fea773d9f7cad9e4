//! What picks among lights; each shape samples itself (its
//! [`PdfHittable`](crate::PdfHittable) implementation beside it, in `shape/`, `mesh/` and
//! `instance/`), and what next-event estimation sees of any light is in `src/sample.rs`.
//!
//! - `uniform.rs`: a slice or `Vec` of lights as their uniform mixture; [`Mixture`]
//!   (`mixture.rs`): lights picked by weight; [`LightTree`] (`tree/`): lights picked by
//!   their importance from the shading point (its build, its cluster bounds, its walk).
//! - `RandomDirection` and `RandomDirection09` (`random.rs`, the `rand` and `rand09`
//!   features): a light sampled with a `rand` generator.

mod mixture;
#[cfg(any(feature = "rand", feature = "rand09"))]
mod random;
mod tree;
mod uniform;

pub use mixture::Mixture;
#[cfg(feature = "rand")]
pub use random::RandomDirection;
#[cfg(feature = "rand09")]
pub use random::RandomDirection09;
#[cfg(feature = "gltf")]
pub(crate) use tree::Emitters;
pub use tree::{Emission, LightTree};
