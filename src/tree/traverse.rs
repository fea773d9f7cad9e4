//! Front-to-back traversal with an explicit stack: no recursion, no allocation.
//!
//! A node's eight boxes are tested together, in `f32` lanes ([`Lanes`]) where the ray and the
//! tree allow it and in `f64` otherwise ([`entries`]); both are conservative against the
//! crate's one box test, so that a node never misses a ray its shapes' boxes take.

use super::node::Node;
use super::{MAX_DEPTH, Tally, Tree, WIDTH};
use glam::{DVec3, Vec3};

use crate::aabb::{BoxRay, slab_spans};
use crate::simd::Boxes;
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

/// A ray set up for the `f32` test of a node's eight boxes, which never rejects a box that
/// [`entries`] (the `f64` test on the same bounds) accepts, and never reports it entered
/// later: so the tree still answers as the loop over its objects (the contract's clause 3).
///
/// Per axis, the distance to a bound `f` (an offset from the tree's origin) is
/// `f * inv + shift` in `f32`: two roundings (one where AVX2's lanes fuse the multiply and
/// the add, which only errs less), where the `f64` test computes
/// `((origin + f) - o) * inv` with its own. With `r = o - origin` and `I = |inv|`, the `f32`
/// form errs from `(f - r) * inv` by at most `2^-24` of `|f| I` (the reciprocal's rounding
/// to `f32`) and `2^-24` of each of its two results (at most `(B + |r|) I` and a pad more,
/// `B` the largest `|f|` the tree holds along the axis), and the `f64` test by a few
/// `2^-53` of the same and the rounding of `origin + f` (`Reach::rounding`, times `I`),
/// and its far distance's padding (`FAR_PAD`). So `shift` is `-r * inv` moved outward by
/// one pad per axis and ray, `(B + |r|) I 2^-21 + 2 rounding I` (eight `2^-24` where four
/// would do), and rounded outward to `f32`: the near distances lower bounds of the `f64`
/// test's, the far ones upper bounds, with no pad per lane and node (Ize 2013, "Robust
/// BVH Ray Traversal", pads per lane; Embree's robust mode pads by a constant ulp count).
/// An absolute `2^-120` covers underflow, flushed to zero or not.
///
/// The lanes are taken only where nothing overflows and nothing is NaN: bounds within
/// `2^60` of the tree's origin, a ray origin within `2^62` of it, and every `|inv|` within
/// `[2^-62, 2^62]`, so that every distance stays below `2^125`; a ray with a zero
/// direction component (an infinite reciprocal, whose distances are `±inf` or NaN) takes
/// the `f64` test. An unused lane's empty box (`±inf` bounds) gives an infinite entry or
/// exit, never NaN.
struct Lanes<B: Boxes> {
    /// What makes lanes of `B`.
    token: B::Token,
    /// Per axis: the index into `Node::bounds` of the near bound, and of the far one.
    near: [usize; 3],
    far: [usize; 3],
    /// The reciprocal direction, and `-r * inv` moved outward for the near and far bounds,
    /// each in every lane.
    inv: [B; 3],
    near_shift: [B; 3],
    far_shift: [B; 3],
    /// `ray_t.min`, rounded down to `f32`.
    lo: B,
}

/// The pad's relative part, and its absolute one (see [`Lanes`]).
const PAD: f64 = 1.0 / (1u32 << 21) as f64;
const UNDERFLOW: f64 = 1.0 / (1u128 << 120) as f64;

/// The walk's two stacks, and why neither overflows. A node whose three or more children
/// the ray enters puts all of them on the stack before it takes the nearest off (one or
/// two push at most one), so testing a node needs room for `pending + WIDTH` entries. What
/// is pending then is, for each node above it, at most the `WIDTH - 1` children not taken
/// (last in, first out: a level's entries come off only after all pushed above them), so
/// at most `(WIDTH - 1) (d - 1)` at level `d` (the root's is 1).
///
/// - [`SMALL`], in the walk's frame, tests a node only where `pending + WIDTH <= SMALL`;
///   otherwise the walk goes on on the deep stack from that node, untested. 24 tests a
///   node of eight under up to 16 pending (every child of two levels entered, and two
///   more), where a walk mostly enters one or two children. (It tested up to
///   `pending + WIDTH - 1` and overflowed at 17 pending and eight children: the ToyCar's
///   crash. Tried: 25, which spills just the walks that spilled then; its 300 bytes,
///   zeroed on every walk, cost the skylight room's bounces 1.5% more instructions than
///   288, in callgrind. The kilobyte it once was cost about 70 a ray.)
/// - [`DEEP`] tests every node, so it holds the most a tree of [`MAX_DEPTH`] levels asks:
///   `(WIDTH - 1) (MAX_DEPTH - 1) + WIDTH`. No tree has more levels: the build's
///   (`build::MEDIAN_FROM_DEPTH`), and an insert refuses a place below it
///   (`insert::Tree::best_spot`).
///
/// The tests `walks_at_each_stack_bound_offer_every_leaf_once` drive both to their last
/// entry.
const SMALL: usize = 24;
const DEEP: usize = (WIDTH - 1) * (MAX_DEPTH - 1) + WIDTH;

/// Limits within which the `f32` distances cannot overflow (see [`Lanes`]).
const ORIGIN_LIMIT: f64 = (1u64 << 62) as f64;
const INV_LIMIT: f64 = (1u64 << 62) as f64;

/// A box test of a node's children: (lower bounds on) where the ray enters each within
/// `[ray_t.min, limit]`, and as bits the children it enters (`limit` is `t_max` in the
/// test's units, and rounded up to `f32`: see [`Limit`]).
trait Entries {
    fn entries(&self, node: &Node, limit: Limit) -> ([f32; WIDTH], u32);
}

/// `t_max` in the box test's units (`f64`), and rounded up to `f32`: made once each time
/// `t_max` changes, not per node.
#[derive(Clone, Copy)]
struct Limit {
    scaled: f64,
    up: f32,
}

impl Limit {
    #[inline(always)]
    fn new(box_ray: &BoxRay, t_max: f64) -> Self {
        let scaled = box_ray.scaled_max(t_max);
        Self {
            scaled,
            up: up(DVec3::splat(scaled.min(f64::from(f32::MAX)))).x,
        }
    }
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
    fn entries(&self, node: &Node, limit: Limit) -> ([f32; WIDTH], u32) {
        let t = entries(
            node,
            &self.origin,
            &self.ray,
            Interval::new(self.min, limit.scaled),
        )
        .map(|t| {
            if t < f64::INFINITY {
                down(DVec3::splat(t)).x.min(f32::MAX)
            } else {
                f32::INFINITY
            }
        });
        (t, t.le_bits([f32::MAX; WIDTH]))
    }
}

impl<B: Boxes> Entries for Lanes<B> {
    #[inline(always)]
    fn entries(&self, node: &Node, limit: Limit) -> ([f32; WIDTH], u32) {
        self.entries(node, limit.up)
    }
}

impl<B: Boxes> Lanes<B> {
    /// The lanes of a valid ray ([`Ray::is_valid`], which the walk checks first), or `None`
    /// where it or the tree is past the limits, or `ray_t` has a NaN end.
    #[inline(always)]
    fn new(
        token: B::Token,
        tree: &Tree,
        ray: &Ray,
        box_ray: &BoxRay,
        ray_t: Interval,
    ) -> Option<Self> {
        let inv = box_ray.inv_direction;
        let relative = ray.origin - tree.origin;
        let magnitude = inv.abs();
        // (A NaN fails the comparisons; `min_element` and `max_element` would pass it over,
        // but no component is NaN: the ray is valid, and its reciprocal of a finite
        // direction is a number or infinite.)
        let within = magnitude.min_element() >= 1.0 / INV_LIMIT
            && magnitude.max_element() <= INV_LIMIT
            && relative.abs().max_element() <= ORIGIN_LIMIT;
        if !(tree.reach.compact && within) || ray_t.min.is_nan() || ray_t.max.is_nan() {
            return None;
        }
        let reach = &tree.reach;
        let pad = (DVec3::from(reach.extent) + relative.abs()) * magnitude * PAD
            + 2.0 * DVec3::from(reach.rounding) * magnitude
            + DVec3::splat(UNDERFLOW + STEP);
        // Rounded outward to `f32` as [`up`] and [`down`] round, their step (`STEP` above)
        // folded into the pad.
        let shift = -relative * inv;
        let pad = pad + shift.abs() * f64::from(f32::EPSILON);
        let (near_shift, far_shift) = ((shift - pad).as_vec3(), (shift + pad).as_vec3());
        let mut lo = down(DVec3::splat(ray_t.min.max(-f64::from(f32::MAX)))).x;
        // A start at zero or after is kept at zero or after: rounded down it would be a
        // step below zero, which every box the ray starts in would carry into its entry.
        if ray_t.min >= 0.0 {
            lo = lo.max(0.0);
        }
        let mut lanes = Self {
            token,
            near: [0; 3],
            far: [0; 3],
            inv: splat3(token, inv.as_vec3()),
            near_shift: splat3(token, near_shift),
            far_shift: splat3(token, far_shift),
            lo: B::splat(token, lo),
        };
        for axis in 0..3 {
            let negative = box_ray.negative[axis];
            lanes.near[axis] = if negative { 3 + axis } else { axis };
            lanes.far[axis] = if negative { axis } else { 3 + axis };
        }
        Some(lanes)
    }

    /// Lower bounds on where the ray enters each child within `[ray_t.min, hi]` as the
    /// `f64` test finds it, and the children entered, as bits.
    #[inline(always)]
    fn entries(&self, node: &Node, hi: f32) -> ([f32; WIDTH], u32) {
        let (mut t0, mut t1) = (self.lo, B::splat(self.token, hi));
        for axis in 0..3 {
            let near = B::load(self.token, &node.bounds[self.near[axis]]);
            let far = B::load(self.token, &node.bounds[self.far[axis]]);
            // No distance is NaN (see `Lanes`), so the comparisons are the CPU's own `max`
            // and `min`.
            t0 = near.mul_add(self.inv[axis], self.near_shift[axis]).max(t0);
            t1 = far.mul_add(self.inv[axis], self.far_shift[axis]).min(t1);
        }
        (t0.to_array(), t0.le_bits(t1))
    }
}

/// Asks the CPU to start loading node `index` (its four cache lines), which the walk has
/// put on its stack: by the time it is popped, its boxes are nearer. Where SSE is not
/// there, nothing.
#[inline(always)]
fn prefetch(tree: &Tree, index: u32) {
    #[cfg(all(
        any(target_arch = "x86", target_arch = "x86_64"),
        target_feature = "sse"
    ))]
    if let Some(node) = tree.nodes.get(index as usize) {
        for side in [0, 2, 4] {
            safe_arch::prefetch_t0(&node.bounds[side]);
        }
        safe_arch::prefetch_t0(&node.index);
    }
    #[cfg(not(all(
        any(target_arch = "x86", target_arch = "x86_64"),
        target_feature = "sse"
    )))]
    let _ = (tree, index);
}

/// Each coordinate of `v` in every lane. (A function: a closure or `map` in its place
/// was left out of line, and made the lanes outside the AVX2 copy, a call each.)
#[inline(always)]
fn splat3<B: Boxes>(token: B::Token, v: Vec3) -> [B; 3] {
    [
        B::splat(token, v.x),
        B::splat(token, v.y),
        B::splat(token, v.z),
    ]
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
        visit: impl FnMut(usize, usize, &mut f64) -> bool,
    ) {
        self.walk_on::<NEAREST, [f32; WIDTH]>((), ray, ray_t, t_max, tally, visit);
    }

    /// [`Tree::walk`], its node test in lanes of `B` (made with `token`): AVX's where a
    /// caller compiled for AVX2 has the proof, arrays the compiler vectorizes otherwise.
    #[inline(always)]
    pub(crate) fn walk_on<const NEAREST: bool, B: Boxes>(
        &self,
        token: B::Token,
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
        match Lanes::<B>::new(token, self, ray, &box_ray, scaled_t) {
            Some(lanes) => self.descend::<NEAREST>(t_max, tally, &mut visit, &lanes, &box_ray),
            None => {
                let reference = Reference {
                    origin: self.origin.to_array(),
                    ray: box_ray,
                    min: scaled_t.min,
                };
                self.descend::<NEAREST>(t_max, tally, &mut visit, &reference, &box_ray);
            }
        }
    }

    /// The walk itself, with `test` giving (lower bounds on) where the ray enters each
    /// child of a node before `t_max` (and which it enters), in the units of `box_ray`'s
    /// scaled direction: on a stack in the walk's frame, moved to a deep one where that
    /// fills (the closest-hit rule does not depend on the order of the walk, so the deep
    /// one simply goes on from where the small one stopped).
    #[inline(always)]
    fn descend<const NEAREST: bool>(
        &self,
        t_max: &mut f64,
        tally: &mut impl Tally,
        visit: &mut impl FnMut(usize, usize, &mut f64) -> bool,
        test: &impl Entries,
        box_ray: &BoxRay,
    ) {
        let mut walk = Walk {
            children: [(0, 0); SMALL],
            entries: [0.0; SMALL],
            pending: 0,
            at: (0, 0),
            limit: Limit::new(box_ray, *t_max),
        };
        if walk.run::<NEAREST>(self, t_max, tally, visit, test, box_ray) {
            self.deep::<NEAREST>(&walk, t_max, tally, visit, test, box_ray);
        }
    }

    /// [`Tree::descend`] once the small stack is full: the same walk, on from `small`.
    #[cold]
    #[inline(never)]
    fn deep<const NEAREST: bool>(
        &self,
        small: &Walk<SMALL>,
        t_max: &mut f64,
        tally: &mut impl Tally,
        visit: &mut impl FnMut(usize, usize, &mut f64) -> bool,
        test: &impl Entries,
        box_ray: &BoxRay,
    ) {
        let mut walk = Walk {
            children: [(0, 0); DEEP],
            entries: [0.0; DEEP],
            pending: small.pending,
            at: small.at,
            limit: small.limit,
        };
        let pending = small.pending;
        walk.children[..pending].copy_from_slice(&small.children[..pending]);
        walk.entries[..pending].copy_from_slice(&small.entries[..pending]);
        walk.run::<NEAREST>(self, t_max, tally, visit, test, box_ray);
    }
}

/// A walk under way: pending children as (index, count) and where the ray enters each, in
/// two arrays, nearest on top; the child being visited (`count == 0`: a node), and `t_max`
/// as the box test takes it. (Two arrays rather than one of (index, count, entry): 4% to
/// 6% fewer instructions on a `Bvh`'s shadow rays, the mesh's within 0.3%; one of 16-byte
/// entries cost 39 more a ray.)
struct Walk<const N: usize> {
    children: [(u32, u32); N],
    entries: [f32; N],
    pending: usize,
    at: (u32, u32),
    limit: Limit,
}

impl<const N: usize> Walk<N> {
    /// Walks on until done (`false`) or until a node's children might not fit on the stack
    /// (`true`: that node is `at`, not yet tested). (`cargo mutants` on this walk: what the
    /// tests do not notice changes no answer, only the cost, which the ledger counts: a
    /// larger deep stack, spilling to it sooner or always, children taken in another order,
    /// `t_max`'s limit or a prefetch skipped, `^` for `|` on disjoint bits.)
    #[inline(always)]
    fn run<const NEAREST: bool>(
        &mut self,
        tree: &Tree,
        t_max: &mut f64,
        tally: &mut impl Tally,
        visit: &mut impl FnMut(usize, usize, &mut f64) -> bool,
        test: &impl Entries,
        box_ray: &BoxRay,
    ) -> bool {
        loop {
            let (index, count) = self.at;
            if count == 0 {
                // Room for all of a node's children before its nearest is taken (see
                // `SMALL`); the deep stack has it for every node of every tree.
                if N < DEEP && self.pending + WIDTH > N {
                    return true;
                }
                let node = &tree.nodes[index as usize];
                tally.node();
                let (t, mut bits) = test.entries(node, self.limit);
                if bits != 0 {
                    // One child entered, or two: no sort. (Tried: for any hit, farthest
                    // first, or the boxes the ray starts in last: fewer face tests on
                    // blocked shadow rays, no faster.)
                    let first = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if bits == 0 {
                        self.at = (node.index[first], node.count[first]);
                        continue;
                    }
                    let second = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if bits == 0 {
                        let (near, far) = if NEAREST && t[second] < t[first] {
                            (second, first)
                        } else {
                            (first, second)
                        };
                        self.children[self.pending] = (node.index[far], node.count[far]);
                        self.entries[self.pending] = t[far];
                        self.pending += 1;
                        self.at = (node.index[near], node.count[near]);
                        continue;
                    }
                    // Three or more: onto the stack, nearest first where asked (an
                    // insertion sort, of equal entries the lower lane on top), and the top
                    // taken. (Tried: a branch-free sorting network on keys that order as
                    // the distances do; slower on primary rays, no faster on bounces.)
                    let base = self.pending;
                    let mut bits = bits | (1 << first) | (1 << second);
                    while bits != 0 {
                        // Highest lane first, so that without sorting the lowest is on top.
                        let k = 31 - bits.leading_zeros() as usize;
                        bits &= !(1 << k);
                        let mut at = self.pending;
                        while NEAREST && at > base && self.entries[at - 1] < t[k] {
                            self.children[at] = self.children[at - 1];
                            self.entries[at] = self.entries[at - 1];
                            at -= 1;
                        }
                        self.children[at] = (node.index[k], node.count[k]);
                        self.entries[at] = t[k];
                        self.pending += 1;
                    }
                    self.pending -= 1;
                    self.at = self.children[self.pending];
                    for &(i, c) in &self.children[base..self.pending] {
                        if c == 0 {
                            prefetch(tree, i);
                        }
                    }
                    continue;
                }
            } else {
                let before = *t_max;
                if visit(index as usize, count as usize, t_max) {
                    return false;
                }
                if *t_max != before {
                    self.limit = Limit::new(box_ray, *t_max);
                }
            }
            // The nearest pending child the ray still reaches before t_max.
            loop {
                if self.pending == 0 {
                    return false;
                }
                self.pending -= 1;
                if self.entries[self.pending] <= self.limit.up {
                    self.at = self.children[self.pending];
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{BoxRay, Boxes, Lanes, Limit, Tree, WIDTH, entries};
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
            let ray_t = Interval::new(t_min, t_max);
            // Both kinds of lanes: the arrays, and AVX's with their fused multiply-add.
            conservative::<[f32; WIDTH]>((), &tree, &ray, ray_t, t_max)?;
            #[cfg(target_arch = "x86_64")]
            if let Some(token) = crate::simd::Avx2::detect() {
                conservative::<crate::simd::Avx8>(token, &tree, &ray, ray_t, t_max)?;
                as_tight_as_the_arrays(token, &tree, &ray, ray_t, t_max)?;
            }
        }
    }

    /// AVX's lanes are as tight as the arrays': both round the same distances
    /// `f * inv + shift` of `f32` operands, whose exact values (`f * inv` is exact in `f64`)
    /// each kind misses by at most two roundings, `2^-23` of `|f inv| + |shift|` (one
    /// where fused). So the two kinds' entries are within `2^-22` of the largest such `size`
    /// of each other, and a child one kind enters and the other does not has exact entry
    /// and exit that close too. (A slip that makes the AVX test looser, which the
    /// conservative test cannot see, fails here.)
    #[cfg(target_arch = "x86_64")]
    fn as_tight_as_the_arrays(
        token: crate::simd::Avx2,
        tree: &Tree,
        ray: &Ray,
        ray_t: Interval,
        t_max: f64,
    ) -> Result<(), TestCaseError> {
        let box_ray = BoxRay::new(ray);
        let arrays = Lanes::<[f32; WIDTH]>::new((), tree, ray, &box_ray, ray_t);
        let avx = Lanes::<crate::simd::Avx8>::new(token, tree, ray, &box_ray, ray_t);
        let (lanes, avx) = match (arrays, avx) {
            (Some(lanes), Some(avx)) => (lanes, avx),
            (arrays, avx) => {
                prop_assert!(arrays.is_none() && avx.is_none());
                return Ok(());
            }
        };
        let hi = Limit::new(&box_ray, t_max).up;
        for node in &tree.nodes {
            let (t, entered) = lanes.entries(node, hi);
            let (u, entered_avx) = avx.entries(node, hi);
            for k in 0..WIDTH {
                // The exact distances (in `f64`, where `f * inv` is exact and the sum's
                // rounding is far below the tolerance), and the largest term.
                let distance = |side: usize, shift: f32, axis: usize| {
                    let product = f64::from(node.bounds[side][k]) * f64::from(lanes.inv[axis][0]);
                    (
                        product + f64::from(shift),
                        product.abs() + f64::from(shift).abs(),
                    )
                };
                let (mut entry, mut exit) = (f64::from(lanes.lo[0]), f64::from(hi));
                let mut size = entry.abs();
                for axis in 0..3 {
                    let (near, a) = distance(lanes.near[axis], lanes.near_shift[axis][0], axis);
                    let (far, b) = distance(lanes.far[axis], lanes.far_shift[axis][0], axis);
                    entry = entry.max(near);
                    exit = exit.min(far);
                    size = size.max(a).max(b);
                }
                if !size.is_finite() {
                    // An unused lane's empty box, infinite either way.
                    continue;
                }
                let tolerance = 1.01 * f64::from(f32::EPSILON) * 2.0 * size;
                prop_assert!(
                    (f64::from(t[k]) - f64::from(u[k])).abs() <= tolerance,
                    "lane {k}: entries {} and {}, {tolerance} apart at most",
                    t[k],
                    u[k]
                );
                prop_assert!(
                    (entered ^ entered_avx) & (1 << k) == 0 || (entry - exit).abs() <= tolerance,
                    "lane {k}: entered by one kind only, exact entry {entry} and exit {exit}"
                );
            }
        }
        Ok(())
    }

    /// What `lanes_are_conservative_against_the_f64_test` asserts, on lanes of `B`.
    fn conservative<B: Boxes>(
        token: B::Token,
        tree: &Tree,
        ray: &Ray,
        ray_t: Interval,
        t_max: f64,
    ) -> Result<(), TestCaseError> {
        let box_ray = BoxRay::new(ray);
        let Some(lanes) = Lanes::<B>::new(token, tree, ray, &box_ray, ray_t) else {
            // Only past the limits: every |1/d| in [2^-62, 2^62] (so no zero
            // component).
            let within = |inv: f64| (2f64.powi(-62)..=2f64.powi(62)).contains(&inv.abs());
            prop_assert!(!box_ray.inv_direction.to_array().into_iter().all(within));
            return Ok(());
        };
        let world = tree.origin.to_array();
        for node in &tree.nodes {
            let exact = entries(node, &world, &box_ray, ray_t);
            let (fast, entered) = lanes.entries(node, Limit::new(&box_ray, t_max).up);
            for k in 0..exact.len() {
                if exact[k] < f64::INFINITY {
                    prop_assert!(
                        entered & (1 << k) != 0,
                        "lane {k}: entered by the f64 test only"
                    );
                    prop_assert!(
                        f64::from(fast[k]) <= exact[k],
                        "lane {k}: f32 entry {} after the f64 test's {}",
                        fast[k],
                        exact[k]
                    );
                }
            }
        }
        Ok(())
    }

    /// A walk that enters every child of every node fills the small stack and goes on on
    /// the deep one: it still offers every leaf once, with both child orders.
    #[test]
    fn a_walk_past_the_small_stack_offers_every_leaf_once() {
        // Boxes that all hold the ray's path, each a little apart from the others so that
        // the build still splits them: every node's children are all entered.
        let n = 8usize.pow(5);
        let boxes: Vec<Aabb> = (0..n)
            .map(|i| {
                let c = DVec3::new((i % 97) as f64, (i % 89) as f64, (i % 83) as f64) * 1e-3;
                Aabb::new(c - DVec3::splat(1.0), c + DVec3::splat(1.0))
            })
            .collect();
        let (tree, _) = Tree::build(boxes.len(), |i| boxes[i], Shape::OBJECTS, false);
        assert!(
            (super::WIDTH - 1) * tree.depth() > super::SMALL,
            "depth {}",
            tree.depth()
        );
        let ray = Ray::new(DVec3::splat(-5.0), DVec3::new(1.0, 0.9, 1.1));
        for nearest in [true, false] {
            let mut seen = vec![0u32; n];
            let mut offer = |first: usize, count: usize, _: &mut f64| {
                seen[first..first + count].iter_mut().for_each(|s| *s += 1);
                false
            };
            let mut t_max = f64::INFINITY;
            if nearest {
                tree.walk::<true>(&ray, Interval::FORWARD, &mut t_max, &mut (), &mut offer);
            } else {
                tree.walk::<false>(&ray, Interval::FORWARD, &mut t_max, &mut (), &mut offer);
            }
            assert!(
                seen.iter().all(|&s| s == 1),
                "nearest {nearest}: a leaf offered not once"
            );
        }
    }

    /// A tree of one node a level, the node of level `l + 1` with `lanes[l]` children,
    /// all of one box: lane 0 the next level's node (on the last level, a leaf) and the
    /// rest leaves of one object each. A ray through the box enters every child and takes
    /// lane 0 first (equal entries: the lower lane on top), so the walk tests the last
    /// node with `sum(lanes[..last] - 1)` entries pending, and it pushes `lanes[last]`.
    fn chain(lanes: &[usize]) -> Tree {
        let unit = Aabb::new(DVec3::splat(-1.0), DVec3::ONE);
        let (mut tree, _) = Tree::build(1, |_| unit, Shape::OBJECTS, false);
        let template = tree.nodes[0];
        let mut objects = 0;
        tree.nodes = lanes
            .iter()
            .enumerate()
            .map(|(level, &used)| {
                let mut node = template;
                for k in 0..super::WIDTH {
                    for side in 0..6 {
                        node.bounds[side][k] = if k < used {
                            template.bounds[side][0]
                        } else {
                            template.bounds[side][super::WIDTH - 1]
                        };
                    }
                    let inner = k == 0 && level + 1 < lanes.len();
                    (node.index[k], node.count[k]) = match () {
                        _ if k >= used => (0, 0),
                        _ if inner => (level as u32 + 1, 0),
                        _ => {
                            objects += 1;
                            (objects - 1, 1)
                        }
                    };
                }
                node
            })
            .collect();
        tree.order = (0..objects).collect();
        tree.bounded = objects as usize;
        tree.depth = lanes.len();
        tree
    }

    /// Levels of full nodes, then one of fewer children, then a full one, such that the
    /// walk tests the last with `pending` entries pending.
    fn chain_with_pending(pending: usize) -> Tree {
        let full = super::WIDTH - 1;
        let mut lanes = vec![super::WIDTH; pending / full];
        lanes.push(pending % full + 1);
        lanes.push(super::WIDTH);
        chain(&lanes)
    }

    /// Every leaf offered once by both walks, on `ray`; the nodes tested, as counted.
    fn offers_every_leaf_once(tree: &Tree, ray: &Ray) -> u32 {
        let mut nodes = 0;
        for nearest in [true, false] {
            let mut seen = vec![0u32; tree.bounded];
            let mut offer = |first: usize, count: usize, _: &mut f64| {
                seen[first..first + count].iter_mut().for_each(|s| *s += 1);
                false
            };
            let (mut t_max, mut visits) = (f64::INFINITY, crate::Visits::default());
            if nearest {
                tree.walk::<true>(ray, Interval::FORWARD, &mut t_max, &mut visits, &mut offer);
            } else {
                tree.walk::<false>(ray, Interval::FORWARD, &mut t_max, &mut visits, &mut offer);
            }
            assert!(
                seen.iter().all(|&s| s == 1),
                "nearest {nearest}: a leaf offered not once"
            );
            nodes = visits.nodes;
        }
        nodes
    }

    /// Each stack filled to its last entry, and one past the small one's limit: the small
    /// stack tests a node of `WIDTH` children with `SMALL - WIDTH` pending (its last entry
    /// written; with one more pending the walk goes on on the deep stack), and the deep
    /// stack walks a tree of `MAX_DEPTH` full levels, which writes its last entry. Each
    /// walk offers every leaf once. (With the small stack testing up to
    /// `pending + WIDTH - 1`, or the deep stack `(WIDTH - 1) MAX_DEPTH` long, as before the
    /// ToyCar's crash was fixed, the first and last of these panicked.)
    #[test]
    fn walks_at_each_stack_bound_offer_every_leaf_once() {
        use super::{MAX_DEPTH, SMALL, WIDTH};
        let ray = Ray::new(DVec3::splat(-5.0), DVec3::new(1.0, 0.9, 1.1));
        for pending in [SMALL - WIDTH, SMALL - WIDTH + 1] {
            let tree = chain_with_pending(pending);
            let levels = offers_every_leaf_once(&tree, &ray);
            assert_eq!(levels as usize, tree.depth(), "{pending} pending");
        }
        // Pending `(WIDTH - 1) (MAX_DEPTH - 1)` at the last level, which pushes `WIDTH`:
        // entry `DEEP - 1` written.
        let deepest = chain(&[WIDTH; MAX_DEPTH]);
        assert_eq!(offers_every_leaf_once(&deepest, &ray) as usize, MAX_DEPTH);
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
            let lanes =
                Lanes::<[f32; WIDTH]>::new((), &tree, &ray, &box_ray, Interval::FORWARD).unwrap();
            let normal_or_zero = |x: f32| x == 0.0 || x.is_normal() || x.is_infinite();
            assert!(normal_or_zero(lanes.lo[0]), "{}", lanes.lo[0]);
            for &v in lanes.near_shift.iter().chain(&lanes.far_shift).flatten() {
                assert!(normal_or_zero(v), "{v}");
            }
            for node in &tree.nodes {
                let (entries, entered) = lanes.entries(node, f32::INFINITY);
                let entries = (0..entries.len())
                    .filter(|k| entered & (1 << k) != 0)
                    .map(|k| entries[k]);
                assert!(
                    entries.clone().all(normal_or_zero),
                    "{:?}",
                    entries.collect::<Vec<_>>()
                );
            }
        }
    }
}
