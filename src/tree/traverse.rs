//! Front-to-back traversal with an explicit stack: no recursion, no allocation.
//!
//! A node's eight boxes are tested together, in `f32` lanes ([`Lanes`]) where the ray and the
//! tree allow it and in `f64` otherwise ([`entries`]); both are conservative against the
//! crate's one box test, so that a node never misses a ray its shapes' boxes take.

use super::node::Node;
use super::{MAX_DEPTH, Tally, Tree, WIDTH};
use glam::{DVec3, Vec3};

use crate::aabb::{BoxRay, slab_spans};
use crate::{Interval, Ray};

/// Where the ray enters each child within `ray_t` (`+inf`: it misses), by the crate's one
/// box test, on the world-space bounds `origin + offset` (in `f64`, as the build rounded
/// them): every shape's own box test on the same ray runs the same arithmetic on a box
/// inside these, so a node never misses a ray its shapes' boxes take. The reference the
/// `f32` lanes are held to, and the test for rays they cannot take.
#[inline(always)]
fn entries(node: &Node, origin: &[f64; 3], ray: &BoxRay, ray_t: Interval) -> [f64; WIDTH] {
    let world = |bounds: &[[f32; WIDTH]]| {
        core::array::from_fn(|k| bounds[k].map(|f| origin[k] + f64::from(f)))
    };
    slab_spans(
        world(&node.bounds[..3]),
        world(&node.bounds[3..]),
        ray,
        ray_t,
    )
    .0
}

/// How far each `f32` distance is moved outward, relative to itself: the test's own
/// rounding (the difference, the product, the reciprocal's rounding to `f32`: three
/// roundings of `2^-24`) and the `f64` test's (a few of `2^-53`, and its far distance's
/// padding), with room to spare.
const RHO: f32 = 1.0 / (1u32 << 20) as f32;
/// And absolutely: a distance that underflows errs by up to the smallest subnormal.
const SIGMA: f32 = f32::MIN_POSITIVE;

/// A ray set up for the `f32` test of a node's eight boxes, which never rejects a box that
/// [`entries`] (the `f64` test on the same bounds) accepts, and never reports it entered
/// later: so the tree still answers as the loop over its objects (the contract's clause 3).
///
/// Per axis, the distance to a bound is `(bound - origin) * inv` in `f32`, with the ray's
/// origin relative to the tree's `origin` rounded *toward* the bound for near distances and
/// away from it for far ones, after being moved by the rounding of the `f64` test's world
/// bounds (`Tree::rounding`): the difference is then at most (at least) the one the `f64`
/// test takes, exactly. What remains are relative errors, a few `2^-24` here and `2^-53`
/// there, which the entry and exit absorb by moving outward by `RHO` of themselves, and
/// underflow, by `SIGMA`. The lanes are taken only where nothing overflows: bounds within
/// `2^60` of the tree's origin, a ray origin within `2^62` of it, and every `|1 / d|` within
/// `[2^-62, 2^62]` (or infinite, a zero component, whose distances are `±inf` or NaN in
/// both tests alike), so that every distance stays below `2^125`.
///
/// A NaN distance (a ray parallel to a slab, from exactly its plane) is ignored by both
/// tests' `max`/`min`; an unused lane's empty box gives an infinite entry, and a NaN bound,
/// which no comparison passes.
struct Lanes {
    /// Per axis: the index into `Node::bounds` of the near bound, and of the far one.
    near: [usize; 3],
    far: [usize; 3],
    /// The origin relative to the tree's, rounded for the near bounds and for the far ones,
    /// and the reciprocal direction.
    origin_near: [f32; 3],
    origin_far: [f32; 3],
    inv: [f32; 3],
    /// `ray_t.min`, rounded down to `f32`.
    lo: f32,
}

/// Stack sizes: for trees of depth up to 12, and for every tree the build makes
/// (`MAX_DEPTH` levels at most). (Tried: a third, for trees of depth 2; slower on the
/// Cornell box.)
const SHALLOW: usize = (WIDTH - 1) * 12;
const DEEP: usize = (WIDTH - 1) * MAX_DEPTH;

/// Limits within which the `f32` distances cannot overflow (see [`Lanes`]).
const ORIGIN_LIMIT: f64 = (1u64 << 62) as f64;
const INV_LIMIT: f64 = (1u64 << 62) as f64;

/// A box test of a node's children: (lower bounds on) where the ray enters each within
/// `[ray_t.min, t_max]` (`+inf` where it misses).
trait Entries {
    fn entries(&self, node: &Node, t_max: f64) -> [f32; WIDTH];
}

/// The `f64` test ([`entries`]) for rays the lanes cannot take.
struct Reference {
    origin: [f64; 3],
    ray: BoxRay,
    min: f64,
}

impl Entries for Reference {
    /// Entries rounded down: still lower bounds (`f32::MAX` for one past `f32`'s range).
    #[inline(always)]
    fn entries(&self, node: &Node, t_max: f64) -> [f32; WIDTH] {
        entries(
            node,
            &self.origin,
            &self.ray,
            Interval::new(self.min, t_max),
        )
        .map(|t| {
            if t < f64::INFINITY {
                down(DVec3::splat(t)).x.min(f32::MAX)
            } else {
                f32::INFINITY
            }
        })
    }
}

impl Entries for Lanes {
    #[inline(always)]
    fn entries(&self, node: &Node, t_max: f64) -> [f32; WIDTH] {
        self.entries(node, t_max)
    }
}

impl Lanes {
    /// The ray's lanes, or `None` where it or the tree is past the limits, or `ray_t` has a
    /// NaN end.
    #[inline(always)]
    fn new(tree: &Tree, ray: &Ray, box_ray: &BoxRay, ray_t: Interval) -> Option<Self> {
        let inv = box_ray.inv_direction;
        let relative = ray.origin - tree.origin;
        let magnitude = inv.abs();
        let inv_ok = magnitude.cmpeq(DVec3::INFINITY)
            | (magnitude.cmpge(DVec3::splat(1.0 / INV_LIMIT))
                & magnitude.cmple(DVec3::splat(INV_LIMIT)));
        // (A NaN relative origin fails the comparison.)
        let origin_ok = relative.abs().cmple(DVec3::splat(ORIGIN_LIMIT));
        if !(tree.compact && inv_ok.all() && origin_ok.all())
            || ray_t.min.is_nan()
            || ray_t.max.is_nan()
        {
            return None;
        }
        // The f64 test's bounds round by up to `rounding`, and `relative` by an ulp of
        // itself; twice both covers them and the rounding of these sums.
        let slack = 2.0 * (DVec3::from(tree.rounding) + relative.abs() * f64::EPSILON);
        let (above, below) = (up(relative + slack), down(relative - slack));
        let mut lanes = Self {
            near: [0; 3],
            far: [0; 3],
            origin_near: [0.0; 3],
            origin_far: [0.0; 3],
            inv: [0.0; 3],
            lo: down(DVec3::splat(ray_t.min.max(-f64::from(f32::MAX)))).x,
        };
        // A start at zero or after is kept at zero or after: rounded down it would be a
        // step below zero, which every box the ray starts in would carry into its entry
        // and the padding of it, and the step's magnitude would be all the entry has.
        if ray_t.min >= 0.0 {
            lanes.lo = lanes.lo.max(0.0);
        }
        for axis in 0..3 {
            // Toward the bound: a near distance no larger than the f64 test's, a far one
            // no smaller.
            let (near, far, origin_near, origin_far) = if box_ray.negative[axis] {
                (3 + axis, axis, below[axis], above[axis])
            } else {
                (axis, 3 + axis, above[axis], below[axis])
            };
            lanes.near[axis] = near;
            lanes.far[axis] = far;
            lanes.origin_near[axis] = origin_near;
            lanes.origin_far[axis] = origin_far;
            lanes.inv[axis] = inv[axis] as f32;
        }
        Some(lanes)
    }

    /// Lower bounds on where the ray enters each child within `[ray_t.min, t_max]` as the
    /// `f64` test finds it (`+inf`: not even the widened test is passed).
    #[inline(always)]
    fn entries(&self, node: &Node, t_max: f64) -> [f32; WIDTH] {
        let hi = up(DVec3::splat(t_max.min(f64::from(f32::MAX)))).x;
        let (mut t0, mut t1) = ([self.lo; WIDTH], [hi; WIDTH]);
        for axis in 0..3 {
            let near = &node.bounds[self.near[axis]];
            let far = &node.bounds[self.far[axis]];
            // Lane by lane, in loops the compiler turns into one instruction per step for
            // all eight lanes (two with SSE alone).
            for k in 0..WIDTH {
                let a = (near[k] - self.origin_near[axis]) * self.inv[axis];
                let b = (far[k] - self.origin_far[axis]) * self.inv[axis];
                // A NaN distance is ignored, as in the f64 test: `x.max(y)` is `y` when `x`
                // is NaN (and `t0`, `t1` never are). (Tried: `if a > t0 { a } else { t0 }`,
                // SSE's own `max`, one instruction where this takes three: within noise.)
                t0[k] = a.max(t0[k]);
                t1[k] = b.min(t1[k]);
            }
        }
        let mut entries = [0.0; WIDTH];
        for k in 0..WIDTH {
            let entry = t0[k] - t0[k].abs() * RHO - SIGMA;
            let exit = t1[k] + t1[k].abs() * RHO + SIGMA;
            entries[k] = if entry <= exit { entry } else { f32::INFINITY };
        }
        entries
    }
}

/// An `f32` at or above each coordinate of `x` (finite, or past `f32`'s range): `x` grown
/// by more than half an `f32` ulp before rounding to nearest, branch-free.
#[inline(always)]
fn up(x: DVec3) -> Vec3 {
    (x + x.abs() * f64::from(f32::EPSILON) + DVec3::splat(STEP)).as_vec3()
}

/// As [`up`], at or below.
#[inline(always)]
fn down(x: DVec3) -> Vec3 {
    (x - x.abs() * f64::from(f32::EPSILON) - DVec3::splat(STEP)).as_vec3()
}

/// The absolute part of [`up`]'s and [`down`]'s step: more than half an ulp of the
/// subnormals, and a normal number, so that a value near zero steps past the subnormals
/// rather than into them (where every lane computed from it would be slow, and read as
/// zero with the CPU's denormals-are-zero mode on). Stepping toward zero from a negative
/// value can still end among them; read as zero, such a value is still on the right side.
const STEP: f64 = f32::MIN_POSITIVE as f64;

/// Bit `k` set where the ray enters child `k` (`t[k]` finite): a comparison and a mask
/// per four lanes, through the `wide` crate (SSE's `cmpltps` and `movmskps`; in the AVX2 path, two
/// comparisons and one mask). (Tried: a loop of `m | (t[k] < inf) << k`, which LLVM
/// compiles to scalar instructions, one per lane and more.)
#[inline(always)]
fn entered_bits(t: &[f32; WIDTH]) -> u32 {
    let infinite = wide::f32x4::splat(f32::INFINITY);
    let mut bits = 0;
    for (i, lanes) in t.chunks_exact(4).enumerate() {
        let lanes = wide::f32x4::from([lanes[0], lanes[1], lanes[2], lanes[3]]);
        bits |= (wide::CmpLt::cmp_lt(lanes, infinite).move_mask() as u32) << (4 * i);
    }
    bits
}

impl Tree {
    /// Offers `visit` the unbounded objects, then every leaf whose box the ray enters
    /// within `[ray_t.min, *t_max]`, as a run of positions in the tree's order (first,
    /// count); `visit` lowers `t_max` as it finds hits (later boxes are culled against it)
    /// and returns `true` to stop. `tally` counts the nodes.
    ///
    /// With `NEAREST`, the nearer child first: what finds a closest hit soonest, and lets
    /// it cull the most. Without, in the node's order: for a query that stops at any hit
    /// or sums them all, where sorting the children is work for nothing.
    #[inline(always)]
    pub(crate) fn walk<const NEAREST: bool>(
        &self,
        ray: &Ray,
        ray_t: Interval,
        t_max: &mut f64,
        tally: &mut impl Tally,
        mut visit: impl FnMut(usize, usize, &mut f64) -> bool,
    ) {
        if !ray.is_valid() {
            return;
        }
        let unbounded = self.order.len() - self.bounded;
        if unbounded != 0 && visit(self.bounded, unbounded, t_max) {
            return;
        }
        if self.nodes.is_empty() {
            return;
        }
        // The boxes are tested along the direction scaled by a power of two (exactly), so
        // that a direction of any length f64 holds has finite reciprocals and distances
        // within the lanes' range; `t_max`, along the ray's own direction, is converted
        // as it is lowered.
        let box_ray = BoxRay::new(ray);
        let scaled_t = box_ray.scaled_range(ray_t);
        // The stack is cleared on every walk, which costs as much as a node visit or two
        // at the deepest size: a smaller one where the tree allows, for the rays the lanes
        // take (all but rays past their limits, which take the deepest).
        let pending = (WIDTH - 1) * self.depth;
        match Lanes::new(self, ray, &box_ray, scaled_t) {
            Some(lanes) if pending <= SHALLOW => {
                self.descend::<SHALLOW, NEAREST>(t_max, tally, visit, &lanes, &box_ray);
            }
            Some(lanes) => self.descend::<DEEP, NEAREST>(t_max, tally, visit, &lanes, &box_ray),
            None => {
                let reference = Reference {
                    origin: self.origin.to_array(),
                    ray: box_ray,
                    min: scaled_t.min,
                };
                self.descend::<DEEP, NEAREST>(t_max, tally, visit, &reference, &box_ray);
            }
        }
    }

    /// The walk itself, with `test` giving (lower bounds on) where the ray enters each
    /// child of a node before `t_max` (`+inf` where it misses), in the units of
    /// `box_ray`'s scaled direction.
    #[inline(always)]
    fn descend<const STACK: usize, const NEAREST: bool>(
        &self,
        t_max: &mut f64,
        tally: &mut impl Tally,
        mut visit: impl FnMut(usize, usize, &mut f64) -> bool,
        test: &impl Entries,
        box_ray: &BoxRay,
    ) {
        // Pending nodes as (index, count, entry distance): at most WIDTH - 1 per level
        // above the current node, `self.depth` levels at most.
        let mut stack = [(0u32, 0u32, 0.0f32); STACK];
        let mut pending = 0;
        let (mut index, mut count) = (0u32, 0u32);
        // `t_max` in the boxes' units.
        let mut limit = box_ray.scaled_max(*t_max);
        loop {
            if count == 0 {
                let node = &self.nodes[index as usize];
                tally.node();
                let t = test.entries(node, limit);
                // The children entered, as bits, visited lowest first.
                let mut bits = entered_bits(&t);
                // Nearest first where asked (an insertion sort of at most eight). (Tried: a
                // branch-free sorting network on keys that order as the distances do;
                // slower on primary rays, no faster on bounces. For any hit, farthest first,
                // or the boxes the ray starts in last: fewer face tests on blocked shadow
                // rays, no faster.)
                let mut entered = [(0.0f32, 0u32, 0u32); WIDTH];
                let mut n = 0;
                while bits != 0 {
                    let k = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let t = t[k];
                    let mut at = n;
                    while NEAREST && at > 0 && entered[at - 1].0 > t {
                        entered[at] = entered[at - 1];
                        at -= 1;
                    }
                    entered[at] = (t, node.index[k], node.count[k]);
                    n += 1;
                }
                if n > 0 {
                    for &(t_entry, i, c) in entered[1..n].iter().rev() {
                        stack[pending] = (i, c, t_entry);
                        pending += 1;
                    }
                    (index, count) = (entered[0].1, entered[0].2);
                    continue;
                }
            } else if visit(index as usize, count as usize, t_max) {
                return;
            } else {
                limit = box_ray.scaled_max(*t_max);
            }
            // The nearest pending node the ray still reaches before t_max.
            loop {
                if pending == 0 {
                    return;
                }
                pending -= 1;
                let (i, c, t_entry) = stack[pending];
                if f64::from(t_entry) <= limit {
                    (index, count) = (i, c);
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{BoxRay, Lanes, Tree, entries};
    use crate::tree::Shape;
    use crate::{Aabb, Interval, Ray};
    use glam::DVec3;
    use proptest::prelude::*;

    /// A coordinate of a direction: zeros of both signs, and magnitudes from 1e-20 to 1e20
    /// (past the lanes' limits at both ends, where the f64 test takes over).
    fn component() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(0.0),
            Just(-0.0),
            (-20i32..=20, -1.0f64..1.0).prop_map(|(e, m)| m * 10f64.powi(e)),
            -1.0f64..1.0,
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// The `f32` lanes never reject a child the `f64` test accepts, nor put its entry
        /// later, for every node of trees of boxes from 1e-6 to 1e6 wide at offsets up to
        /// 1e12 (built there, or built elsewhere and refitted), and rays from inside, beside (on a box's own bound, parallel to it) and
        /// far away, with directions of every size and with zero components.
        #[test]
        fn lanes_are_conservative_against_the_f64_test(
            offset in prop_oneof![Just(0.0), Just(1e6), Just(1e9), Just(1e12), Just(-3.7e10)],
            boxes in prop::collection::vec(
                (prop::array::uniform3(-1.0f64..1.0), prop::array::uniform3(-6i32..=6)),
                1..40,
            ),
            scale in -3i32..=3,
            on_bound in any::<bool>(),
            pick in any::<prop::sample::Index>(),
            from in prop::array::uniform3(-2.0f64..2.0),
            far in prop_oneof![Just(1.0), Just(1e3), Just(1e9)],
            direction in prop::array::uniform3(component()),
            t_min in prop_oneof![Just(0.0), Just(f64::NEG_INFINITY), Just(-1.0), 0.0f64..1.0],
            t_max in prop_oneof![Just(f64::INFINITY), 0.0f64..10.0, Just(1e30)],
            built_at in prop::option::of(prop_oneof![Just(0.0), Just(1e9), Just(-2.9e12)]),
        ) {
            let size = 10f64.powi(scale);
            let boxes: Vec<Aabb> = boxes
                .iter()
                .map(|&(c, e)| {
                    let c = DVec3::from(c) * size + DVec3::splat(offset);
                    let half = DVec3::splat(size * 10f64.powi(e[0]) * 0.5)
                        * DVec3::new(1.0, 10f64.powi(e[1] % 3), 10f64.powi(e[2] % 3));
                    Aabb::new(c - half, c + half)
                })
                .collect();
            let (mut tree, _) = Tree::build(boxes.len(), |i| boxes[i], Shape::OBJECTS, false);
            if let Some(at) = built_at {
                // Built where the boxes were (elsewhere, shrunk or grown), then refitted to
                // where they are: the refitted tree must hold as a built one does.
                let moved: Vec<Aabb> = boxes
                    .iter()
                    .map(|b| {
                        let (lo, hi) = (b.min() - DVec3::splat(offset), b.max() - DVec3::splat(offset));
                        Aabb::new(lo * 3.0 + DVec3::splat(at), hi * 3.0 + DVec3::splat(at))
                    })
                    .collect();
                (tree, _) = Tree::build(moved.len(), |i| moved[i], Shape::OBJECTS, false);
                let order = tree.order.clone();
                prop_assert!(tree.refit(None, |p| boxes[order[p] as usize]).is_some());
            }
            let mut origin = DVec3::from(from) * size * far + DVec3::splat(offset);
            let mut direction = DVec3::from(direction);
            if on_bound {
                // From exactly a box's bound, parallel to that slab.
                let b = boxes[pick.index(boxes.len())];
                origin.x = b.min().x;
                direction.x = 0.0;
            }
            prop_assume!(direction != DVec3::ZERO);
            let ray = Ray::new(origin, direction);
            let box_ray = BoxRay::new(&ray);
            let ray_t = Interval::new(t_min, t_max);
            let Some(lanes) = Lanes::new(&tree, &ray, &box_ray, ray_t) else {
                // Only past the limits: every |1/d| in [2^-62, 2^62] or infinite.
                let within = |inv: f64| {
                    inv.is_infinite() || (2f64.powi(-62)..=2f64.powi(62)).contains(&inv.abs())
                };
                prop_assert!(!box_ray.inv_direction.to_array().into_iter().all(within));
                return Ok(());
            };
            let world = tree.origin.to_array();
            for node in &tree.nodes {
                let exact = entries(node, &world, &box_ray, ray_t);
                let fast = lanes.entries(node, t_max);
                for k in 0..exact.len() {
                    if exact[k] < f64::INFINITY {
                        prop_assert!(
                            f64::from(fast[k]) <= exact[k],
                            "lane {k}: f32 entry {} after the f64 test's {}", fast[k], exact[k]
                        );
                    }
                }
            }
        }
    }

    /// A ray from a box's inside starting at zero, as every bounce and shadow ray does,
    /// meets no subnormal number in the lanes: its start, and its entries into the boxes
    /// it starts in, are normal numbers or zero.
    #[test]
    fn lanes_of_a_ray_from_inside_hold_no_subnormal() {
        let boxes = [
            Aabb::new(DVec3::ZERO, DVec3::ONE),
            Aabb::new(DVec3::splat(2.0), DVec3::splat(3.0)),
        ];
        let (tree, _) = Tree::build(boxes.len(), |i| boxes[i], Shape::OBJECTS, false);
        for origin in [DVec3::splat(0.5), tree.origin, DVec3::new(0.0, 0.5, 0.5)] {
            let ray = Ray::new(origin, DVec3::new(0.3, -0.2, 1.0));
            let box_ray = BoxRay::new(&ray);
            let lanes = Lanes::new(&tree, &ray, &box_ray, Interval::FORWARD).unwrap();
            let normal_or_zero = |x: f32| x == 0.0 || x.is_normal() || x.is_infinite();
            assert!(normal_or_zero(lanes.lo), "{}", lanes.lo);
            for &v in lanes.origin_near.iter().chain(&lanes.origin_far) {
                assert!(normal_or_zero(v), "{v}");
            }
            for node in &tree.nodes {
                let entries = lanes.entries(node, f64::INFINITY);
                assert!(entries.into_iter().all(normal_or_zero), "{entries:?}");
            }
        }
    }
}
