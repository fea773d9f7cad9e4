//! Front-to-back traversal with an explicit stack: no recursion, no allocation.

use glam::DVec3;

use super::{Bvh, MAX_DEPTH, Node};
use crate::aabb::{BoxRay, slab_entry};
use crate::{Hittable, Interval, Ray};

/// Where the ray enters the node's box within `ray_t`, by the crate's one box test.
#[inline(always)]
fn entry(node: &Node, ray: &BoxRay, ray_t: Interval) -> Option<f64> {
    let min = DVec3::new(
        f64::from(node.min[0]),
        f64::from(node.min[1]),
        f64::from(node.min[2]),
    );
    let max = DVec3::new(
        f64::from(node.max[0]),
        f64::from(node.max[1]),
        f64::from(node.max[2]),
    );
    slab_entry(min, max, ray, ray_t)
}

impl<T: Hittable> Bvh<T> {
    /// Offers `visit` the unbounded objects, then every leaf whose box the ray enters
    /// within `[ray_t.min, *t_max]`, nearer child first. `visit` gets a run of objects, the
    /// position of the first in `self.objects`, and `t_max`, which it lowers as it finds
    /// hits (later boxes are culled against it); it returns `true` to stop.
    pub(super) fn walk(
        &self,
        ray: &Ray,
        ray_t: Interval,
        t_max: &mut f64,
        mut visit: impl FnMut(&[T], usize, &mut f64) -> bool,
    ) {
        if !ray.is_valid() {
            return;
        }
        let unbounded = &self.objects[self.bounded..];
        if !unbounded.is_empty() && visit(unbounded, self.bounded, t_max) {
            return;
        }
        if self.bounded == 0 {
            return;
        }
        let ray = BoxRay::new(ray);
        if entry(&self.root, &ray, Interval::new(ray_t.min, *t_max)).is_none() {
            return;
        }
        // At most one entry per level above the current node: the build keeps the depth
        // below MAX_DEPTH.
        let mut stack = [(Node::default(), 0.0f64); MAX_DEPTH];
        let mut pending = 0;
        let mut node = self.root;
        loop {
            if node.count == 0 {
                let [a, b] = self.pairs[node.index as usize].0;
                let range = Interval::new(ray_t.min, *t_max);
                match (entry(&a, &ray, range), entry(&b, &ray, range)) {
                    (Some(ta), Some(tb)) => {
                        let (near, far, t_far) = if ta <= tb { (a, b, tb) } else { (b, a, ta) };
                        stack[pending] = (far, t_far);
                        pending += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = a;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = b;
                        continue;
                    }
                    (None, None) => {}
                }
            } else {
                let first = node.index as usize;
                if visit(
                    &self.objects[first..first + node.count as usize],
                    first,
                    t_max,
                ) {
                    return;
                }
            }
            // The nearest pending node the ray still reaches before t_max.
            loop {
                if pending == 0 {
                    return;
                }
                pending -= 1;
                let (next, t_entry) = stack[pending];
                if t_entry <= *t_max {
                    node = next;
                    break;
                }
            }
        }
    }
}
