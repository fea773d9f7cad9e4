//! A list of hittables as one: the closest hit of a slice or `Vec`.

use alloc::vec::Vec;

use crate::masked::sees;
use crate::record::{Found, Made};
use crate::{Aabb, HitRecord, Hittable, Interval, Ray};

impl<T: Hittable> Hittable for [T] {
    /// Finds the closest crossing with [`Hittable::find`] and builds the record of that one
    /// alone.
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let mut closest: Option<(usize, Found)> = None;
        // Two places for a record made during the search: candidates write the one that
        // does not hold the winner's, so that one that ties and loses (or that made a
        // record and found nothing) does not replace it. (Tried: a fresh `Made` per
        // candidate; it was copied in whole before every call, slower.)
        let mut made = [Made::new(), Made::new()];
        let mut free = 0;
        for (index, object) in self.iter().enumerate() {
            let max = closest.map_or(ray_t.max, |(_, f)| f.t);
            if sees(ray, object)
                && let Some(f) = object.find(ray, Interval::new(ray_t.min, max), &mut made[free])
                // Of hits at exactly the same t, the first object's stands.
                && closest.is_none_or(|(_, c)| f.t < c.t)
            {
                if f.is_made() {
                    free ^= 1;
                }
                closest = Some((index, f));
            }
        }
        let (index, found) = closest?;
        let hit = made[free ^ 1].record(&self[index], ray, ray_t, &found);
        if hit.is_none() {
            // A record that cannot be made (past f64's range) is no hit: ask again, record
            // by record, as the objects' own `hit` would answer.
            return hit_by_records(self, ray, ray_t);
        }
        hit
    }

    fn bounding_box(&self) -> Aabb {
        self.iter()
            .fold(Aabb::EMPTY, |b, o| b.union(&o.bounding_box()))
    }

    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.iter().any(|o| sees(ray, o) && o.occluded(ray, ray_t))
    }
}

/// The closest hit by every object's [`Hittable::hit`].
#[cold]
fn hit_by_records<T: Hittable>(objects: &[T], ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
    let mut closest: Option<HitRecord> = None;
    for object in objects {
        let max = closest.map_or(ray_t.max, |h| h.t);
        if sees(ray, object)
            && let Some(h) = object.hit(ray, Interval::new(ray_t.min, max))
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
