//! Optional integrations, each behind its feature: `approx` comparisons and `serde`.

#[cfg(feature = "approx")]
mod approx;
#[cfg(feature = "serde")]
mod serde;
