//! A list of hittables as one: the closest hit of a slice or `Vec`.

use alloc::vec::Vec;

use crate::{Aabb, HitRecord, Hittable, Interval, Ray};

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
