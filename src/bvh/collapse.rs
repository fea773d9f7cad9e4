//! The binary tree the build makes (pairs of children), collapsed into nodes of eight.

use alloc::vec::Vec;

use super::build::Box3;
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
/// is a leaf becomes a node of one child. Returns the levels of nodes.
pub(super) fn collapse(pairs: &[Pair], root: Child, nodes: &mut Vec<Node>) -> usize {
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
    let (lanes, used) = lanes_of(pairs, root);
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

/// The nodes [`collapse`] makes of the binary tree under `root`: what to reserve, so
/// that the vector of nodes neither grows by doubling nor keeps slack.
pub(super) fn node_count(pairs: &[Pair], root: Child) -> usize {
    let (lanes, used) = lanes_of(pairs, root);
    1 + lanes[..used]
        .iter()
        .filter(|lane| lane.count == 0)
        .map(|&lane| node_count(pairs, lane))
        .sum::<usize>()
}

/// The lanes of the node [`collapse`] makes of `root`, and how many are used: its two
/// children, then, while a lane is free, the inner child of largest surface area opened
/// in place of it.
fn lanes_of(pairs: &[Pair], root: Child) -> ([Child; WIDTH], usize) {
    let mut lanes = [root; WIDTH];
    let mut used = 1;
    if root.count == 0 {
        // Each lane's surface area, computed once (`-1` for a leaf, which is not opened).
        let area = |c: &Child| {
            if c.count == 0 {
                c.bounds.half_area()
            } else {
                -1.0
            }
        };
        let mut areas = [-1.0; WIDTH];
        let pair = &pairs[root.index as usize];
        (lanes[0], lanes[1], used) = (pair.child(0), pair.child(1), 2);
        (areas[0], areas[1]) = (area(&lanes[0]), area(&lanes[1]));
        while used < WIDTH {
            let widest = (0..used)
                .filter(|&k| lanes[k].count == 0)
                .max_by(|&a, &b| areas[a].total_cmp(&areas[b]));
            let Some(k) = widest else { break };
            // Its two children take its place, in order, so that the lanes stay in the
            // binary tree's left-to-right order (and their leaves in the objects' order:
            // what a refit relies on to visit the objects in order).
            let pair = &pairs[lanes[k].index as usize];
            lanes.copy_within(k + 1..used, k + 2);
            areas.copy_within(k + 1..used, k + 2);
            (lanes[k], lanes[k + 1]) = (pair.child(0), pair.child(1));
            (areas[k], areas[k + 1]) = (area(&lanes[k]), area(&lanes[k + 1]));
            used += 1;
        }
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
