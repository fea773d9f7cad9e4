//! Optional integrations, each behind its feature: `approx` comparisons, `serde`, and the
//! scene loaders (`obj`, `gltf`).

#[cfg(feature = "approx")]
mod approx;
#[cfg(feature = "gltf")]
pub(crate) mod gltf;
#[cfg(any(feature = "obj", feature = "gltf"))]
pub(crate) mod load;
#[cfg(feature = "obj")]
pub(crate) mod obj;
#[cfg(feature = "serde")]
mod serde;
