//! Binned SAH build (Wald 2007, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies"; pbrt-v4 `BVHAggregate::buildRecursive`), on `f32` boxes rounded outward:
//! the nodes store `f32` anyway, and 32-byte records halve the memory the build sweeps.

use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;

use glam::{DVec3, Vec4};

use super::{Bounds, Bvh, MAX_DEPTH, Node, Tree, WIDTH};
use crate::math::Dd;
use crate::{Aabb, Hittable};

/// Centroid bins per axis.
const BINS: usize = 16;
/// A node with more objects than this is always split (for a [`Bvh`]).
const MAX_LEAF: usize = 8;
/// Cost of visiting a node, relative to testing one object.
const TRAVERSAL_COST: f64 = 1.0;
/// From this depth on, splits are by count (median), which halves the objects: with at most
/// 2^32 of them, 32 more levels reach single objects, within MAX_DEPTH.
const MEDIAN_FROM_DEPTH: usize = MAX_DEPTH - 33;

/// A box in `f32`, as SIMD lanes `x, y, z, w` (`w` unused by the box).
#[derive(Clone, Copy)]
struct Box3 {
    min: Vec4,
    max: Vec4,
}

impl Box3 {
    const EMPTY: Self = Self {
        min: Vec4::INFINITY,
        max: Vec4::NEG_INFINITY,
    };

    #[inline]
    fn grow(&mut self, min: Vec4, max: Vec4) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    /// Half the surface area (only ratios of areas matter); 0 for an empty box.
    #[inline]
    fn half_area(&self) -> f64 {
        let d = (self.max - self.min).max(Vec4::ZERO);
        let (x, y, z) = (f64::from(d.x), f64::from(d.y), f64::from(d.z));
        x * y + y * z + z * x
    }
}

/// One bounded object: its box, and in the `w` lane of `min` its position in the caller's
/// list (as bits), so that a record is 32 bytes and moves as two SIMD registers. Those bits
/// are read back, never computed with: as a float they are mostly subnormal, and arithmetic
/// on subnormals is slow (`centroid2` clears the lane; `min`/`max` do not care).
#[derive(Clone, Copy)]
struct Prim {
    min: Vec4,
    max: Vec4,
}

impl Prim {
    #[inline]
    fn index(&self) -> u32 {
        self.min.w.to_bits()
    }

    /// Twice the centroid (the factor cancels in every use), with `w` zero.
    #[inline]
    fn centroid2(&self) -> Vec4 {
        (self.min + self.max).with_w(0.0)
    }
}

/// Two sibling nodes of the binary tree the SAH build makes, before [`collapse`] turns it
/// into [`Node`]s of four: their boxes, and for each either two children (`count == 0`,
/// `index` the pair that holds them) or a leaf (`count` objects from `index`).
#[derive(Clone, Copy)]
struct Pair {
    min: [[f32; 2]; 3],
    max: [[f32; 2]; 3],
    index: [u32; 2],
    count: [u32; 2],
}

impl Pair {
    /// Child `k` (0 or 1).
    fn child(&self, k: usize) -> Child {
        let corner = |c: &[[f32; 2]; 3]| Vec4::new(c[0][k], c[1][k], c[2][k], 0.0);
        Child {
            bounds: Box3 {
                min: corner(&self.min),
                max: corner(&self.max),
            },
            index: self.index[k],
            count: self.count[k],
        }
    }
}

/// A node as the build returns it, before it is written into its parent's pair.
#[derive(Clone, Copy)]
struct Child {
    bounds: Box3,
    index: u32,
    count: u32,
}

pub(super) fn build<T: Hittable>(mut objects: Vec<T>, parallel: bool) -> Bvh<T> {
    let boxes: Vec<Aabb> = objects.iter().map(Hittable::bounding_box).collect();
    let (tree, bbox) = Tree::build(boxes.len(), |i| boxes[i], Shape::OBJECTS, parallel);
    drop(boxes);
    permute(&mut objects, &tree.order);
    let built_cost = tree.sah_cost();
    Bvh {
        objects,
        tree,
        bbox,
        built_cost,
        links: super::update::Links::default(),
    }
}

/// How the surface area heuristic weighs a node against its objects.
#[derive(Clone, Copy)]
pub(crate) struct Shape {
    /// Cost of visiting a node, relative to testing one object.
    pub(crate) traversal_cost: f64,
    /// A node with more objects than this is always split.
    pub(crate) max_leaf: usize,
}

impl Shape {
    /// For a [`Bvh`] of arbitrary objects: a node costs about one object test.
    pub(crate) const OBJECTS: Self = Self {
        traversal_cost: TRAVERSAL_COST,
        max_leaf: MAX_LEAF,
    };
}

impl Tree {
    /// The tree over `count` objects whose boxes `box_of` gives (called twice per object),
    /// and the union of all the boxes; `parallel` builds large subtrees side by side (with
    /// the `rayon` feature; the same tree). (Tried: reinsertion, `Bvh::optimize`, right
    /// after the build, as obvhs's medium preset does: the cost 1% lower, rays no faster.)
    ///
    /// # Panics
    /// If `count` exceeds `u32::MAX`.
    pub(crate) fn build(
        count: usize,
        box_of: impl Fn(usize) -> Aabb,
        shape: Shape,
        parallel: bool,
    ) -> (Self, Aabb) {
        assert!(
            u32::try_from(count).is_ok(),
            "a tree holds at most u32::MAX objects"
        );
        let (mut bbox, mut bounded) = (Aabb::EMPTY, Aabb::EMPTY);
        for i in 0..count {
            let b = box_of(i);
            bbox = bbox.union(&b);
            if b.is_bounded() {
                bounded = bounded.union(&b);
            }
        }
        // The centre of the bounded objects' box: nodes store their bounds relative to it,
        // so that f32 keeps its precision however far from the world's origin the scene
        // sits.
        // Not rounded to f32's precision: at 1e12 that would move it by up to 2^15, and
        // every offset's f32 resolution with it (to 2^-9, coarser than a small mesh's
        // triangles there). From the f64 centre, a box coordinate of a scene far from the
        // world's origin is a short exact difference, which f32 holds exactly, and
        // `origin + offset` gives the coordinate back without rounding.
        let origin = if bounded.is_bounded() {
            0.5 * bounded.min() + 0.5 * bounded.max()
        } else {
            DVec3::ZERO
        };
        let mut prims = Vec::with_capacity(count);
        let mut unbounded = Vec::new();
        let o = origin.to_array();
        for index in 0..count as u32 {
            let b = box_of(index as usize);
            let (lo, hi) = (b.min().to_array(), b.max().to_array());
            let (min, max) = (
                Vec4::new(
                    below(lo[0], o[0]),
                    below(lo[1], o[1]),
                    below(lo[2], o[2]),
                    f32::from_bits(index),
                ),
                Vec4::new(
                    above(hi[0], o[0]),
                    above(hi[1], o[1]),
                    above(hi[2], o[2]),
                    0.0,
                ),
            );
            // Infinite boxes (and boxes past f32's range) stay out of the SAH arithmetic:
            // such objects are tested on every ray.
            if b.is_bounded() && min.truncate().is_finite() && max.truncate().is_finite() {
                prims.push(Prim { min, max });
            } else {
                unbounded.push(index);
            }
        }

        let mut nodes = Vec::new();
        let mut depth = 0;
        if !prims.is_empty() {
            let extent = Extent::of(&prims);
            let mut builder = Builder::new(shape, parallel);
            let root = builder.node(&mut prims, 0, 0, extent);
            nodes.reserve(builder.pairs.len() / 2 + 1);
            depth = collapse(&builder.pairs, root, &mut nodes);
        }
        let (rounding, compact) = rounding(&nodes, origin);
        let bounded = prims.len();
        let mut order: Vec<u32> = Vec::with_capacity(count);
        order.extend(prims.iter().map(Prim::index));
        drop(prims);
        order.extend(unbounded);
        let tree = Self {
            nodes,
            origin,
            rounding,
            compact,
            depth,
            in_order: true,
            order,
            bounded,
            traversal_cost: shape.traversal_cost,
            spare: Vec::new(),
        };
        (tree, bbox)
    }
}

/// Per axis, how far `origin + bound` rounds in `f64` over the nodes' finite bounds, and
/// whether every bound lies within `2^60` of `origin`: what `Tree::rounding` and
/// `Tree::compact` hold.
fn rounding(nodes: &[Node], origin: DVec3) -> ([f64; 3], bool) {
    let (mut rounding, mut compact) = ([0.0; 3], true);
    for node in nodes {
        for k in 0..WIDTH {
            cover(&mut rounding, &mut compact, origin, &node.lane(k));
        }
    }
    (rounding, compact)
}

/// Grows `rounding` and `compact` (as [`rounding`] gives them) to cover the finite bounds
/// of a box about `origin`. How far `origin + bound` rounds is found bound by bound
/// (exactly, by two-sum): mostly not at all, since [`below`] and [`above`] pick offsets
/// whose sum lands on the box's own coordinates; but an ulp of the origin where it cannot
/// (about 1e-4 at 1e12), which a bound from the magnitudes alone would charge every node.
pub(super) fn cover(
    rounding: &mut [f64; 3],
    compact: &mut bool,
    origin: DVec3,
    (min, max): &Bounds,
) {
    for a in 0..3 {
        for f in [min[a], max[a]].into_iter().filter(|f| f.is_finite()) {
            *compact &= f64::from(f).abs() <= (1u64 << 60) as f64;
            let error = Dd::diff(origin[a], -f64::from(f)).lo.abs();
            rounding[a] = f64::max(rounding[a], error);
        }
    }
}

/// `b` as offsets from `origin`, rounded outward by [`below`] and [`above`]; `None` where
/// `b` is not bounded or an offset is past `f32`'s range.
pub(super) fn offsets(b: &Aabb, origin: DVec3) -> Option<Bounds> {
    if !b.is_bounded() {
        return None;
    }
    let min = [0, 1, 2].map(|a| below(b.min()[a], origin[a]));
    let max = [0, 1, 2].map(|a| above(b.max()[a], origin[a]));
    min.iter()
        .chain(&max)
        .all(|f| f.is_finite())
        .then_some((min, max))
}

/// The binary tree of `pairs` under `root` as nodes of up to four children, appended to
/// `nodes` parents first: each node takes its two children, then, while it has a free
/// lane, opens the inner child of largest surface area (the one a ray most often enters)
/// in place of it. Lanes keep the binary tree's left-to-right order, so that a walk of the
/// nodes, lane by lane, depth first, meets the leaves in the objects' order. A root that
/// is a leaf becomes a node of one child. Returns the levels of nodes.
fn collapse(pairs: &[Pair], root: Child, nodes: &mut Vec<Node>) -> usize {
    let slot = nodes.len();
    nodes.push(Node {
        bounds: [
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        index: [0; WIDTH],
        count: [0; WIDTH],
    });
    let mut lanes = [root; WIDTH];
    let mut used = 1;
    if root.count == 0 {
        let pair = &pairs[root.index as usize];
        (lanes[0], lanes[1], used) = (pair.child(0), pair.child(1), 2);
        while used < WIDTH {
            let widest = (0..used).filter(|&k| lanes[k].count == 0).max_by(|&a, &b| {
                lanes[a]
                    .bounds
                    .half_area()
                    .total_cmp(&lanes[b].bounds.half_area())
            });
            let Some(k) = widest else { break };
            // Its two children take its place, in order, so that the lanes stay in the
            // binary tree's left-to-right order (and their leaves in the objects' order:
            // what a refit relies on to visit the objects in order).
            let pair = &pairs[lanes[k].index as usize];
            lanes.copy_within(k + 1..used, k + 2);
            (lanes[k], lanes[k + 1]) = (pair.child(0), pair.child(1));
            used += 1;
        }
    }
    let mut below = 0;
    for (k, &child) in lanes[..used].iter().enumerate() {
        let mut lane = child;
        if lane.count == 0 {
            lane.index = nodes.len() as u32;
            below = below.max(collapse(pairs, child, nodes));
        }
        let node = &mut nodes[slot];
        for axis in 0..3 {
            node.bounds[axis][k] = lane.bounds.min[axis];
            node.bounds[3 + axis][k] = lane.bounds.max[axis];
        }
        node.index[k] = lane.index;
        node.count[k] = lane.count;
    }
    below + 1
}

fn pair(a: Child, b: Child) -> Pair {
    Pair {
        min: [0, 1, 2].map(|axis| [a.bounds.min[axis], b.bounds.min[axis]]),
        max: [0, 1, 2].map(|axis| [a.bounds.max[axis], b.bounds.max[axis]]),
        index: [a.index, b.index],
        count: [a.count, b.count],
    }
}

/// The box of some objects and the box of their (doubled) centroids.
#[derive(Clone, Copy)]
struct Extent {
    bounds: Box3,
    centroids: Box3,
}

impl Extent {
    const EMPTY: Self = Self {
        bounds: Box3::EMPTY,
        centroids: Box3::EMPTY,
    };

    fn of(prims: &[Prim]) -> Self {
        let mut extent = Self::EMPTY;
        for p in prims {
            extent.bounds.grow(p.min, p.max);
            extent.centroids.grow(p.centroid2(), p.centroid2());
        }
        extent
    }

    fn grow(&mut self, other: &Self) {
        self.bounds.grow(other.bounds.min, other.bounds.max);
        self.centroids
            .grow(other.centroids.min, other.centroids.max);
    }
}

/// Per bin: how many objects, and their extent.
struct Bins {
    count: [u32; BINS],
    extent: [Extent; BINS],
}

impl Default for Bins {
    fn default() -> Self {
        Self {
            count: [0; BINS],
            extent: [Extent::EMPTY; BINS],
        }
    }
}

/// The best split found by [`Builder::sah_split`].
struct Split {
    /// In units of one object test.
    cost: f64,
    axis: usize,
    /// The last bin on the left.
    bin: usize,
    /// The extent of each side.
    sides: [Extent; 2],
}

/// The pairs built so far, and the bins every node reuses.
struct Builder {
    pairs: Vec<Pair>,
    bins: Box<Bins>,
    shape: Shape,
    /// Whether to build large subtrees in parallel (only with the `rayon` feature).
    #[cfg_attr(not(feature = "rayon"), allow(dead_code))]
    parallel: bool,
}

/// Nodes with at least this many objects build their two subtrees in parallel (with the
/// `rayon` feature): below it, the work is too small to be worth a task.
#[cfg(feature = "rayon")]
const PARALLEL_FROM: usize = 1 << 14;

impl Builder {
    fn new(shape: Shape, parallel: bool) -> Self {
        Self {
            pairs: Vec::new(),
            bins: Box::new(Bins::default()),
            shape,
            parallel,
        }
    }

    /// A subtree in pairs of its own, numbered from 0.
    #[cfg(feature = "rayon")]
    fn subtree(
        mut self,
        prims: &mut [Prim],
        offset: usize,
        depth: usize,
        extent: Extent,
    ) -> (Child, Vec<Pair>) {
        let root = self.node(prims, offset, depth, extent);
        (root, self.pairs)
    }

    /// Appends a [`Builder::subtree`]'s pairs, renumbered to where they land.
    #[cfg(feature = "rayon")]
    fn graft(&mut self, (mut root, pairs): (Child, Vec<Pair>)) -> Child {
        let base = self.pairs.len() as u32;
        let inner = |index: &mut u32, count: u32| {
            if count == 0 {
                *index += base;
            }
        };
        self.pairs.extend(pairs.into_iter().map(|mut p| {
            inner(&mut p.index[0], p.count[0]);
            inner(&mut p.index[1], p.count[1]);
            p
        }));
        inner(&mut root.index, root.count);
        root
    }

    /// Builds the subtree over `prims` (at position `offset` of the final order) and
    /// returns its root; the pairs of inner nodes go to `pairs`, parents before children.
    fn node(&mut self, prims: &mut [Prim], offset: usize, depth: usize, extent: Extent) -> Child {
        let n = prims.len();
        let leaf = Child {
            bounds: extent.bounds,
            index: offset as u32,
            count: n as u32,
        };
        if n == 1 {
            return leaf;
        }

        let split = if depth < MEDIAN_FROM_DEPTH {
            self.sah_split(prims, &extent)
        } else {
            None
        };
        let (mid, sides) = match split {
            Some(split) if split.cost >= n as f64 && n <= self.shape.max_leaf => return leaf,
            Some(split) => {
                let binning = Binning::new(&extent.centroids, split.axis, n);
                let lane = Vec4::AXES[split.axis];
                let mid = partition(prims, |p| binning.bin(p.centroid2().dot(lane)) <= split.bin);
                (mid, Some(split.sides))
            }
            None if n <= self.shape.max_leaf => return leaf,
            None => (0, None),
        };
        // No SAH split (all centroids coincide, or deep in the tree), or one that leaves a
        // side empty: a median by count along the widest centroid axis, which always halves.
        let (mid, [left_extent, right_extent]) = match sides {
            Some(sides) if mid != 0 && mid != n => (mid, sides),
            _ => {
                let width = (extent.centroids.max - extent.centroids.min).to_array();
                let axis = (0..3)
                    .max_by(|&a, &b| width[a].total_cmp(&width[b]))
                    .unwrap_or(0);
                prims.select_nth_unstable_by(n / 2, |a, b| {
                    a.centroid2()[axis].total_cmp(&b.centroid2()[axis])
                });
                (
                    n / 2,
                    [Extent::of(&prims[..n / 2]), Extent::of(&prims[n / 2..])],
                )
            }
        };

        let slot = self.pairs.len();
        self.pairs.push(pair(leaf, leaf));
        let (left, right) = prims.split_at_mut(mid);
        #[cfg(feature = "rayon")]
        let (a, b) = if self.parallel && n >= PARALLEL_FROM {
            // Both sides in their own pairs, side by side, then appended as the serial
            // build would have written them (left subtree, then right): the same tree.
            let shape = self.shape;
            let (a, b) = rayon::join(
                || Builder::new(shape, true).subtree(left, offset, depth + 1, left_extent),
                || Builder::new(shape, true).subtree(right, offset + mid, depth + 1, right_extent),
            );
            (self.graft(a), self.graft(b))
        } else {
            (
                self.node(left, offset, depth + 1, left_extent),
                self.node(right, offset + mid, depth + 1, right_extent),
            )
        };
        #[cfg(not(feature = "rayon"))]
        let (a, b) = (
            self.node(left, offset, depth + 1, left_extent),
            self.node(right, offset + mid, depth + 1, right_extent),
        );
        self.pairs[slot] = pair(a, b);
        Child {
            bounds: extent.bounds,
            index: slot as u32,
            count: 0,
        }
    }

    /// The cheapest split by the surface area heuristic along the axis where the
    /// centroids spread widest (as pbrt-v4 does: a third of the binning work of trying all
    /// three, for trees nearly as good); `None` when all centroids coincide. Each bin keeps
    /// its objects' extent, so that the children's extents need no second pass.
    fn sah_split(&mut self, prims: &[Prim], extent: &Extent) -> Option<Split> {
        let centroids = &extent.centroids;
        let width = (centroids.max - centroids.min).to_array();
        let axis = (0..3).max_by(|&a, &b| width[a].total_cmp(&width[b]))?;
        if width[axis] <= 0.0 {
            return None;
        }
        let binning = Binning::new(centroids, axis, prims.len());
        let bins = binning.bins;
        let Bins {
            count,
            extent: bin_extent,
        } = &mut *self.bins;
        count[..bins].fill(0);
        bin_extent[..bins].fill(Extent::EMPTY);
        let lane = Vec4::AXES[axis];
        for p in prims {
            let c = p.centroid2();
            let b = binning.bin(c.dot(lane));
            count[b] += 1;
            bin_extent[b].bounds.grow(p.min, p.max);
            bin_extent[b].centroids.grow(c, c);
        }

        // Costs without the constant traversal cost and the division by the parent's
        // area, which do not change which split is cheapest. Area times count of every
        // suffix, then sweep from the left.
        let mut right_cost = [0.0; BINS];
        let (mut acc, mut k) = (Box3::EMPTY, 0);
        for b in (1..bins).rev() {
            acc.grow(bin_extent[b].bounds.min, bin_extent[b].bounds.max);
            k += count[b];
            right_cost[b] = acc.half_area() * f64::from(k);
        }
        let mut best: Option<(f64, usize)> = None;
        let (mut acc, mut k) = (Box3::EMPTY, 0);
        for b in 0..bins - 1 {
            acc.grow(bin_extent[b].bounds.min, bin_extent[b].bounds.max);
            k += count[b];
            if k == 0 || k as usize == prims.len() {
                continue;
            }
            let cost = acc.half_area() * f64::from(k) + right_cost[b + 1];
            if best.is_none_or(|(c, _)| cost < c) {
                best = Some((cost, b));
            }
        }
        let (cost, bin) = best?;
        let side = |range: core::ops::Range<usize>| {
            let mut side = Extent::EMPTY;
            bin_extent[range].iter().for_each(|e| side.grow(e));
            side
        };
        Some(Split {
            cost: self.shape.traversal_cost + cost / extent.bounds.half_area(),
            axis,
            bin,
            sides: [side(0..bin + 1), side(bin + 1..bins)],
        })
    }
}

/// Maps centroid coordinates along one axis to `bins` bins.
struct Binning {
    lo: f32,
    scale: f32,
    bins: usize,
}

impl Binning {
    /// As many bins as objects, up to `BINS`: small nodes are most nodes, and sweeping
    /// empty bins is most of their cost.
    fn new(centroids: &Box3, axis: usize, objects: usize) -> Self {
        let bins = objects.clamp(2, BINS);
        let (lo, hi) = (centroids.min[axis], centroids.max[axis]);
        let scale = if hi > lo {
            bins as f32 / (hi - lo)
        } else {
            0.0
        };
        Self { lo, scale, bins }
    }

    #[inline]
    fn bin(&self, c: f32) -> usize {
        bin_at((c - self.lo) * self.scale, self.bins)
    }
}

/// The bin of a scaled centroid coordinate. The float-to-int cast saturates, and NaN
/// becomes 0: always a valid bin.
#[inline]
fn bin_at(x: f32, bins: usize) -> usize {
    (x as usize).min(bins - 1)
}

/// Moves the prims satisfying `left` to the front; returns how many. Branch-free (the
/// test is a coin toss on random input): `prims[mid..i]` are all on the right, so swapping
/// `i` with `mid` either way keeps them there.
fn partition(prims: &mut [Prim], left: impl Fn(&Prim) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..prims.len() {
        let goes_left = left(&prims[i]);
        prims.swap(i, mid);
        mid += usize::from(goes_left);
    }
    mid
}

/// Reorders `objects` in place so that position `i` holds the object that was at
/// `order[i]`, following each cycle of the permutation once.
fn permute<T>(objects: &mut [T], order: &[u32]) {
    let mut done = vec![false; objects.len()];
    for start in 0..objects.len() {
        let mut at = start;
        while !done[at] {
            done[at] = true;
            let from = order[at] as usize;
            if from == start {
                break;
            }
            objects.swap(at, from);
            at = from;
        }
    }
}

/// An `f32` offset `f` from `origin` whose world coordinate, as traversal computes it
/// (`origin + f` in `f64`, see `traverse::entries`), is at or below `x`: a node box stored
/// this way still contains the `f64` box it was built from, exactly. Infinite when the
/// offset is past `f32`'s range (the object then stays out of the tree).
///
/// The `f32` at or below `x - origin` (as `f64` rounds it) where its sum with `origin`
/// lands at or below `x`, as it mostly does (often on `x` itself); else its neighbour
/// below, which always does: the rounded difference is within half an `f64` ulp of the
/// exact one, and an `f32` step is wider than that at any magnitude, so the exact sum is
/// below `x`, and rounding it to `f64` cannot pass `x`. Branch-free (which of the two it
/// is, is a coin toss where the origin's bits are not round). Never a subnormal: one is
/// taken down to zero or to the largest negative normal, so that no node holds a bound
/// that traversal would compute with slowly, or read as zero (moved the wrong way) with
/// the CPU's denormals-are-zero mode on.
#[inline]
pub(super) fn below(x: f64, origin: f64) -> f32 {
    let f = round_down(x - origin);
    let f = if origin + f64::from(f) <= x {
        f
    } else {
        step_down(f)
    };
    if f.is_subnormal() {
        if f > 0.0 { 0.0 } else { -f32::MIN_POSITIVE }
    } else {
        f
    }
}

/// As [`below`], at or above `x`.
pub(super) fn above(x: f64, origin: f64) -> f32 {
    -below(-x, -origin)
}

/// The largest `f32` at or below `x` (NaN for NaN), without a branch: rounded to nearest,
/// then, where that went up, its [`step_down`].
#[inline]
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { step_down(f) } else { f }
}

/// The next `f32` toward `-inf` of a non-NaN `f` that is not `-inf`: one step of its bits
/// (toward zero for a positive, away from it for a negative, `-0.0` to the smallest
/// negative subnormal, `+inf` to `f32::MAX`).
#[inline]
fn step_down(f: f32) -> f32 {
    let bits = f.to_bits() as i32;
    f32::from_bits(bits.wrapping_sub(2 * (bits >> 31) + 1) as u32)
}

#[cfg(test)]
mod tests {
    use super::round_down;
    use proptest::prelude::*;

    /// The reference: the largest `f32` at or below `x`, by `next_down`.
    fn reference(x: f64) -> f32 {
        let f = x as f32;
        if f64::from(f) > x { f.next_down() } else { f }
    }

    #[test]
    fn round_down_at_the_edges() {
        let tiny = f64::from(f32::from_bits(1));
        for x in [
            0.0,
            -0.0,
            tiny,
            -tiny,
            0.5 * tiny,
            -0.5 * tiny,
            1e-300,
            -1e-300,
            1.0,
            -1.0,
            f64::from(f32::MAX),
            -f64::from(f32::MAX),
            3.5e38,
            -3.5e38,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            assert_eq!(round_down(x).to_bits(), reference(x).to_bits(), "{x:e}");
        }
        assert!(round_down(f64::NAN).is_nan());
    }

    proptest! {
        /// `below` and `above` hold `x` as traversal computes the bound (`origin + f` in
        /// `f64`), for coordinates and origins of every magnitude, and are tight: at most
        /// two `f32` steps from the difference rounded outward.
        #[test]
        fn offsets_hold_the_coordinate_and_are_tight(
            x in prop_oneof![any::<f64>(), -1e13f64..1e13, -1.0f64..1.0, -1e-37f64..1e-37],
            near in prop_oneof![Just(0.0), -1e-3f64..1e-3, -1e6f64..1e6, -1e-38f64..1e-38],
        ) {
            prop_assume!(x.is_finite());
            let origin = x + near;
            prop_assume!(origin.is_finite());
            let (lo, hi) = (super::below(x, origin), super::above(x, origin));
            prop_assert!(!lo.is_subnormal() && !hi.is_subnormal());
            if lo.is_finite() {
                prop_assert!(origin + f64::from(lo) <= x);
                // (Or a subnormal taken down to zero or to the largest negative normal.)
                prop_assert!(
                    lo >= super::step_down(super::step_down(round_down(x - origin)))
                        || lo == 0.0
                        || lo == -f32::MIN_POSITIVE
                );
            }
            if hi.is_finite() {
                prop_assert!(origin + f64::from(hi) >= x);
                prop_assert!(
                    -hi >= super::step_down(super::step_down(round_down(origin - x)))
                        || hi == 0.0
                        || hi == f32::MIN_POSITIVE
                );
            }
        }

        #[test]
        fn round_down_is_the_largest_f32_at_or_below(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(!x.is_nan());
            prop_assert_eq!(round_down(x).to_bits(), reference(x).to_bits());
        }
    }
}
