//! [`Moving`]: any hittable in linear motion over the rays' times, the book's moving
//! sphere generalized.

use glam::DVec3;

use crate::instance;
use crate::math::gamma;
use crate::record::{Found, Made};
use crate::{Aabb, GeometryError, HitRecord, Hittable, Interval, Ray};

/// `object` moving in a straight line: at time `tau` it is moved by `tau * displacement`,
/// for `tau` the ray's [`time`](Ray::time) clamped to `[0, 1]` (the shutter interval, as in
/// *Ray Tracing: The Next Week*; before and after it the object rests at its ends). Rays
/// are taken back by the same motion and hit the object where it stands, so a moving
/// sphere, mesh instance or whole `Bvh` works alike; the box covers the whole motion.
///
/// Static objects pay nothing for motion elsewhere in a scene: only `Moving` reads a ray's
/// time. A `Moving` is not a [`PdfHittable`](crate::PdfHittable): sampling a light takes no
/// ray, so no time to say where a moving light is.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Hittable, Interval, Moving, Ray, Sphere};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// // The book's bouncing ball: from y = 0 at time 0 to y = 0.5 at time 1.
/// let ball = Moving::new(Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0)?, DVec3::new(0.0, 0.5, 0.0))?;
/// let ray = Ray::new(DVec3::new(0.0, 0.5, 0.0), DVec3::NEG_Z);
/// assert!(ball.hit(&ray, Interval::FORWARD).is_some_and(|h| h.t > 4.1)); // off centre at time 0
/// let later = ball.hit(&ray.at_time(1.0), Interval::FORWARD).unwrap();
/// assert_eq!((later.t, later.time), (4.0, 1.0)); // dead centre at time 1
/// assert!(ball.bounding_box().contains(DVec3::new(0.0, 1.5, -5.0)));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moving<T> {
    object: T,
    displacement: DVec3,
    bbox: Aabb,
    /// Whether the box reaches near f64's end ([`Aabb::near_overflow`]), where moving a hit
    /// can overflow: settled once here, not on every `occluded`.
    near_overflow: bool,
}

impl<T: Hittable> Moving<T> {
    /// `object` moving by `displacement` over times 0 to 1.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite displacement,
    /// [`GeometryError::OutOfRange`] if the motion takes a bounded object past `f64`'s
    /// range.
    pub fn new(object: T, displacement: DVec3) -> Result<Self, GeometryError> {
        if !displacement.is_finite() {
            return Err(GeometryError::NonFinite {
                what: "displacement",
            });
        }
        let start = object.bounding_box();
        let bbox = if start.is_bounded() {
            let (lo, hi) = (start.min(), start.max());
            // `p + tau * displacement` rounds twice: room for it at both ends.
            let room = gamma(2) * (lo.abs().max(hi.abs()) + displacement.abs());
            let end = Aabb {
                min: lo + displacement,
                max: hi + displacement,
            };
            let bbox = start.union(&end).grown(room);
            if !bbox.is_bounded() {
                return Err(GeometryError::OutOfRange);
            }
            bbox
        } else {
            start.union(&Aabb::UNIVERSE)
        };
        Ok(Self {
            object,
            displacement,
            near_overflow: bbox.near_overflow(),
            bbox,
        })
    }
}

impl<T> Moving<T> {
    /// The object, where it is at time 0.
    #[inline]
    #[must_use]
    pub fn object(&self) -> &T {
        &self.object
    }

    /// How far it moves from time 0 to time 1.
    #[inline]
    #[must_use]
    pub fn displacement(&self) -> DVec3 {
        self.displacement
    }

    /// How far it has moved at `time` (clamped to `[0, 1]`; NaN stays NaN, and hits
    /// nothing).
    #[inline]
    #[must_use]
    fn offset_at(&self, time: f64) -> DVec3 {
        time.clamp(0.0, 1.0) * self.displacement
    }
}

impl<T: Hittable> Hittable for Moving<T> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let offset = self.offset_at(ray.time);
        let mut hit = moved(self.object.hit(&back_by(ray, offset), ray_t)?, offset);
        hit.t = instance::settle(&self.bbox, ray, ray_t, hit.t)?;
        (hit.point.is_finite() && hit.point_error.is_finite()).then_some(hit)
    }

    /// The union of the object's box at the start and at the end of its motion, grown by
    /// the rounding of moving it.
    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    /// The object's crossing, found along the ray moved back, with its `t` kept within
    /// this instance's box along `ray`, as `hit` reports it.
    #[inline]
    fn find(&self, ray: &Ray, ray_t: Interval, made: &mut Made) -> Option<Found> {
        // Near f64's end the record can overflow: `hit` decides there.
        if self.near_overflow {
            return self.hit(ray, ray_t).map(|hit| made.keep(hit));
        }
        let offset = self.offset_at(ray.time);
        let local = back_by(ray, offset);
        let found = self.object.find(&local, ray_t, made)?;
        instance::found_in_world(
            found,
            made,
            &self.bbox,
            ray,
            ray_t,
            |f| self.object.record(&local, ray_t, f),
            |h| moved(h, offset),
        )
    }

    #[inline]
    fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
        let offset = self.offset_at(ray.time);
        instance::record_in_world(
            found,
            |f| self.object.record(&back_by(ray, offset), ray_t, f),
            |h| moved(h, offset),
        )
    }

    #[inline]
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        // Near f64's end, moving the hit can overflow, and `hit` then finds nothing.
        if self.near_overflow {
            return self.hit(ray, ray_t).is_some();
        }
        // The box test `hit` makes too, last (see `Transformed`).
        self.object
            .occluded(&back_by(ray, self.offset_at(ray.time)), ray_t)
            && self.bbox.hit(ray, ray_t)
    }
}

/// The object's hit moved by `offset`: the object stands at exactly `object + offset`, and
/// the point moves there with one rounding.
#[inline]
fn moved(mut hit: HitRecord, offset: DVec3) -> HitRecord {
    let point = hit.point + offset;
    hit.point_error += gamma(1) * point.abs();
    hit.point = point;
    hit
}

/// `ray` moved back by `offset`: the ray as the object, at rest at time 0, sees it.
#[inline]
fn back_by(ray: &Ray, offset: DVec3) -> Ray {
    Ray {
        origin: ray.origin - offset,
        ..*ray
    }
}
