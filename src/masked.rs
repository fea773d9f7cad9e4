//! [`Masked`]: an object seen only by rays whose mask meets its own (visibility flags).

use glam::{DVec2, DVec3};

use crate::record::{Found, Made};
use crate::{Aabb, HitRecord, Hittable, Interval, LightSample, PdfHittable, Ray, ShadingContext};

/// `object`, seen only by rays whose [`mask`](Ray::mask) shares a bit with `mask`: a lamp
/// that shadow rays find and the camera does not, an object that casts no shadow, a
/// portal that only bounce rays see (Embree's ray masks, pbrt's and Cycles's visibility
/// settings). A [`Bvh`](crate::Bvh) or a list passes over it without a test where the
/// masks do not meet; so does it on its own. Sampling it as a light is unaffected: a
/// lamp invisible to the camera still lights the scene.
///
/// Inside, the ray's mask is narrowed to `mask`'s bits, so that masks nested through any
/// wrapper or container mean their AND: an object inside `Masked`s (of it, or of a tree or
/// an instance holding it) is seen by the rays whose mask shares a bit with all of them
/// together, whether asked directly or through a list or a [`Bvh`](crate::Bvh).
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Bvh, Hittable, Interval, Masked, Ray, Sphere};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// const CAMERA: u32 = 1 << 0;
/// const SHADOW: u32 = 1 << 1;
/// let scene: Bvh<Masked<Sphere>> = Bvh::new(vec![
///     // A ball that casts no shadow, in front of one that does.
///     Masked::new(Sphere::new(DVec3::new(0.0, 0.0, -3.0), 1.0)?, CAMERA),
///     Masked::new(Sphere::new(DVec3::new(0.0, 0.0, -8.0), 1.0)?, CAMERA | SHADOW),
/// ]);
/// let ray = Ray::new(DVec3::ZERO, DVec3::NEG_Z);
/// assert_eq!(scene.hit(&ray.with_mask(CAMERA), Interval::FORWARD).unwrap().t, 2.0);
/// assert_eq!(scene.hit(&ray.with_mask(SHADOW), Interval::FORWARD).unwrap().t, 7.0);
/// assert!(!scene.occluded(&ray.with_mask(SHADOW), Interval::new(0.0, 5.0)));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Masked<T> {
    object: T,
    mask: u32,
}

impl<T> Masked<T> {
    /// `object`, seen by rays whose mask shares a bit with `mask` (none, for `mask` 0).
    #[inline]
    #[must_use]
    pub const fn new(object: T, mask: u32) -> Self {
        Self { object, mask }
    }

    /// The object.
    #[inline]
    #[must_use]
    pub fn object(&self) -> &T {
        &self.object
    }
}

/// Whether `ray` sees `object`: always for a ray that sees everything (the default), so
/// that an object's mask is asked of only where a renderer uses masks.
#[inline(always)]
pub(crate) fn sees<T: Hittable + ?Sized>(ray: &Ray, object: &T) -> bool {
    ray.mask == u32::MAX || ray.mask & object.mask() != 0
}

impl<T> Masked<T> {
    /// The ray as the object sees it: its mask narrowed to this one's bits; `None` where
    /// none are left.
    #[inline(always)]
    fn narrowed(&self, ray: &Ray) -> Option<Ray> {
        let mask = ray.mask & self.mask;
        (mask != 0).then(|| ray.with_mask(mask))
    }
}

impl<T: Hittable> Hittable for Masked<T> {
    /// The record carries the mask the ray came with, not the narrowed one: rays spawned
    /// from it see what the ray saw.
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let record = self.object.hit(&self.narrowed(ray)?, ray_t)?;
        Some(HitRecord {
            mask: ray.mask,
            ..record
        })
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.object.bounding_box()
    }

    #[inline]
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.narrowed(ray)
            .is_some_and(|ray| self.object.occluded(&ray, ray_t))
    }

    #[inline]
    fn find(&self, ray: &Ray, ray_t: Interval, made: &mut Made) -> Option<Found> {
        let found = self.object.find(&self.narrowed(ray)?, ray_t, made)?;
        if found.is_made() {
            made.kept_mut().mask = ray.mask;
        }
        Some(found)
    }

    #[inline]
    fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
        let record = self.object.record(&self.narrowed(ray)?, ray_t, found)?;
        Some(HitRecord {
            mask: ray.mask,
            ..record
        })
    }

    /// The mask given and the object's own, together (their AND): the rays that see it
    /// are those whose mask meets it, as [`hit`](Hittable::hit) finds.
    #[inline]
    fn mask(&self) -> u32 {
        self.mask & self.object.mask()
    }
}

/// The object's sampling, unchanged: a light's mask says which rays see it, not whether it
/// lights the scene.
impl<T: PdfHittable> PdfHittable for Masked<T> {
    #[inline]
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.object.pdf_value(origin, direction)
    }
    #[inline]
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.object.sample_direction(origin, u)
    }
    #[inline]
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        self.object.sample_light(at, u)
    }
    #[inline]
    fn light_pdf(&self, at: &ShadingContext, direction: DVec3) -> f64 {
        self.object.light_pdf(at, direction)
    }
    #[inline]
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        self.object.light_hit(ray, ray_t)
    }
    #[inline]
    fn emission(&self) -> crate::Emission {
        self.object.emission()
    }
}
