//! A list of hittables as one: the closest hit of a slice or `Vec`.

use alloc::vec::Vec;

use crate::{Aabb, Found, HitRecord, Hittable, Interval, Made, Ray};

impl<T: Hittable> Hittable for [T] {
    /// Finds the closest crossing with [`Hittable::find`] and builds the record of that one
    /// alone.
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let mut closest: Option<(usize, Found)> = None;
        // The winner's record where it was made during the search (each candidate gets its
        // own `Made`: one that finds a crossing at exactly the closest `t` loses, and must
        // not replace the winner's).
        let mut kept = Made::new();
        for (index, object) in self.iter().enumerate() {
            let max = closest.map_or(ray_t.max, |(_, f)| f.t);
            let mut made = Made::new();
            if let Some(f) = object.find(ray, Interval::new(ray_t.min, max), &mut made)
                // Of hits at exactly the same t, the first object's stands.
                && closest.is_none_or(|(_, c)| f.t < c.t)
            {
                if f.is_made() {
                    kept = made;
                }
                closest = Some((index, f));
            }
        }
        let (index, found) = closest?;
        // A record that cannot be made (past f64's range) is no hit: ask again, record by
        // record, as the objects' own `hit` would answer.
        kept.record(&self[index], ray, ray_t, &found)
            .or_else(|| hit_by_records(self, ray, ray_t))
    }

    fn bounding_box(&self) -> Aabb {
        self.iter()
            .fold(Aabb::EMPTY, |b, o| b.union(&o.bounding_box()))
    }

    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.iter().any(|o| o.occluded(ray, ray_t))
    }
}

/// The closest hit by every object's [`Hittable::hit`].
#[cold]
fn hit_by_records<T: Hittable>(objects: &[T], ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
    let mut closest: Option<HitRecord> = None;
    for object in objects {
        let max = closest.map_or(ray_t.max, |h| h.t);
        if let Some(h) = object.hit(ray, Interval::new(ray_t.min, max))
            && closest.is_none_or(|c| h.t < c.t)
        {
            closest = Some(h);
        }
    }
    closest
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
