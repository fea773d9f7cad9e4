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

/// `v / |v|` and `|v|`, without overflow or underflow in the squares: `v` is first scaled
/// by the power of two (an exact scaling) that brings its largest component near 1. For a
/// zero vector, `(NaN, 0)`.
#[must_use]
pub(crate) fn unit_and_length(v: glam::DVec3) -> (glam::DVec3, f64) {
    let scale = power_of_two_scale(v.abs().max_element());
    let scaled = v * scale;
    let length = scaled.length();
    (scaled / length, length / scale)
}

/// The power of two that brings finite `largest >= 0` into `[1, 2)` (clamped to the normal
/// range): multiplying by it is exact, so sums and squares of the scaled values neither
/// overflow nor underflow.
#[inline]
#[must_use]
pub(crate) fn power_of_two_scale(largest: f64) -> f64 {
    let exponent = ((largest.to_bits() >> 52) & 0x7ff) as i64 - 1023;
    f64::from_bits(((1023 - exponent.clamp(-1022, 1022)) as u64) << 52)
}

/// `(sin x, cos x)`.
#[inline]
#[must_use]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    #[cfg(feature = "std")]
    {
        x.sin_cos()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sincos(x)
    }
}

#[inline]
#[must_use]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        y.atan2(x)
    }
    #[cfg(not(feature = "std"))]
    {
        libm::atan2(y, x)
    }
}

#[inline]
#[must_use]
pub(crate) fn acos(x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.acos()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::acos(x)
    }
}
