//! The two traits every shape implements: [`Hittable`] (what a ray hits) and
//! [`PdfHittable`] (a hittable that can be sampled, the interface of lights), and their
//! forwarding through `Box`, `Arc` and `&`.

use alloc::boxed::Box;
use alloc::sync::Arc;

use glam::{DVec2, DVec3};

use crate::record::{Found, Made};
use crate::{Aabb, Emission, HitRecord, Interval, LightSample, Ray, ShadingContext};

/// Something a ray can hit. Object safe: scenes mix shapes as `Box<dyn Hittable>`.
///
/// Implemented for `Box<T>`, `Arc<T>` and `&T` of any hittable (sized or not), and for
/// `[T]` and `Vec<T>`: the closest hit of the list (of hits at exactly the same `t`, the
/// earlier object's), with the union of the boxes (computed on each call; a
/// [`Bvh`](crate::Bvh) keeps one, and skips most objects).
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Disk, Hittable, Interval, Quad, Ray};
///
/// let shapes: Vec<Box<dyn Hittable>> = vec![
///     Box::new(Quad::new(DVec3::new(0.0, 0.0, -2.0), DVec3::X, DVec3::Y).unwrap()),
///     Box::new(Quad::with_interior(DVec3::new(0.5, 0.5, -1.0), DVec3::X, DVec3::Y, Disk).unwrap()),
/// ];
/// let ray = Ray::new(DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.0, 0.0, -1.0));
/// assert_eq!(shapes.hit(&ray, Interval::FORWARD).unwrap().t, 1.0);
/// assert!(shapes.occluded(&ray, Interval::new(0.0, 1.5)));
/// assert!(!shapes.occluded(&ray, Interval::new(0.0, 0.5)));
/// ```
pub trait Hittable: Send + Sync {
    /// The closest hit with `t` in `ray_t`, or `None`. `None` for an invalid ray
    /// (see [`Ray::is_valid`]).
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord>;

    /// A box containing the whole shape; [`Aabb::UNIVERSE`] (or a box infinite on some
    /// axis) for unbounded shapes.
    fn bounding_box(&self) -> Aabb;

    /// Whether anything is hit with `t` in `ray_t`: the any-hit query for shadow rays.
    /// Containers override it to stop at the first hit found, in any order.
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.hit(ray, ray_t).is_some()
    }

    /// Which rays see the object: those whose [`Ray::mask`] shares a bit with it. Every
    /// bit for an object that does not say (all of hitkit's shapes); a
    /// [`Masked`](crate::Masked) says. A [`Bvh`](crate::Bvh) or a list passes over an
    /// object whose mask does not meet the ray's without asking it anything else.
    #[inline]
    fn mask(&self) -> u32 {
        u32::MAX
    }

    /// The closest crossing with `t` in `ray_t`, without its record: the first half of
    /// [`hit`](Hittable::hit), which a closest-hit search (a list, a [`Bvh`](crate::Bvh))
    /// calls on every candidate, building the record only for the winner with
    /// [`record`](Hittable::record) (pbrt-v4 splits `Intersect` from
    /// `InteractionFromIntersection` for the same reason).
    ///
    /// The two halves must agree with `hit`: `find` is `Some` with `t` exactly when `hit` is
    /// `Some` with that `t`, and the winner's record ([`Made::record`]) is then that hit.
    /// The provided `find` keeps this by calling `hit` once and keeping its record in
    /// `made` ([`Made::keep`]), where the search takes it from: a shape whose record is
    /// costly overrides `find` and `record` both, so that losing candidates never build
    /// one, and leaves `made` alone.
    ///
    /// # What a shape's `hit` may rely on
    /// Every container in hitkit (lists, [`Bvh`](crate::Bvh) and trees nested in trees,
    /// [`Transformed`](crate::Transformed), [`Moving`](crate::Moving), `Box`, `Arc`, `&`)
    /// asks each object once per query: `hit`, or `find` and then `record` for the winner
    /// alone, or `occluded`; never `hit` twice, and never the same subtree twice. So a
    /// shape that implements `hit` alone may answer at random, as the book's constant
    /// medium draws its scattering distance inside `hit`: the distance drawn is the one
    /// reported. (A container may ask again only where the winner's record cannot be made,
    /// its point past `f64`'s range.)
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::custom::Made;
    /// use hitkit::{Hittable, Interval, Quad, Ray};
    ///
    /// let quad = Quad::new(DVec3::new(-1.0, -1.0, 0.0), DVec3::X * 2.0, DVec3::Y * 2.0).unwrap();
    /// let ray = Ray::new(DVec3::new(0.5, 0.0, 2.0), DVec3::NEG_Z);
    /// let mut made = Made::new();
    /// let found = quad.find(&ray, Interval::FORWARD, &mut made).unwrap();
    /// let hit = made.record(&quad, &ray, Interval::FORWARD, &found).unwrap();
    /// assert_eq!(Some(hit), quad.hit(&ray, Interval::FORWARD));
    /// ```
    fn find(&self, ray: &Ray, ray_t: Interval, made: &mut Made) -> Option<Found> {
        self.hit(ray, ray_t).map(|record| made.keep(record))
    }

    /// The record of `found`, which [`find`](Hittable::find) returned for the same `ray`
    /// and `ray_t` (or for `ray_t` with a larger `max`: a search lowers it as it goes),
    /// not [made](Found::is_made) (a made one's record is in the search's [`Made`]:
    /// [`Made::record`] asks this only for the others). `None` only where the record
    /// cannot be made (its point past f64's range).
    ///
    /// The provided one asks `hit` again, up to `found.t`: what a shape that overrides
    /// `find` (to return crossings that are not made) and not `record` gets.
    fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
        self.hit(ray, Interval::new(ray_t.min, found.t))
    }
}

/// A hittable that can be sampled: the interface of lights in a path tracer.
///
/// Object safe: the sample point `u` is a uniform point of `[0, 1)^2`, so any sampler
/// (random, stratified, low-discrepancy) drives it.
///
/// Two levels. [`sample_direction`](PdfHittable::sample_direction) and
/// [`pdf_value`](PdfHittable::pdf_value) are the book's: a direction from a point, and its
/// density; a shape implements these. [`sample_light`](PdfHittable::sample_light) and
/// [`light_pdf`](PdfHittable::light_pdf) are what next-event estimation takes: from a
/// [`ShadingContext`] (a point and its surface's normal), a [`LightSample`] with the
/// light's point, normal and distance, for a shadow ray
/// ([`HitRecord::spawn_ray_to`]) that needs no epsilon. Their provided versions are built
/// on the first two; a light that uses the context's normal (a
/// [`LightTree`](crate::LightTree)) overrides them.
pub trait PdfHittable: Hittable {
    /// The density, over solid angle at `origin`, with which
    /// [`sample_direction`](PdfHittable::sample_direction) picks `direction` (of any
    /// length); 0 where the direction misses the shape. Finite and never NaN.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64;

    /// A unit direction from `origin` toward the shape, drawn from `u` in `[0, 1)^2`
    /// (unit to within rounding, for every light hitkit has); the zero vector where there
    /// is nothing to aim at (an empty list of lights).
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3;

    /// A point on the light seen from `at`, drawn from `u` in `[0, 1)^2`: the direction
    /// toward it, its distance, the light's surface there and the direction's density
    /// ([`light_pdf`](PdfHittable::light_pdf) from `at`). `None` where there is nothing to
    /// sample (see [`LightSample::along`]).
    ///
    /// The provided one draws [`sample_direction`](PdfHittable::sample_direction) from
    /// `at.point` and finds the light's surface along it with
    /// [`light_hit`](PdfHittable::light_hit).
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        LightSample::along(self, at, self.sample_direction(at.point, u))
    }

    /// The density, over solid angle at `at.point`, with which
    /// [`sample_light`](PdfHittable::sample_light) draws `direction` from `at`: what a
    /// renderer weighs a direction its material drew by, in multiple importance sampling.
    /// The provided one is [`pdf_value`](PdfHittable::pdf_value) from `at.point`.
    fn light_pdf(&self, at: &ShadingContext, direction: DVec3) -> f64 {
        self.pdf_value(at.point, direction)
    }

    /// The light's first surface along `ray` within `ray_t`, as
    /// [`sample_light`](PdfHittable::sample_light) finds it, and which of its lights that
    /// is ([`LightSample::light`]): [`hit`](Hittable::hit), but whatever the masks, since
    /// a mask says which rays see a light, not where it is (a lamp hidden from every ray
    /// by [`Masked`](crate::Masked) is found here, under any wrapper or mixture).
    ///
    /// The provided one is `hit`, and light 0: right for a light that holds no `Masked`
    /// and is one light; a light that holds others (a mixture, a tree, a list) gives the
    /// index of the one found, and a wrapper (an instance) forwards what it holds.
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        self.hit(ray, ray_t).map(|hit| (0, hit))
    }

    /// The directions the light emits in, as [`LightTree::from_lights`](crate::LightTree::from_lights)
    /// takes them where the caller does not say: a light that faces away from a point is
    /// not picked there.
    ///
    /// The provided one is [`Emission::Everywhere`] (never ruled out). A
    /// [`Quad`](crate::Quad) of any interior emits from the side its normal `u x v` faces,
    /// as the book's `diffuse_light` emits from front faces only; an instance carries its
    /// object's side into world space (the inverse transpose, which keeps the front face's
    /// side under a mirror); pointers and [`Masked`](crate::Masked) forward it. A light
    /// that shines from both sides is [`Emission::BothSides`], given to
    /// [`LightTree::new`](crate::LightTree::new).
    fn emission(&self) -> Emission {
        Emission::Everywhere
    }
}

/// Forwards both traits through a pointer to `T` (`T` is named by the caller).
macro_rules! forward_through {
    ($pointer:ty) => {
        impl<T: Hittable + ?Sized> Hittable for $pointer {
            #[inline]
            fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
                (**self).hit(ray, ray_t)
            }
            #[inline]
            fn bounding_box(&self) -> Aabb {
                (**self).bounding_box()
            }
            #[inline]
            fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
                (**self).occluded(ray, ray_t)
            }
            #[inline]
            fn find(&self, ray: &Ray, ray_t: Interval, made: &mut Made) -> Option<Found> {
                (**self).find(ray, ray_t, made)
            }
            #[inline]
            fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
                (**self).record(ray, ray_t, found)
            }
            #[inline]
            fn mask(&self) -> u32 {
                (**self).mask()
            }
        }

        impl<T: PdfHittable + ?Sized> PdfHittable for $pointer {
            #[inline]
            fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
                (**self).pdf_value(origin, direction)
            }
            #[inline]
            fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
                (**self).sample_direction(origin, u)
            }
            #[inline]
            fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
                (**self).sample_light(at, u)
            }
            #[inline]
            fn light_pdf(&self, at: &ShadingContext, direction: DVec3) -> f64 {
                (**self).light_pdf(at, direction)
            }
            #[inline]
            fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
                (**self).light_hit(ray, ray_t)
            }
            #[inline]
            fn emission(&self) -> Emission {
                (**self).emission()
            }
        }
    };
}

forward_through!(Box<T>);
forward_through!(Arc<T>);
forward_through!(&T);

// The methods of the values below that ask an object: here, with the traits, so that the
// values (`record.rs`, `sample.rs`) do not depend on them.

impl Made {
    /// The record of `found`, which `object`'s [`find`](crate::Hittable::find) returned
    /// for `ray` and `ray_t` with this `Made` (or for `ray_t` with a larger `max`): the
    /// record kept here where `found` is made, else `object`'s
    /// [`record`](crate::Hittable::record). `None` where the record cannot be made (its
    /// point past f64's range).
    #[inline]
    pub fn record<T: Hittable + ?Sized>(
        &self,
        object: &T,
        ray: &Ray,
        ray_t: Interval,
        found: &Found,
    ) -> Option<HitRecord> {
        if found.is_made() {
            Some(*self.kept())
        } else {
            object.record(ray, ray_t, found)
        }
    }
}

impl LightSample {
    /// The sample along `direction` from `at`: the first surface of `light` there
    /// ([`light_hit`](PdfHittable::light_hit), whatever its masks), and the light's
    /// density of the direction. `None` where the direction finds no surface of
    /// the light (a zero direction, a sample rounding aimed past an edge) or has density 0.
    ///
    /// What [`PdfHittable::sample_light`] returns for a direction its sampler drew; a light
    /// that draws directions its own way (as [`LightTree`](crate::LightTree) does, by the
    /// context's normal) ends with it.
    #[must_use]
    pub fn along<L: PdfHittable + ?Sized>(
        light: &L,
        at: &ShadingContext,
        direction: DVec3,
    ) -> Option<Self> {
        Self::along_with(light, at, direction, |d| light.light_pdf(at, d))
    }

    /// [`LightSample::along`] with the density of the direction (as it is kept) from `pdf`.
    pub(crate) fn along_with<L: PdfHittable + ?Sized>(
        light: &L,
        at: &ShadingContext,
        direction: DVec3,
        pdf: impl FnOnce(DVec3) -> f64,
    ) -> Option<Self> {
        // Unit directions (what hitkit's lights return) are kept bit for bit, so that the
        // density is the one of the very direction the sampler tested to reach the light.
        let length = crate::math::length(direction);
        let direction = if (length - 1.0).abs() <= 4.0 * f64::EPSILON {
            direction
        } else {
            direction / length
        };
        let ray = Ray::new(at.point, direction);
        if !ray.is_valid() {
            return None;
        }
        let (light, record) = light.light_hit(&ray, Interval::FORWARD)?;
        let pdf = pdf(direction);
        let distance = record.t;
        (pdf > 0.0 && pdf.is_finite() && distance.is_finite()).then_some(Self {
            direction,
            distance,
            record,
            pdf,
            light,
            delta: false,
        })
    }
}
