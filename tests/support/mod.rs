//! What several test files share: the rounding bound and a fixed random stream (the one
//! the benches use).
#![allow(dead_code)]

#[path = "../../benches/peers/src/scene.rs"]
mod scene;

#[allow(unused_imports)] // not every test file uses it
pub use scene::SplitMix;

/// `gamma(k) = k u / (1 - k u)`, `u` the unit roundoff: bounds `k` chained roundings.
pub fn gamma(k: u32) -> f64 {
    let nu = f64::from(k) * f64::EPSILON * 0.5;
    nu / (1.0 - nu)
}
