//! The one tree [`Bvh`](crate::Bvh) and [`TriangleMesh`](crate::TriangleMesh) share: a
//! flat hierarchy over objects known by position, built with binned SAH, traversed front to
//! back without recursion or allocation.
//!
//! By operation: `node.rs` (a node's `f32` boxes and how a box becomes them), `build.rs`
//! (binned SAH), `collapse.rs` (the binary tree into nodes of eight), `traverse.rs` (the
//! walk, in `f32` lanes), `refit.rs` (bounds after objects moved, and the SAH cost),
//! `insert.rs` (the insertion search) and `reinsert.rs` (moving the worst lanes). The tree
//! knows boxes and positions only; what is at a position is its owner's.

mod build;
mod collapse;
mod insert;
mod node;
mod refit;
mod reinsert;
mod traverse;

pub(crate) use build::{Shape, permute};
pub(crate) use insert::{Lane, Placed, ROOT};

use alloc::vec::Vec;

use glam::DVec3;

use node::Node;

/// Deepest a tree gets; the traversal stack has this many entries. The build switches to
/// median splits (which halve the count) well before it: see `build::MEDIAN_FROM_DEPTH`.
pub(crate) const MAX_DEPTH: usize = 64;

/// Children per node: eight, one AVX2 instruction's `f32` lanes. (Against four: bounce and
/// shadow rays faster on meshes of real size, primary rays slower; `docs/performance.md`,
/// the triad.)
pub(crate) const WIDTH: usize = 8;

/// What one query cost in a tree, counted by
/// [`Bvh::hit_visits`](crate::Bvh::hit_visits),
/// [`Bvh::occluded_visits`](crate::Bvh::occluded_visits) and their
/// [`TriangleMesh`](crate::TriangleMesh) namesakes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Visits {
    /// Nodes whose children's boxes were tested (a node holds up to eight children).
    pub nodes: u32,
    /// Objects (or a mesh's faces) tested.
    pub tests: u32,
}

/// A tree's cost by the surface area heuristic, when it was built and now, after updates
/// moved its objects: what says when to rebuild it. See [`Bvh::cost`](crate::Bvh::cost) and
/// [`TriangleMesh::cost`](crate::TriangleMesh::cost).
///
/// The cost is the expected work of a ray that meets the tree's box, in units of one
/// object test (node visits weighted as the build weighs them): a refitted tree keeps its
/// shape, and as its objects move apart from the ones they were grouped with, its boxes
/// grow and overlap and the cost rises. A rebuild brings it back to about `built`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeCost {
    /// At the last build.
    pub built: f64,
    /// Now.
    pub now: f64,
}

impl TreeCost {
    /// How much dearer a ray is than at the last build, by the heuristic, beyond which
    /// [`TreeCost::needs_rebuild`] says to rebuild.
    pub const REBUILD_AT: f64 = 1.5;

    /// `now / built` (1 for a tree of no bounded objects).
    #[inline]
    #[must_use]
    pub fn ratio(&self) -> f64 {
        if self.built > 0.0 {
            self.now / self.built
        } else {
            1.0
        }
    }

    /// The default policy: whether the cost has grown past [`TreeCost::REBUILD_AT`]
    /// times its cost at build.
    #[inline]
    #[must_use]
    pub fn needs_rebuild(&self) -> bool {
        self.ratio() > Self::REBUILD_AT
    }
}

/// What a query counts: the nodes whose children's boxes it tests, and the objects it
/// tests. `()` counts nothing (and costs nothing); [`Visits`] counts.
pub(crate) trait Tally {
    fn node(&mut self);
    fn tests(&mut self, count: u32);
}

impl Tally for () {
    #[inline(always)]
    fn node(&mut self) {}
    #[inline(always)]
    fn tests(&mut self, _: u32) {}
}

impl Tally for Visits {
    #[inline(always)]
    fn node(&mut self) {
        self.nodes += 1;
    }
    #[inline(always)]
    fn tests(&mut self, count: u32) {
        self.tests += count;
    }
}

/// The hierarchy itself, over objects known by position: what [`Bvh`] and
/// [`TriangleMesh`](crate::TriangleMesh) share.
#[derive(Clone, Debug)]
pub(crate) struct Tree {
    /// Empty when no object is in the tree.
    nodes: Vec<Node>,
    /// What the nodes' bounds are relative to: the centre of the bounded objects' box.
    origin: DVec3,
    /// What the node bounds span about `origin`, and how they round there (see
    /// `traverse::Lanes`, the `f32` test that relies on it).
    reach: node::Reach,
    /// Levels of nodes (0 for an empty tree): what bounds the traversal's stack.
    depth: usize,
    /// Whether a walk of the nodes, lane by lane, depth first, meets the leaves in the
    /// objects' order, as the build makes them (an insertion can break it).
    in_order: bool,
    /// `order[i]`: the caller's position of the object at position `i` of the tree's
    /// order (bounded objects first, then the unbounded ones).
    pub(crate) order: Vec<u32>,
    /// How many objects are in the tree.
    pub(crate) bounded: usize,
    /// What a node visit costs against one object test, as the build weighed it.
    traversal_cost: f64,
    /// Nodes no lane leads to any more (left empty by updates), for new nodes to reuse.
    spare: Vec<u32>,
}

impl Tree {
    /// Every leaf lane, as its name (`node * WIDTH + lane`, as [`Tree::lane`] takes it),
    /// its first position and its count of objects.
    pub(crate) fn leaves(&self) -> impl Iterator<Item = (u32, usize, usize)> + '_ {
        self.nodes.iter().enumerate().flat_map(|(n, node)| {
            (0..WIDTH).filter(|&k| node.count[k] > 0).map(move |k| {
                (
                    (n * WIDTH + k) as u32,
                    node.index[k] as usize,
                    node.count[k] as usize,
                )
            })
        })
    }

    /// Whether no object is in the tree (no node).
    pub(crate) fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Shrinks every box to what it holds, and takes the depth the tree now has.
    pub(crate) fn tighten_all(&mut self) {
        self.depth = self.tighten(0).map_or(1, |(_, height)| height);
    }

    /// Bytes held, for the memory figures.
    pub(crate) fn heap_bytes(&self) -> usize {
        self.nodes.capacity() * core::mem::size_of::<Node>()
            + self.order.capacity() * core::mem::size_of::<u32>()
    }
}

/// The closest-hit rule of every search in the crate: a crossing at `t` (never beyond the
/// best so far, `t_max`, which the search passes as its upper bound) wins over the best so
/// far where it is nearer or, at the same `t`, of lower number: the answer a slice gives,
/// in whatever order a tree meets its objects. `numbers` gives the crossing's object number
/// and the best's (`None`: no best yet), asked only on a tie, which is rare, so that a
/// search looks its numbers up only then.
#[inline(always)]
pub(crate) fn wins(t: f64, t_max: f64, numbers: impl FnOnce() -> (usize, Option<usize>)) -> bool {
    t < t_max || {
        let (index, best) = numbers();
        best.is_none_or(|best| index < best)
    }
}

/// What every tree must hold, for the tests of its owners.
#[cfg(test)]
mod check {
    use alloc::vec;

    use proptest::prelude::*;

    use super::{Tree, WIDTH};
    use crate::Aabb;
    use crate::math::Dd;
    use alloc::vec::Vec;
    use glam::DVec3;

    impl Tree {
        /// Levels of nodes the traversal's stack is sized for.
        pub(crate) fn depth(&self) -> usize {
            self.depth
        }

        /// What every tree must hold, however it was changed: each position of the tree in
        /// exactly one leaf (`leaf` is told each position and its leaf's name); each object's box inside every lane on its
        /// way down (as traversal computes them: `origin + bound` in `f64`); the rounding the
        /// `f32` lanes allow for covering every bound's; no more levels than `depth`.
        /// Returns the levels of nodes.
        pub(crate) fn check(
            &self,
            bbox: impl Fn(usize) -> Aabb,
            mut leaf: impl FnMut(usize, usize) -> Result<(), TestCaseError>,
        ) -> Result<usize, TestCaseError> {
            let tree = self;
            let mut seen = vec![0u32; tree.bounded];
            // (node, boxes of the lanes above it)
            let mut stack = vec![(0usize, 1usize, Vec::<(DVec3, DVec3)>::new())];
            let mut levels = 0;
            while let Some((n, level, above)) = stack.pop().filter(|_| !tree.nodes.is_empty()) {
                prop_assert!(level <= tree.depth);
                levels = levels.max(level);
                let node = &tree.nodes[n];
                for k in 0..WIDTH {
                    let world = |side: usize| {
                        DVec3::from_array(
                            [0, 1, 2].map(|a| tree.origin[a] + f64::from(node.bounds[side + a][k])),
                        )
                    };
                    let mut path = above.clone();
                    path.push((world(0), world(3)));
                    if node.count[k] > 0 {
                        let first = node.index[k] as usize;
                        let range = first..first + node.count[k] as usize;
                        for (p, times) in range.clone().zip(&mut seen[range]) {
                            *times += 1;
                            leaf(p, n * WIDTH + k)?;
                            let b = bbox(p);
                            for (lo, hi) in &path {
                                prop_assert!(lo.cmple(b.min()).all() && hi.cmpge(b.max()).all());
                            }
                        }
                    } else if node.index[k] != 0 {
                        stack.push((node.index[k] as usize, level + 1, path));
                    }
                    for side in 0..6 {
                        let f = node.bounds[side][k];
                        if f.is_finite() {
                            let a = side % 3;
                            let error = Dd::diff(tree.origin[a], -f64::from(f)).lo.abs();
                            prop_assert!(error <= tree.reach.rounding[a]);
                            prop_assert!(f64::from(f).abs() <= tree.reach.extent[a]);
                        }
                    }
                }
            }
            prop_assert!(
                seen.iter().all(|&s| s == 1),
                "a position in no leaf or in two"
            );
            Ok(levels)
        }
    }
}
