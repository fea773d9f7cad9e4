use alloc::boxed::Box;
use alloc::sync::Arc;
use alloc::vec::Vec;

use glam::{DVec2, DVec3};

use crate::{Aabb, Interval, Ray};

/// Names a material. The library carries the id from shape to hit record; the renderer
/// owns the materials and decides what an id means (an index into its own table, say).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct MaterialId(pub u32);

/// Where a ray met a surface.
///
/// `normal` is unit length and faces against the ray; `front_face` says whether the ray
/// came from the side the shape's outward normal points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    /// Ray parameter of the hit, in units of the ray's direction.
    pub t: f64,
    /// The hit point.
    pub point: DVec3,
    /// A bound on the absolute error of each coordinate of `point`: the exact surface
    /// point lies within `point ± point_error`. [`HitRecord::spawn_ray`] uses it.
    pub point_error: DVec3,
    /// Unit surface normal, facing against the incoming ray.
    pub normal: DVec3,
    /// Whether the ray hit the side the outward normal points to.
    pub front_face: bool,
    /// Surface coordinates; each shape documents its mapping.
    pub uv: DVec2,
    /// The material of the shape that was hit.
    pub material: MaterialId,
}

impl HitRecord {
    /// A record whose `normal` and `front_face` are set from the shape's unit
    /// `outward_normal` and the ray's direction.
    #[inline]
    #[must_use]
    pub fn new(
        ray: &Ray,
        t: f64,
        point: DVec3,
        point_error: DVec3,
        outward_normal: DVec3,
        uv: DVec2,
        material: MaterialId,
    ) -> Self {
        let front_face = ray.direction.dot(outward_normal) < 0.0;
        let normal = if front_face {
            outward_normal
        } else {
            -outward_normal
        };
        Self {
            t,
            point,
            point_error,
            normal,
            front_face,
            uv,
            material,
        }
    }

    /// A ray leaving the hit point along `direction` that does not hit the same surface
    /// again at `t >= 0`, with no epsilon on the renderer's side: trace it with
    /// `Interval::new(0.0, f64::INFINITY)`.
    ///
    /// The origin is moved off the surface, to the side `direction` points to, by the
    /// point's error bound projected on the normal, then rounded one more float away
    /// (pbrt-v4's `OffsetRayOrigin`).
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Hittable, Interval, Quad, Ray};
    /// let floor = Quad::new(DVec3::new(-1e9, 0.0, -1e9), DVec3::X * 2e9, DVec3::Z * 2e9).unwrap();
    /// let down = Ray::new(DVec3::new(1e8 + 0.3, 1.0, 0.7), DVec3::new(0.3, -1.0, 0.1));
    /// let hit = floor.hit(&down, Interval::new(0.0, f64::INFINITY)).unwrap();
    /// let bounce = hit.spawn_ray(DVec3::new(0.2, 1.0, 0.0));
    /// assert!(floor.hit(&bounce, Interval::new(0.0, f64::INFINITY)).is_none());
    /// ```
    #[inline]
    #[must_use]
    pub fn spawn_ray(&self, direction: DVec3) -> Ray {
        let toward = if direction.dot(self.normal) < 0.0 {
            -self.normal
        } else {
            self.normal
        };
        // Near the end of f64's range the bound itself overflows; the largest finite offset
        // then keeps `0 * inf` (a zero normal component) from making the origin NaN.
        let offset = self.normal.abs().dot(self.point_error).min(f64::MAX);
        let mut origin = self.point + offset * toward;
        // One more float away along every axis the normal has a component on, so that the
        // origin leaves the surface even where the error bound is zero.
        for axis in 0..3 {
            if toward[axis] > 0.0 {
                origin[axis] = origin[axis].next_up();
            } else if toward[axis] < 0.0 {
                origin[axis] = origin[axis].next_down();
            }
        }
        // Near the end of the range, the origin stays finite (at the end of it).
        Ray::new(
            origin.clamp(DVec3::splat(f64::MIN), DVec3::splat(f64::MAX)),
            direction,
        )
    }
}

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
/// assert_eq!(shapes.hit(&ray, Interval::new(0.0, f64::INFINITY)).unwrap().t, 1.0);
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
}

/// A hittable that can be sampled: the interface of lights in a path tracer.
///
/// Object safe: the sample point `u` is a uniform point of `[0, 1)^2`, so any sampler
/// (random, stratified, low-discrepancy) drives it.
pub trait PdfHittable: Hittable {
    /// The density, over solid angle at `origin`, with which
    /// [`sample_direction`](PdfHittable::sample_direction) picks `direction`; 0 where the
    /// direction misses the shape. Finite and never NaN.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64;

    /// A direction from `origin` toward the shape, drawn from `u` in `[0, 1)^2`.
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3;
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
        }
    };
}

forward_through!(Box<T>);
forward_through!(Arc<T>);
forward_through!(&T);

impl<T: Hittable> Hittable for [T] {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let mut closest: Option<HitRecord> = None;
        for object in self {
            let max = closest.map_or(ray_t.max, |h| h.t);
            if let Some(h) = object.hit(ray, Interval::new(ray_t.min, max)) {
                // Of hits at exactly the same t, the first object's stands.
                if closest.is_none_or(|c| h.t < c.t) {
                    closest = Some(h);
                }
            }
        }
        closest
    }

    fn bounding_box(&self) -> Aabb {
        self.iter()
            .fold(Aabb::EMPTY, |b, o| b.union(&o.bounding_box()))
    }

    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.iter().any(|o| o.occluded(ray, ray_t))
    }
}

/// A uniform mixture of lights: `sample_direction` picks one with probability `1 / n` (by
/// `u.x`, whose remaining digits are reused for the light's own sample, so one point of
/// `[0, 1)^2` still makes one direction), and `pdf_value` is the mean of their densities,
/// which is the mixture's density. An empty list has density 0 everywhere and samples
/// the zero direction, which hits nothing.
impl<T: PdfHittable> PdfHittable for [T] {
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        // Each density divided first: the sum of the quotients cannot overflow, as the sum
        // of densities near f64::MAX can.
        let n = self.len() as f64;
        self.iter()
            .map(|light| light.pdf_value(origin, direction) / n)
            .sum::<f64>()
    }

    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        let Some(last) = self.len().checked_sub(1) else {
            return DVec3::ZERO;
        };
        let scaled = u.x.clamp(0.0, 1.0) * self.len() as f64;
        let index = (scaled as usize).min(last);
        let rest = DVec2::new((scaled - index as f64).clamp(0.0, 1.0), u.y);
        self[index].sample_direction(origin, rest)
    }
}

impl<T: PdfHittable> PdfHittable for Vec<T> {
    #[inline]
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.as_slice().pdf_value(origin, direction)
    }
    #[inline]
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.as_slice().sample_direction(origin, u)
    }
}

impl<T: Hittable> Hittable for Vec<T> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.as_slice().hit(ray, ray_t)
    }
    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.as_slice().bounding_box()
    }
    #[inline]
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.as_slice().occluded(ray, ray_t)
    }
}
