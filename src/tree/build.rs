//! Binned SAH build (Wald 2007, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies"; pbrt-v4 `BVHAggregate::buildRecursive`), on `f32` boxes rounded outward:
//! the nodes store `f32` anyway, and 32-byte records halve the memory the build sweeps.

use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;

use glam::{DVec3, Vec4};

use super::collapse::{Child, Pair, collapse, pair, plan};
use super::node::{Box3, Node, Reach, above, below};
use super::{MAX_DEPTH, Tree, WIDTH};
use crate::Aabb;

/// Centroid bins per axis.
const BINS: usize = 16;
/// A node with more objects than this is always split (for a [`Bvh`]).
const MAX_LEAF: usize = 8;
/// Cost of visiting a node, relative to testing one object.
const TRAVERSAL_COST: f64 = 1.0;
/// From this depth on, splits are by count (median), which halves the objects: a node at
/// this depth holds fewer than 2^32 of them, so 32 halvings more leave one, and no inner
/// node of the binary tree lies deeper than `MAX_DEPTH - 2` (the root's depth is 0). A
/// node of eight takes the place of at least one binary level, so the tree has at most
/// `MAX_DEPTH - 1` levels of them, within what the walk's stacks hold (as nodes of eight, a
/// chain of binary levels takes one node for seven: `the_deepest_build_stays_within_max_depth`).
const MEDIAN_FROM_DEPTH: usize = MAX_DEPTH - 33;

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
    /// after the build, as obvhs's medium preset does: a lower cost, rays no faster.)
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
            // The nodes' lanes chosen first, then the nodes allocated to the node: a node
            // opens up to `WIDTH - 1` pairs and those low in the tree fewer. (Tried: one
            // node per two pairs reserved and the slack given back after the collapse, a
            // copy; the vector grown by doubling; the lanes chosen twice to count the
            // nodes: each slower.)
            let mut plans = Vec::with_capacity(builder.pairs.len() / 2 + 1);
            plan(&builder.pairs, root, &mut plans);
            nodes.reserve_exact(plans.len());
            depth = collapse(&builder.pairs, root, &plans, &mut 0, &mut nodes);
        }
        let reach = reach(&nodes, origin);
        let bounded = prims.len();
        let mut order: Vec<u32> = Vec::with_capacity(count);
        order.extend(prims.iter().map(Prim::index));
        drop(prims);
        order.extend(unbounded);
        let tree = Self {
            nodes,
            origin,
            reach,
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

/// The [`Reach`] of the nodes' bounds about `origin`.
fn reach(nodes: &[Node], origin: DVec3) -> Reach {
    let mut reach = Reach::NONE;
    for node in nodes {
        for k in 0..WIDTH {
            reach.cover(origin, &node.lane(k));
        }
    }
    reach
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
/// becomes 0: always below `bins`, which [`Binning::new`] keeps at most [`BINS`], the size
/// of the arrays it indexes (`every_centroid_falls_in_a_bin` tries the extremes).
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
pub(crate) fn permute<T>(objects: &mut [T], order: &[u32]) {
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

#[cfg(test)]
mod tests {
    /// Boxes along a line, each twice as far out and as large as the last: a chain, the
    /// deepest kind of tree the heuristic makes, within `MAX_DEPTH` as nodes of eight,
    /// whole, and walked without a leaf missed or offered twice.
    #[test]
    fn the_deepest_build_stays_within_max_depth() {
        use super::{MAX_DEPTH, Shape, Tree};
        use crate::{Aabb, Interval, Ray};
        use glam::DVec3;
        let boxes: Vec<Aabb> = (0..100)
            .map(|i| {
                let r = 2f64.powi(i);
                Aabb::new(DVec3::new(2.0 * r, -r, -r), DVec3::new(4.0 * r, r, r))
            })
            .collect();
        let (tree, _) = Tree::build(boxes.len(), |i| boxes[i], Shape::OBJECTS, false);
        let levels = tree
            .check(|p| boxes[tree.order[p] as usize], |_, _| Ok(()))
            .unwrap();
        assert!(levels < MAX_DEPTH, "{levels} levels");
        let ray = Ray::new(DVec3::new(0.0, 0.5, 0.0), DVec3::X);
        let (mut seen, mut t_max) = (vec![0; boxes.len()], f64::INFINITY);
        tree.walk::<true>(
            &ray,
            Interval::FORWARD,
            &mut t_max,
            &mut (),
            |first, count, _| {
                seen[first..first + count].iter_mut().for_each(|s| *s += 1);
                false
            },
        );
        assert!(seen.iter().all(|&s| s == 1));
    }

    /// Every scaled centroid falls in one of the bins in use, past either end, infinite
    /// and NaN included.
    #[test]
    fn every_centroid_falls_in_a_bin() {
        for bins in [2, 7, super::BINS] {
            let last = bins as f32;
            for x in [
                f32::NAN,
                f32::NEG_INFINITY,
                -1.0,
                -0.0,
                0.0,
                last - 0.5,
                last,
                last + 1.0,
                f32::MAX,
                f32::INFINITY,
            ] {
                assert!(super::bin_at(x, bins) < bins, "{x} of {bins}");
            }
        }
    }

    /// The build reserves exactly the nodes its collapse makes (`collapse::plan`):
    /// no slack is kept, and the vector never grows by doubling, for trees of every shape
    /// the build makes, from one object to leaves of coinciding boxes.
    #[test]
    fn the_build_keeps_no_spare_nodes() {
        use super::{Shape, Tree};
        use crate::Aabb;
        use glam::DVec3;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in [1, 2, 3, 7, 8, 9, 64, 1000, 20_000] {
            let boxes: Vec<Aabb> = (0..n)
                .map(|i| {
                    // Random boxes, and every eleventh at the same place (where the build
                    // splits by count).
                    let c = if i % 11 == 0 {
                        DVec3::splat(0.5)
                    } else {
                        DVec3::new(next(), next(), next()) * 100.0
                    };
                    Aabb::new(c, c + DVec3::splat(next()))
                })
                .collect();
            for shape in [Shape::OBJECTS, crate::mesh::MESH_SHAPE] {
                let (tree, _) = Tree::build(n, |i| boxes[i], shape, false);
                assert_eq!(tree.nodes.capacity(), tree.nodes.len(), "{n} boxes");
            }
        }
    }
}
