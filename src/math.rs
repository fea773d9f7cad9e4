//! The float functions `core` lacks, and the rounding-error arithmetic shared by every
//! module: one place for each piece of numerical machinery.

/// Unit roundoff of `f64` (half the machine epsilon), as pbrt-v4's `MachineEpsilon`.
pub(crate) const UNIT_ROUNDOFF: f64 = f64::EPSILON * 0.5;

/// `gamma(n) = n u / (1 - n u)`: bounds the relative error of `n` chained roundings
/// (Higham, *Accuracy and Stability of Numerical Algorithms*, 3.1; pbrt-v4 section 6.8.1).
#[inline]
#[must_use]
pub(crate) const fn gamma(n: u32) -> f64 {
    let nu = n as f64 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

#[inline]
#[must_use]
pub(crate) fn sqrt(x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.sqrt()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sqrt(x)
    }
}
