//! [`Ray`]: an origin, a direction and a time.

use glam::DVec3;

use crate::Interval;
use crate::math::{direction_scale, scaled_outward};

/// A ray `origin + t * direction`, sent at `time`.
///
/// The direction need not be unit length: hits report `t` in units of `direction`, and
/// whether a surface is hit, and where, does not depend on the direction's length, from
/// the subnormals to `f64::MAX` (along `d * 2^k` every shape and tree finds the same point
/// at `t * 2^-k`, unless that `t` would pass `f64`'s range; densities over solid angle are
/// the same).
///
/// `time` is the book's `ray.time()`: the moment the ray samples, for objects that move
/// ([`Moving`](crate::Moving)); 0 unless set with [`Ray::at_time`]. Static shapes ignore
/// it, and [`HitRecord::spawn_ray`](crate::HitRecord::spawn_ray) passes it on.
///
/// ```
/// use hitkit::{glam::DVec3, Ray};
/// let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -2.0));
/// assert_eq!(ray.at(1.5), DVec3::new(0.0, 0.0, -3.0));
/// assert_eq!((ray.time, ray.at_time(0.25).time), (0.0, 0.25));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Ray {
    /// Where the ray starts.
    pub origin: DVec3,
    /// Where it goes; any finite, non-zero vector.
    pub direction: DVec3,
    /// When it is sent; moving objects are where they are at this time.
    #[cfg_attr(feature = "serde", serde(default))]
    pub time: f64,
    /// What the ray sees: an object whose [`mask`](crate::Hittable::mask) shares no bit
    /// with it is passed over (a lamp the camera does not see, an object that casts no
    /// shadow). Every bit set by [`Ray::new`]: every object is seen.
    #[cfg_attr(feature = "serde", serde(default = "every_bit"))]
    pub mask: u32,
}

/// The mask of a ray that sees everything (serde's default for a ray or a record without
/// one).
#[cfg(feature = "serde")]
pub(crate) fn every_bit() -> u32 {
    u32::MAX
}

impl Ray {
    /// A ray from `origin` along `direction`, at time 0.
    #[inline]
    #[must_use]
    pub const fn new(origin: DVec3, direction: DVec3) -> Self {
        Self {
            origin,
            direction,
            time: 0.0,
            mask: u32::MAX,
        }
    }

    /// The same ray seeing only objects whose mask shares a bit with `mask` (see
    /// [`Ray::mask`] and [`Masked`](crate::Masked)).
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Hittable, Interval, Masked, Ray, Sphere};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// const CAMERA: u32 = 1;
    /// const SHADOW: u32 = 2;
    /// // A lamp that shadow rays find but the camera does not see.
    /// let lamp = Masked::new(Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0)?, SHADOW);
    /// let ray = Ray::new(DVec3::ZERO, DVec3::NEG_Z);
    /// assert!(lamp.hit(&ray.with_mask(CAMERA), Interval::FORWARD).is_none());
    /// assert!(lamp.occluded(&ray.with_mask(SHADOW), Interval::FORWARD));
    /// assert!(lamp.hit(&ray, Interval::FORWARD).is_some()); // a ray sees all by default
    /// # Ok(())
    /// # }
    /// ```
    #[inline]
    #[must_use]
    pub const fn with_mask(mut self, mask: u32) -> Self {
        self.mask = mask;
        self
    }

    /// The same ray at `time`.
    #[inline]
    #[must_use]
    pub const fn at_time(mut self, time: f64) -> Self {
        self.time = time;
        self
    }

    /// The point at parameter `t`.
    #[inline]
    #[must_use]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.direction
    }

    /// The same ray with its direction scaled by a power of two, exactly, where its length
    /// is so far from 1 that the arithmetic of a test would over- or underflow
    /// ([`direction_scale`]), and the scale: `t` along `self` is `scale` times `t` along
    /// the scaled ray. `None` for every ordinary ray, which needs no scaling.
    #[inline]
    pub(crate) fn rescaled(&self) -> Option<(Self, f64)> {
        let scale = direction_scale(self.direction);
        (scale != 1.0).then(|| {
            let direction = self.direction * scale;
            (Self { direction, ..*self }, scale)
        })
    }

    /// A `t` found along the [rescaled](Ray::rescaled) ray (with `ray_t` scaled as it
    /// was, by [`Interval::scaled`]) as a `t` along this one: exact, but for one that
    /// underflows, which is rounded up, so that a range ending at it (a search's lowered
    /// `ray_t.max`, `record` asking again) still holds the crossing; `None` where it leaves
    /// f64's range or `ray_t`.
    #[inline]
    pub(crate) fn t_from_rescaled(t: f64, scale: f64, ray_t: Interval) -> Option<f64> {
        let t = scaled_outward(t, scale, false);
        (t.abs() < f64::INFINITY && ray_t.contains(t)).then_some(t)
    }

    /// Whether the ray can be traced: a finite origin and a finite, non-zero direction.
    /// Every `hit` in hitkit returns `None` for a ray that is not.
    #[inline]
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite() && self.direction.is_finite() && self.direction != DVec3::ZERO
    }
}
