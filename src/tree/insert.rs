//! Inserting an object into a built tree: the lane it goes into, found by a best-first
//! search for the least growth of the tree's cost (Bittner et al. 2013's insertion search),
//! and the boxes above it grown.

use alloc::collections::BinaryHeap;
use alloc::vec::Vec;
use core::cmp::Reverse;

use super::node::{
    Bounds, Node, Reach, clear, empty_node, grow, half_area, in_use, offsets, set_bounds, union,
};
use super::{MAX_DEPTH, Tree, WIDTH};
use crate::Aabb;

impl Tree {
    /// `b` as a leaf's bounds about the tree's origin, rounded outward, with the tree's
    /// rounding and compactness grown to cover them; `None` where `b` is not bounded or
    /// lies past `f32`'s range from the origin (such an object is tested on every ray). A
    /// tree without nodes takes `b`'s centre as its origin first.
    pub(crate) fn lane_bounds(&mut self, b: &Aabb) -> Option<Bounds> {
        if !b.is_bounded() {
            return None;
        }
        if self.nodes.is_empty() {
            self.origin = 0.5 * b.min() + 0.5 * b.max();
            self.reach = Reach::NONE;
        }
        let bounds = offsets(b, self.origin)?;
        self.reach.cover(self.origin, &bounds);
        Some(bounds)
    }

    /// The first position and count of the leaf `node * WIDTH + lane`.
    pub(crate) fn lane(&self, leaf: u32) -> (usize, usize) {
        let (n, k) = (leaf as usize / WIDTH, leaf as usize % WIDTH);
        (
            self.nodes[n].index[k] as usize,
            self.nodes[n].count[k] as usize,
        )
    }

    /// Takes the last position off a leaf; a leaf left with none becomes an unused lane.
    pub(crate) fn shrink(&mut self, leaf: u32) {
        self.in_order = false;
        let (n, k) = (leaf as usize / WIDTH, leaf as usize % WIDTH);
        let node = &mut self.nodes[n];
        node.count[k] -= 1;
        if node.count[k] == 0 {
            clear(node, k);
        }
    }

    /// Moves a leaf of one object to position `to`.
    pub(crate) fn move_leaf(&mut self, leaf: u32, to: u32) {
        self.in_order = false;
        let (n, k) = (leaf as usize / WIDTH, leaf as usize % WIDTH);
        self.nodes[n].index[k] = to;
    }

    /// Places `lane` where the surface area heuristic puts it: of every free lane, and
    /// every lane to pair it with in a new node (a leaf's, or given the `lineage` that
    /// knows the heights, a subtree's too), the one that adds least to the tree's cost
    /// (its own lane and the growth of every lane above it), found by a best-first search
    /// that skips the subtrees whose growth alone already costs more than the best found
    /// (the branch and bound of Bittner et al. 2013, "Fast insertion-based optimization of
    /// bounding volume hierarchies"), settling for the best found after [`SEARCH`] nodes.
    /// Keeps `lineage` up to date. `None` where no place lies within the deepest tree the
    /// traversal's stack holds (nothing is changed: the caller rebuilds).
    pub(crate) fn place(&mut self, lane: Lane, lineage: Option<&mut Lineage>) -> Option<Placed> {
        self.in_order = false;
        if self.nodes.is_empty() {
            self.nodes.push(empty_node());
            self.depth = 1;
        }
        let (visits, v, spot) = self.best_spot(&lane, lineage.as_deref())?;
        let Visit { node: n, level, .. } = visits[v];
        let (n, level) = (n as usize, level as usize);
        // The lanes on the way down grow to hold it.
        let mut at = visits[v];
        while at.from != ROOT {
            let from = visits[at.from as usize];
            grow(
                &mut self.nodes[from.node as usize],
                at.lane as usize,
                lane.bounds,
            );
            at = from;
        }
        let (k, pair) = match spot {
            Spot::Free(k) => {
                set_lane(&mut self.nodes[n], k, &lane);
                (k, None)
            }
            Spot::Pair(k, height) => {
                // A new node in lane `k`'s place, holding what it held and the new lane.
                let old = &self.nodes[n];
                let mut node = empty_node();
                let kept = Lane {
                    index: old.index[k],
                    count: old.count[k],
                    bounds: old.lane(k),
                    height,
                };
                set_lane(&mut node, 0, &kept);
                set_lane(&mut node, 1, &lane);
                let m = match self.spare.pop() {
                    Some(m) => {
                        self.nodes[m as usize] = node;
                        m as usize
                    }
                    None => {
                        self.nodes.push(node);
                        self.nodes.len() - 1
                    }
                };
                let parent = &mut self.nodes[n];
                parent.count[k] = 0;
                parent.index[k] = m as u32;
                grow(parent, k, lane.bounds);
                (k, Some((kept, m as u32)))
            }
        };
        let below = pair.map_or(lane.height, |(kept, _)| 1 + kept.height.max(lane.height));
        self.depth = self.depth.max(level + below);
        let placed = Placed {
            lane: pair.map_or(n * WIDTH + k, |(_, m)| m as usize * WIDTH + 1) as u32,
            pair,
        };
        if let Some(lineage) = lineage {
            lineage.placed(self.nodes.len(), n, k, &lane, &placed);
        }
        Some(placed)
    }

    /// The search of [`Tree::place`]: the nodes it visited, the visit of the node to place
    /// `lane` in, and where in it.
    pub(crate) fn best_spot(
        &self,
        lane: &Lane,
        lineage: Option<&Lineage>,
    ) -> Option<(Vec<Visit>, usize, Spot)> {
        let own = half_area(&lane.bounds) * lane.weight(self.traversal_cost);
        // Whether a pair's new node can still be numbered.
        let room = self.nodes.len() < u32::MAX as usize;
        let mut visits = alloc::vec![Visit {
            node: 0,
            level: 1,
            from: ROOT,
            lane: 0,
        }];
        // Costs are sums of areas and growths, never negative: their bits order as they do.
        let mut queue = BinaryHeap::new();
        queue.push(Reverse((0f64.to_bits(), 0u32)));
        let mut best: Option<(f64, usize, Spot)> = None;
        let mut searched = 0;
        while let Some(Reverse((bits, v))) = queue.pop() {
            let above = f64::from_bits(bits);
            if best.is_some_and(|(cost, ..)| above + own >= cost || searched >= SEARCH) {
                break;
            }
            searched += 1;
            let v = v as usize;
            let Visit { node: n, level, .. } = visits[v];
            let level = level as usize;
            let node = &self.nodes[n as usize];
            let consider = |best: &mut Option<(f64, usize, Spot)>, cost: f64, spot| {
                if best.is_none_or(|(b, ..)| cost < b) {
                    *best = Some((cost, v, spot));
                }
            };
            if level + lane.height <= MAX_DEPTH
                && let Some(k) = (0..WIDTH).find(|&k| !in_use(node, k))
            {
                consider(&mut best, above + own, Spot::Free(k));
            }
            for k in (0..WIDTH).filter(|&k| in_use(node, k)) {
                let bounds = node.lane(k);
                let grown = half_area(&union(&bounds, &lane.bounds));
                let leaf = node.count[k] > 0;
                // The levels of nodes below lane `k`, where they are known.
                let height = match lineage {
                    _ if leaf => Some(0),
                    Some(lineage) => Some(usize::from(lineage.height[node.index[k] as usize])),
                    None => None,
                };
                if let Some(height) = height
                    && level + 1 + height.max(lane.height) <= MAX_DEPTH
                    && room
                {
                    // Lane `k` becomes the new node's, and what it held moves down
                    // beside the new lane.
                    let cost = above + grown * self.traversal_cost + own;
                    consider(&mut best, cost, Spot::Pair(k, height));
                }
                if !leaf {
                    let below = above + (grown - half_area(&bounds)) * self.traversal_cost;
                    if best.is_none_or(|(b, ..)| below + own < b) {
                        visits.push(Visit {
                            node: node.index[k],
                            level: level as u32 + 1,
                            from: v as u32,
                            lane: k as u8,
                        });
                        queue.push(Reverse((below.to_bits(), (visits.len() - 1) as u32)));
                    }
                }
            }
        }
        best.map(|(_, v, spot)| (visits, v, spot))
    }

    /// Shrinks every inner lane's box under node `n` to the union of the lanes under it (a
    /// removal leaves them as they were); a lane whose node has no lane in use any more
    /// becomes unused, and its node spare. Returns the box of node `n` and its height (1
    /// for a node of leaves only), `None` if it holds nothing.
    pub(crate) fn tighten(&mut self, n: usize) -> Option<(Bounds, usize)> {
        let mut all: Option<(Bounds, usize)> = None;
        for k in 0..WIDTH {
            let node = &self.nodes[n];
            let lane = if node.count[k] > 0 {
                Some((node.lane(k), 1))
            } else if node.index[k] != 0 {
                let child = node.index[k];
                let below = self.tighten(child as usize);
                let node = &mut self.nodes[n];
                match below {
                    Some((bounds, _)) => set_bounds(node, k, bounds),
                    None => {
                        clear(node, k);
                        self.spare.push(child);
                    }
                }
                below.map(|(bounds, height)| (bounds, height + 1))
            } else {
                None
            };
            all = match (all, lane) {
                (Some(all), Some(lane)) => Some((union(&all.0, &lane.0), all.1.max(lane.1))),
                (all, lane) => all.or(lane),
            };
        }
        all
    }
}

/// Where [`Tree::place`] put a lane.
pub(crate) struct Placed {
    /// The lane it took, as `node * WIDTH + lane`.
    pub(crate) lane: u32,
    /// Where it was paired with what a lane held: that (now in lane 0 of the new node),
    /// and the new node.
    pub(crate) pair: Option<(Lane, u32)>,
}

/// For each node, the lane that leads to it (as `node * WIDTH + lane`; [`ROOT`] for the
/// root and for nodes no lane leads to) and its height (the levels of nodes from it
/// down; at least that, as lanes leave), kept by [`Bvh::optimize`] as it moves lanes.
pub(crate) struct Lineage {
    pub(crate) up: Vec<u32>,
    /// At most [`MAX_DEPTH`] (no place is taken below it), so a byte holds it.
    pub(crate) height: Vec<u8>,
}

impl Lineage {
    /// Records that [`Tree::place`] put `lane` in lane `k` of node `n` (of `nodes` in all),
    /// as `placed` says: the lanes that now lead to moved and new nodes, and the heights
    /// above them.
    pub(crate) fn placed(
        &mut self,
        nodes: usize,
        n: usize,
        k: usize,
        lane: &Lane,
        placed: &Placed,
    ) {
        self.up.resize(nodes, ROOT);
        self.height.resize(nodes, 0);
        let mut lead = |lane: &Lane, id: u32| {
            if lane.count == 0 {
                self.up[lane.index as usize] = id;
            }
        };
        lead(lane, placed.lane);
        let mut height = 1 + lane.height;
        if let Some((kept, m)) = &placed.pair {
            lead(kept, m * WIDTH as u32);
            self.up[*m as usize] = (n * WIDTH + k) as u32;
            height = 1 + kept.height.max(lane.height);
            self.height[*m as usize] = height as u8;
            height += 1;
        }
        // Up the tree, as far as heights grow.
        let mut n = n;
        while usize::from(self.height[n]) < height {
            self.height[n] = height as u8;
            if self.up[n] == ROOT {
                break;
            }
            n = self.up[n] as usize / WIDTH;
            height += 1;
        }
    }
}

/// What a lane holds: `count` objects from position `index` on, or (`count` 0) the node
/// `index`, with its bounds and the levels of nodes below it (0 for a leaf).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lane {
    pub(crate) index: u32,
    pub(crate) count: u32,
    pub(crate) bounds: Bounds,
    pub(crate) height: usize,
}

impl Lane {
    /// A leaf of one object.
    pub(crate) fn leaf(position: usize, bounds: Bounds) -> Self {
        Self {
            index: position as u32,
            count: 1,
            bounds,
            height: 0,
        }
    }

    /// What the surface area heuristic weighs the lane's area by: its objects' tests, or
    /// a node's visit.
    pub(crate) fn weight(&self, traversal_cost: f64) -> f64 {
        if self.count > 0 {
            f64::from(self.count)
        } else {
            traversal_cost
        }
    }
}

/// How many nodes [`Tree::place`]'s search looks into before it settles for the best place
/// found: enough for the searches we measured (a few dozen nodes), a bound for scenes where
/// every box holds every other (objects all in one point) and no branch can be cut.
pub(crate) const SEARCH: usize = 256;

/// A node [`Tree::place`]'s search reached: which, at what level, and by which lane of
/// which earlier visit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Visit {
    pub(crate) node: u32,
    pub(crate) level: u32,
    pub(crate) from: u32,
    pub(crate) lane: u8,
}

/// The root's visit comes from no other.
pub(crate) const ROOT: u32 = u32::MAX;

/// Where in a node [`Tree::place`] puts a lane.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Spot {
    /// In this unused lane.
    Free(usize),
    /// With what this lane holds (of the height given), in a new node in its place.
    Pair(usize, usize),
}

pub(crate) fn set_lane(node: &mut Node, k: usize, lane: &Lane) {
    node.index[k] = lane.index;
    node.count[k] = lane.count;
    set_bounds(node, k, lane.bounds);
}
