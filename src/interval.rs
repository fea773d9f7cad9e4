//! [`Interval`]: a closed range of ray parameters.

use crate::math::scaled_outward;

/// A closed range of reals `[min, max]`; empty when `min > max` (or either is NaN).
///
/// ```
/// use hitkit::Interval;
/// let i = Interval::new(0.0, 1.0);
/// assert!(i.contains(1.0) && !i.surrounds(1.0));
/// assert!(Interval::EMPTY.is_empty() && Interval::UNIVERSE.contains(1e300));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Interval {
    /// Lower end.
    pub min: f64,
    /// Upper end.
    pub max: f64,
}

impl Interval {
    /// Contains nothing.
    pub const EMPTY: Self = Self::new(f64::INFINITY, f64::NEG_INFINITY);
    /// Contains every real.
    pub const UNIVERSE: Self = Self::new(f64::NEG_INFINITY, f64::INFINITY);
    /// `[0, infinity)`: everything ahead of a ray's origin, the range to trace a camera ray
    /// or a [spawned](crate::HitRecord::spawn_ray) one with (no epsilon needed).
    ///
    /// ```
    /// use hitkit::Interval;
    /// assert_eq!(Interval::FORWARD, Interval::new(0.0, f64::INFINITY));
    /// ```
    pub const FORWARD: Self = Self::new(0.0, f64::INFINITY);

    /// The interval `[min, max]`.
    #[inline]
    #[must_use]
    pub const fn new(min: f64, max: f64) -> Self {
        Self { min, max }
    }

    /// Both ends times a power of two `factor` (a range of `t` along a ray whose direction
    /// was divided by it: see [`Ray::rescaled`](crate::Ray)), rounded outward where the
    /// products under- or overflow.
    #[inline]
    pub(crate) fn scaled(self, factor: f64) -> Self {
        if factor == 1.0 {
            return self;
        }
        Self::new(
            scaled_outward(self.min, factor, true),
            scaled_outward(self.max, factor, false),
        )
    }

    /// `max - min`; negative for an empty interval.
    #[inline]
    #[must_use]
    pub fn size(&self) -> f64 {
        self.max - self.min
    }

    /// Whether it contains no number.
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min > self.max || self.min.is_nan() || self.max.is_nan()
    }

    /// `min <= x <= max` (closed). False for NaN.
    #[inline]
    #[must_use]
    pub fn contains(&self, x: f64) -> bool {
        self.min <= x && x <= self.max
    }

    /// `min < x < max` (open). False for NaN.
    #[inline]
    #[must_use]
    pub fn surrounds(&self, x: f64) -> bool {
        self.min < x && x < self.max
    }

    /// `x` clamped into the interval (NaN stays NaN).
    #[inline]
    #[must_use]
    pub fn clamp(&self, x: f64) -> f64 {
        if x < self.min {
            self.min
        } else if x > self.max {
            self.max
        } else {
            x
        }
    }

    /// The smallest interval containing both.
    #[inline]
    #[must_use]
    pub fn union(&self, other: &Self) -> Self {
        Self::new(self.min.min(other.min), self.max.max(other.max))
    }
}

impl Default for Interval {
    /// [`Interval::EMPTY`].
    fn default() -> Self {
        Self::EMPTY
    }
}
