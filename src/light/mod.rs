//! What picks among lights; each shape samples itself (its
//! [`PdfHittable`](crate::PdfHittable) implementation beside it, in `shape/`, `mesh/` and
//! `instance/`), and what next-event estimation sees of any light is in `src/sample.rs`.
//!
//! - `uniform.rs`: a slice or `Vec` of lights as their uniform mixture; [`Mixture`]
//!   (`mixture.rs`): lights picked by weight; [`LightTree`] (`tree/`): lights picked by
//!   their importance from the shading point (its build, its cluster bounds, its walk).
//! - [`PunctualLight`] (`punctual.rs`): point, spot and sun lights, of no surface and a
//!   delta density; [`Light`] (`either.rs`): a surface or a punctual light, for a tree of
//!   both kinds.
//! - `RandomDirection` and `RandomDirection09` (`random.rs`, the `rand` and `rand09`
//!   features): a light sampled with a `rand` generator.

mod either;
mod mixture;
mod punctual;
#[cfg(any(feature = "rand", feature = "rand09"))]
mod random;
mod tree;
mod uniform;

pub use either::Light;
pub use mixture::Mixture;
pub use punctual::PunctualLight;

/// A light picked for next-event estimation ([`LightTree::pick`], [`Mixture::pick`]):
/// which one, the probability it had, and what is left of the number that picked it.
///
/// Next-event estimation samples the picked light alone and divides by the probability
/// times that light's own density: cheaper than [`PdfHittable::sample_light`] of the whole
/// mixture or tree, which returns the full density (every light's share of the direction),
/// what multiple importance sampling of a direction the material drew needs instead.
///
/// [`PdfHittable::sample_light`]: crate::PdfHittable::sample_light
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct LightPick {
    /// The light's index in the sampler's `lights()`.
    pub light: usize,
    /// The probability that it is picked from where it was: positive.
    pub probability: f64,
    /// What is left of the number `u` that picked it, rescaled to `[0, 1)`: a uniform
    /// number for the light's own sample, independent of the pick.
    pub rest: f64,
}
#[cfg(feature = "rand")]
pub use random::RandomDirection;
#[cfg(feature = "rand09")]
pub use random::RandomDirection09;
#[cfg(feature = "gltf")]
pub(crate) use tree::Emitters;
pub use tree::LightTree;
