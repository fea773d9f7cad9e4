//! The binary tree the build makes (pairs of children), collapsed into nodes of eight.

use alloc::vec::Vec;

use super::node::Box3;
use super::node::Node;
use glam::Vec4;

use super::WIDTH;

/// Two sibling nodes of the binary tree the SAH build makes, before [`collapse`] turns it
/// into [`Node`]s of eight: their boxes, and for each either two children (`count == 0`,
/// `index` the pair that holds them) or a leaf (`count` objects from `index`).
#[derive(Clone, Copy)]
pub(super) struct Pair {
    pub(super) min: [[f32; 2]; 3],
    pub(super) max: [[f32; 2]; 3],
    pub(super) index: [u32; 2],
    pub(super) count: [u32; 2],
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
pub(super) struct Child {
    pub(super) bounds: Box3,
    pub(super) index: u32,
    pub(super) count: u32,
}

/// The binary tree of `pairs` under `root` as nodes of up to eight children, appended to
/// `nodes` parents first: each node takes its two children, then, while it has a free
/// lane, opens the inner child of largest surface area (the one a ray most often enters)
/// in place of it. Lanes keep the binary tree's left-to-right order, so that a walk of the
/// nodes, lane by lane, depth first, meets the leaves in the objects' order. A root that
/// is a leaf becomes a node of one child. The lanes are `plans[*next]` on, as [`plan`] chose
/// them (parents first, in the same order). Returns the levels of nodes.
pub(super) fn collapse(
    pairs: &[Pair],
    root: Child,
    plans: &[Plan],
    next: &mut usize,
    nodes: &mut Vec<Node>,
) -> usize {
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
    let (lanes, used) = plans[*next];
    *next += 1;
    let mut below = 0;
    for (k, &(pair, side)) in lanes[..used].iter().enumerate() {
        let child = if root.count == 0 {
            pairs[pair as usize].child(side as usize)
        } else {
            root
        };
        let mut lane = child;
        if lane.count == 0 {
            lane.index = nodes.len() as u32;
            below = below.max(collapse(pairs, child, plans, next, nodes));
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

/// A node's lanes, as (pair, side) in the pairs, and how many are used.
pub(super) type Plan = ([(u32, u32); WIDTH], usize);

/// The lanes of every node [`collapse`] makes of the binary tree under `root`, parents
/// first: chosen before any node is written, so that the vector of nodes is allocated once,
/// to the node, with neither doubling nor slack.
pub(super) fn plan(pairs: &[Pair], root: Child, plans: &mut Vec<Plan>) {
    let (lanes, used) = lanes_of(pairs, root);
    plans.push((lanes, used));
    if root.count == 0 {
        for &(pair, side) in &lanes[..used] {
            let pair = &pairs[pair as usize];
            if pair.count[side as usize] == 0 {
                plan(pairs, pair.child(side as usize), plans);
            }
        }
    }
}

/// The lanes of the node [`collapse`] makes of an inner `root`, as (pair, side) in
/// `pairs`, and how many are used: its two children, then, while a lane is free, the inner
/// child of largest surface area opened in place of it. (For a leaf `root`, one lane,
/// which [`collapse`] fills with the root itself.)
fn lanes_of(pairs: &[Pair], root: Child) -> Plan {
    let mut lanes = [(root.index, 0); WIDTH];
    if root.count != 0 {
        return (lanes, 1);
    }
    // Each lane's surface area, computed once (`-1` for a leaf, which is not opened).
    let area = |(pair, side): (u32, u32)| {
        let child = pairs[pair as usize].child(side as usize);
        if child.count == 0 {
            child.bounds.half_area()
        } else {
            -1.0
        }
    };
    let mut areas = [-1.0; WIDTH];
    lanes[1] = (root.index, 1);
    (areas[0], areas[1]) = (area(lanes[0]), area(lanes[1]));
    let mut used = 2;
    while used < WIDTH {
        let mut widest = None;
        for k in 0..used {
            // The last of equal areas, as `Iterator::max_by` picks it.
            if areas[k] >= 0.0 && widest.is_none_or(|w: usize| areas[k] >= areas[w]) {
                widest = Some(k);
            }
        }
        let Some(k) = widest else { break };
        // Its two children take its place, in order, so that the lanes stay in the
        // binary tree's left-to-right order (and their leaves in the objects' order:
        // what a refit relies on to visit the objects in order).
        let (pair, side) = lanes[k];
        let inner = pairs[pair as usize].index[side as usize];
        // One lane more: `used < WIDTH` here, so every index written is below `WIDTH`.
        // (A loop of at most six moves: `copy_within` calls `memmove`.)
        for j in (k + 1..used).rev() {
            lanes[j + 1] = lanes[j];
            areas[j + 1] = areas[j];
        }
        (lanes[k], lanes[k + 1]) = ((inner, 0), (inner, 1));
        (areas[k], areas[k + 1]) = (area(lanes[k]), area(lanes[k + 1]));
        used += 1;
    }
    (lanes, used)
}

pub(super) fn pair(a: Child, b: Child) -> Pair {
    Pair {
        min: [0, 1, 2].map(|axis| [a.bounds.min[axis], b.bounds.min[axis]]),
        max: [0, 1, 2].map(|axis| [a.bounds.max[axis], b.bounds.max[axis]]),
        index: [a.index, b.index],
        count: [a.count, b.count],
    }
}
