//! Front-to-back traversal with an explicit stack: no recursion, no allocation.

use super::{Bvh, MAX_DEPTH, Pair, Tree};
use crate::aabb::{BoxRay, slab_spans};
use crate::{Hittable, Interval, Ray};

/// Where the ray enters each of the two siblings within `ray_t` (`+inf`: it misses), by
/// the crate's one box test, on the world-space bounds `origin + offset` (in `f64`, as the
/// build rounded them): every shape's own box test on the same ray runs the same
/// arithmetic on a box inside these, so a node never misses a ray its shapes' boxes take.
#[inline(always)]
fn entries(pair: &Pair, origin: &[f64; 3], ray: &BoxRay, ray_t: Interval) -> [f64; 2] {
    let world =
        |axes: &[[f32; 2]; 3]| core::array::from_fn(|k| axes[k].map(|f| origin[k] + f64::from(f)));
    slab_spans(world(&pair.min), world(&pair.max), ray, ray_t).0
}

impl<T: Hittable> Bvh<T> {
    /// Offers `visit` the unbounded objects, then every leaf whose box the ray enters
    /// within `[ray_t.min, *t_max]`, nearer child first. `visit` gets a run of objects, the
    /// position of the first in `self.objects`, and `t_max`, which it lowers as it finds
    /// hits (later boxes are culled against it); it returns `true` to stop.
    #[inline]
    pub(super) fn walk(
        &self,
        ray: &Ray,
        ray_t: Interval,
        t_max: &mut f64,
        mut visit: impl FnMut(&[T], usize, &mut f64) -> bool,
    ) {
        let objects = &self.objects;
        self.tree.walk(ray, ray_t, t_max, |first, count, t_max| {
            visit(&objects[first..first + count], first, t_max)
        });
    }
}

impl Tree {
    /// Offers `visit` the unbounded objects, then every leaf whose box the ray enters
    /// within `[ray_t.min, *t_max]`, nearer child first, as a run of positions in the
    /// tree's order (first, count); `visit` lowers `t_max` as it finds hits (later boxes
    /// are culled against it) and returns `true` to stop.
    pub(crate) fn walk(
        &self,
        ray: &Ray,
        ray_t: Interval,
        t_max: &mut f64,
        mut visit: impl FnMut(usize, usize, &mut f64) -> bool,
    ) {
        if !ray.is_valid() {
            return;
        }
        let unbounded = self.order.len() - self.bounded;
        if unbounded != 0 && visit(self.bounded, unbounded, t_max) {
            return;
        }
        if self.pairs.is_empty() {
            return;
        }
        let ray = BoxRay::new(ray);
        let origin = self.origin.to_array();
        // Pending nodes as (index, count, entry distance); at most one per level above the
        // current node, and the build keeps the depth below MAX_DEPTH.
        let mut stack = [(0u32, 0u32, 0.0f64); MAX_DEPTH];
        let mut pending = 0;
        // The root is child 0 of pair 0 (beside an empty box): start as its parent would.
        let (mut index, mut count) = (0u32, 0u32);
        loop {
            if count == 0 {
                let pair = &self.pairs[index as usize];
                let [ta, tb] = entries(pair, &origin, &ray, Interval::new(ray_t.min, *t_max));
                let (a, b) = (
                    (pair.index[0], pair.count[0]),
                    (pair.index[1], pair.count[1]),
                );
                match (ta < f64::INFINITY, tb < f64::INFINITY) {
                    (true, true) => {
                        let (near, far, t_far) = if ta <= tb { (a, b, tb) } else { (b, a, ta) };
                        stack[pending] = (far.0, far.1, t_far);
                        pending += 1;
                        (index, count) = near;
                        continue;
                    }
                    (true, false) => {
                        (index, count) = a;
                        continue;
                    }
                    (false, true) => {
                        (index, count) = b;
                        continue;
                    }
                    (false, false) => {}
                }
            } else if visit(index as usize, count as usize, t_max) {
                return;
            }
            // The nearest pending node the ray still reaches before t_max.
            loop {
                if pending == 0 {
                    return;
                }
                pending -= 1;
                let (i, c, t_entry) = stack[pending];
                if t_entry <= *t_max {
                    (index, count) = (i, c);
                    break;
                }
            }
        }
    }
}
