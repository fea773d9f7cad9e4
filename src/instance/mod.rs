//! What [`Transformed`](crate::Transformed) and [`Moving`](crate::Moving) share: the
//! two-step search through an instance, whose object finds its crossing along the ray
//! moved into the object's frame and reports it along the world ray.

mod frame;
mod moving;
mod transformed;

pub use frame::{Affine, Frame, Rigid};
pub use moving::Moving;
pub use transformed::Transformed;

use crate::record::{Found, Made};
use crate::{Aabb, HitRecord, Interval, Ray};

/// The `t` of the object's crossing (along the moved ray) as the instance's: kept within
/// the instance's box span along the whole of `ray`, since moving the ray rounds and can
/// take a crossing just past the box, which holds the object's (so that a `Bvh` of
/// instances finds what a loop finds); then in `ray_t`, so that it does not depend on
/// `ray_t.max`. `clamp_hit` settles most without a slab test.
#[inline]
pub(crate) fn settle(bbox: &Aabb, ray: &Ray, ray_t: Interval, t: f64) -> Option<f64> {
    let t = bbox.clamp_hit(ray, t)?;
    ray_t.contains(t).then_some(t)
}

/// The object's crossing `found` (along the moved ray) as the instance's, its `t`
/// [settled](settle). A record the object made during its search (kept in `made`) is moved
/// to the world now (`to_world`), so that a record kept is always the instance's own; so is
/// the record of a crossing whose `t` had to move (rare), made with `record` and kept.
#[inline]
pub(crate) fn found_in_world(
    found: Found,
    made: &mut Made,
    bbox: &Aabb,
    ray: &Ray,
    ray_t: Interval,
    record: impl FnOnce(&Found) -> Option<HitRecord>,
    to_world: impl FnOnce(HitRecord) -> HitRecord,
) -> Option<Found> {
    let t = settle(bbox, ray, ray_t, found.t)?;
    if found.is_made() {
        let local = made.kept_mut();
        *local = at_t(t, to_world(*local));
        let mut found = found;
        found.t = t;
        return Some(found);
    }
    if t == found.t {
        return Some(found);
    }
    Some(made.keep(at_t(t, to_world(record(&found)?))))
}

/// The record of a crossing that [`found_in_world`] returned and did not make: the
/// object's own (`record`) moved to the world, at the crossing's `t`.
#[inline]
pub(crate) fn record_in_world(
    found: &Found,
    record: impl FnOnce(&Found) -> Option<HitRecord>,
    to_world: impl FnOnce(HitRecord) -> HitRecord,
) -> Option<HitRecord> {
    Some(at_t(found.t, to_world(record(found)?)))
}

/// `record` at the instance's `t` (moving the ray to the object and back rounds it).
#[inline(always)]
fn at_t(t: f64, record: HitRecord) -> HitRecord {
    HitRecord { t, ..record }
}
