//! Reinsertion: the lanes whose boxes cost the tree most, taken out and inserted again
//! where they cost least ([`Bvh::optimize`](crate::Bvh::optimize)).

use alloc::vec::Vec;

use super::insert::{Lane, Lineage, ROOT};
use super::node::{EMPTY, clear, half_area, in_use, set_bounds, union};
use super::{Tree, WIDTH};

impl Tree {
    /// The lanes (leaves and subtrees) whose nodes' boxes shrink most without them (in
    /// surface area), the `share` of all lanes in use at most, worst first; only those
    /// whose node does shrink.
    pub(crate) fn worst_lanes(&self, share: f64) -> Vec<u32> {
        let lanes = self
            .nodes
            .iter()
            .flat_map(|node| (0..WIDTH).map(|k| in_use(node, k)));
        // `as` takes NaN to 0.
        let keep = (lanes.filter(|&used| used).count() as f64 * share.clamp(0.0, 1.0)) as usize;
        if keep == 0 {
            return Vec::new();
        }
        let mut scored: Vec<(f64, u32)> = Vec::new();
        for (n, node) in self.nodes.iter().enumerate() {
            // An unused lane's box is empty: nothing in a union.
            let without = |skip: usize| {
                (0..WIDTH)
                    .filter(|&k| k != skip)
                    .fold(EMPTY, |all, k| union(&all, &node.lane(k)))
            };
            let whole = half_area(&without(WIDTH));
            for k in (0..WIDTH).filter(|&k| in_use(node, k)) {
                let gain = whole - half_area(&without(k));
                if gain > 0.0 {
                    scored.push((gain, (n * WIDTH + k) as u32));
                }
            }
        }
        let worst_first = |a: &(f64, u32), b: &(f64, u32)| b.0.total_cmp(&a.0);
        if keep < scored.len() {
            scored.select_nth_unstable_by(keep, worst_first);
            scored.truncate(keep);
        }
        scored.sort_unstable_by(worst_first);
        scored.into_iter().map(|(_, lane)| lane).collect()
    }

    /// What lane `node * WIDTH + lane` holds: its index and count.
    pub(crate) fn holds(&self, id: u32) -> (u32, u32) {
        let (n, k) = (id as usize / WIDTH, id as usize % WIDTH);
        (self.nodes[n].index[k], self.nodes[n].count[k])
    }

    /// What [`Bvh::optimize`] keeps as it moves lanes: see [`Lineage`].
    pub(crate) fn lineage(&self) -> Lineage {
        let mut lineage = Lineage {
            up: alloc::vec![ROOT; self.nodes.len()],
            height: alloc::vec![0; self.nodes.len()],
        };
        for (n, node) in self.nodes.iter().enumerate() {
            for k in (0..WIDTH).filter(|&k| node.count[k] == 0 && node.index[k] != 0) {
                lineage.up[node.index[k] as usize] = (n * WIDTH + k) as u32;
            }
        }
        if !self.nodes.is_empty() {
            self.heights(0, &mut lineage.height);
        }
        lineage
    }

    /// Writes the height of node `n` and of every node under it into `heights`; returns
    /// `n`'s.
    pub(crate) fn heights(&self, n: usize, heights: &mut [u8]) -> u8 {
        let node = &self.nodes[n];
        let below = (0..WIDTH)
            .filter(|&k| node.count[k] == 0 && node.index[k] != 0)
            .map(|k| self.heights(node.index[k] as usize, heights))
            .max()
            .unwrap_or(0);
        heights[n] = below + 1;
        below + 1
    }

    /// Takes lane `id` (`node * WIDTH + lane`) out of its node, and shrinks the boxes above
    /// it to what they still hold (a node left empty is spare, and no lane leads to it). A
    /// subtree's nodes stay where they are, reached from nowhere until placed.
    pub(crate) fn take(&mut self, id: u32, lineage: &mut Lineage) -> Lane {
        self.in_order = false;
        let (mut n, k) = (id as usize / WIDTH, id as usize % WIDTH);
        let node = &mut self.nodes[n];
        let (index, count) = (node.index[k], node.count[k]);
        let taken = Lane {
            index,
            count,
            bounds: node.lane(k),
            height: if count > 0 {
                0
            } else {
                usize::from(lineage.height[index as usize])
            },
        };
        clear(node, k);
        let up = &mut lineage.up;
        while up[n] != ROOT {
            let node = &self.nodes[n];
            let bounds = (0..WIDTH)
                .filter(|&k| in_use(node, k))
                .map(|k| node.lane(k))
                .reduce(|a, b| union(&a, &b));
            let (p, k) = (up[n] as usize / WIDTH, up[n] as usize % WIDTH);
            match bounds {
                Some(bounds) => set_bounds(&mut self.nodes[p], k, bounds),
                None => {
                    clear(&mut self.nodes[p], k);
                    self.spare.push(n as u32);
                    up[n] = ROOT;
                }
            }
            n = p;
        }
        taken
    }
}
