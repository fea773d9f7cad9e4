//! Refitting: a tree's boxes recomputed for objects that moved, its shape kept; and the
//! surface-area cost that says when a refitted tree has grown worse than a rebuilt one.

use glam::DVec3;

use super::node::{Bounds, Node, Reach, half_area, offsets};
use super::{Tree, WIDTH};
use crate::Aabb;

impl Tree {
    /// Recomputes every node's boxes from `box_of` (by position in the tree's order),
    /// bottom up, about `centre` (or, where it is `None`, the centre of the new boxes of
    /// the objects in the tree, found by a first pass over them), keeping the tree's shape
    /// and order; returns the union of all the boxes, as [`Tree::build`] does. After the
    /// first pass, `box_of` is called once for each position, in increasing order for a
    /// tree as the build made it (`in_order`), so that a caller can compute what else it
    /// keeps per object along the way.
    ///
    /// `None` where an object in the tree no longer has a bounded box, or has one past
    /// `f32`'s range from the centre: the tree then holds boxes that may not contain
    /// their objects, and the caller must rebuild it.
    pub(crate) fn refit(
        &mut self,
        centre: Option<DVec3>,
        mut box_of: impl FnMut(usize) -> Aabb,
    ) -> Option<Aabb> {
        let mut refit = Refit {
            all: Aabb::EMPTY,
            reach: Reach::NONE,
            next: 0,
            in_order: true,
        };
        if !self.nodes.is_empty() {
            // Centred as the build centres: the offsets keep their precision however far
            // the objects have moved.
            self.origin = match centre {
                Some(centre) => centre,
                None => {
                    let bounded = (0..self.bounded).fold(Aabb::EMPTY, |b, p| b.union(&box_of(p)));
                    0.5 * bounded.min() + 0.5 * bounded.max()
                }
            };
            if !self.origin.is_finite() {
                return None;
            }
            refit.in_order = self.in_order;
            refit.node(&mut self.nodes, 0, self.origin, &mut box_of)?;
            self.reach = refit.reach;
        }
        for p in self.bounded..self.order.len() {
            refit.all = refit.all.union(&box_of(p));
        }
        Some(refit.all)
    }

    /// The tree's expected cost for a ray that meets its box, by the surface area
    /// heuristic: node visits (each weighted as the build weighs them against one object
    /// test) and object tests, each weighted by the chance that a ray through the root's box
    /// enters the box it is behind (the ratio of their surface areas). 0 for a tree of no
    /// bounded objects.
    pub(crate) fn sah_cost(&self) -> f64 {
        let Some(root) = self.nodes.first() else {
            return 0.0;
        };
        let root_area = half_area(&(0..WIDTH).map(|k| root.lane(k)).fold(
            ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
            |(lo, hi), (min, max)| {
                (
                    [0, 1, 2].map(|a| lo[a].min(min[a])),
                    [0, 1, 2].map(|a| hi[a].max(max[a])),
                )
            },
        ));
        let mut cost = 0.0;
        for node in &self.nodes {
            for k in 0..WIDTH {
                let weight = if node.count[k] > 0 {
                    f64::from(node.count[k])
                } else if node.index[k] != 0 {
                    self.traversal_cost
                } else {
                    continue;
                };
                cost += half_area(&node.lane(k)) * weight;
            }
        }
        // A flat tree (every object in one point, say) has no area to weigh by: each ray
        // that meets it meets everything.
        if root_area > 0.0 {
            self.traversal_cost + cost / root_area
        } else {
            self.traversal_cost + self.bounded as f64
        }
    }
}

/// A refit under way: what it has gathered, and the next position it expects.
struct Refit {
    /// The union of the objects' boxes so far.
    all: Aabb,
    /// As `Tree::reach`, over the leaves' bounds so far (an inner bound is a copy of one of
    /// its leaves').
    reach: Reach,
    /// Where the tree meets its leaves in the objects' order: the position it expects next.
    next: usize,
    in_order: bool,
}

impl Refit {
    /// Refits node `n` and everything under it, lane by lane, depth first (so that the
    /// leaves come in the objects' order); returns the node's box (lower bounds, upper
    /// bounds), or `None` where an object cannot be held (see [`Tree::refit`]).
    fn node(
        &mut self,
        nodes: &mut [Node],
        n: usize,
        origin: DVec3,
        box_of: &mut impl FnMut(usize) -> Aabb,
    ) -> Option<Bounds> {
        let (mut node_min, mut node_max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for k in 0..WIDTH {
            let (index, count) = (nodes[n].index[k], nodes[n].count[k]);
            let (min, max) = if count > 0 {
                let first = index as usize;
                debug_assert!(!self.in_order || first == self.next);
                let b =
                    (first..first + count as usize).fold(Aabb::EMPTY, |b, p| b.union(&box_of(p)));
                self.next = first + count as usize;
                let bounds = offsets(&b, origin)?;
                self.all = self.all.union(&b);
                self.reach.cover(origin, &bounds);
                bounds
            } else if index != 0 {
                // An inner child (the root, node 0, is no one's child).
                self.node(nodes, index as usize, origin, box_of)?
            } else {
                // An unused lane keeps its empty box.
                continue;
            };
            let node = &mut nodes[n];
            for a in 0..3 {
                node.bounds[a][k] = min[a];
                node.bounds[3 + a][k] = max[a];
                node_min[a] = node_min[a].min(min[a]);
                node_max[a] = node_max[a].max(max[a]);
            }
        }
        Some((node_min, node_max))
    }
}

#[cfg(test)]
mod tests {
    use super::super::build::Shape;
    use super::{Tree, WIDTH};
    use crate::Aabb;
    use glam::DVec3;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// After a refit to boxes moved anywhere (another offset to 1e12, another size),
        /// every lane's box, as traversal computes it in `f64` (`origin + bound`), holds
        /// every object under it exactly; and the tree is the one a build would make of
        /// the same shape: the same order, the same depth.
        #[test]
        fn refitted_boxes_hold_their_objects_exactly(
            boxes in prop::collection::vec(
                (prop::array::uniform3(-1.0f64..1.0), prop::array::uniform3(-6.0f64..0.0)),
                1..60,
            ),
            from in prop_oneof![Just(0.0), Just(1e6), Just(-3.3e12)],
            to in prop_oneof![Just(0.0), Just(1234.5), Just(7.7e9), Just(1.7e12)],
            scale in prop_oneof![Just(1e-3), Just(1.0), Just(1e3)],
            jitter in any::<u64>(),
        ) {
            let place = |offset: f64, size: f64, k: usize| {
                let (c, e) = boxes[k];
                let wobble = ((jitter >> (k % 60)) & 1) as f64 * 0.37;
                let c = (DVec3::from(c) + wobble) * size + DVec3::splat(offset);
                let half = DVec3::from(e.map(|e| 10f64.powf(e))) * size;
                Aabb::new(c - half, c + half)
            };
            let before: Vec<Aabb> = (0..boxes.len()).map(|k| place(from, 1.0, k)).collect();
            let after: Vec<Aabb> = (0..boxes.len()).map(|k| place(to, scale, k)).collect();
            let (mut tree, _) = Tree::build(before.len(), |i| before[i], Shape::OBJECTS, false);
            let (order, depth) = (tree.order.clone(), tree.depth);
            let all = tree.refit(None, |p| after[order[p] as usize]);
            let union = after.iter().fold(Aabb::EMPTY, |b, a| b.union(a));
            prop_assert_eq!(all, Some(union));
            prop_assert_eq!((&tree.order, tree.depth), (&order, depth));
            let o = tree.origin;
            // Every object under a lane, found by walking down from it.
            fn objects(tree: &Tree, node: usize, k: usize, out: &mut Vec<usize>) {
                let (index, count) = (tree.nodes[node].index[k], tree.nodes[node].count[k]);
                if count > 0 {
                    out.extend(index as usize..(index + count) as usize);
                } else if index != 0 {
                    for k in 0..WIDTH {
                        objects(tree, index as usize, k, out);
                    }
                }
            }
            for n in 0..tree.nodes.len() {
                for k in 0..WIDTH {
                    let mut under = Vec::new();
                    objects(&tree, n, k, &mut under);
                    let bounds = &tree.nodes[n].bounds;
                    let mut held = Aabb::EMPTY;
                    for p in under {
                        let b = after[order[p] as usize];
                        held = held.union(&b);
                        for a in 0..3 {
                            prop_assert!(o[a] + f64::from(bounds[a][k]) <= b.min()[a]);
                            prop_assert!(o[a] + f64::from(bounds[3 + a][k]) >= b.max()[a]);
                        }
                    }
                    if held.is_empty() {
                        continue;
                    }
                    for a in 0..3 {
                        // Tight, as about the new centre: each bound within an f32 ulp of
                        // the scene's reach from it (2^-23 of it; twice that for the
                        // outward step) and an f64 ulp or two of the centre, of the
                        // objects' own. About a stale centre far away, it would be off by
                        // the f32 ulps of that distance.
                        let centre = 0.5 * union.min()[a] + 0.5 * union.max()[a];
                        let reach = union.max()[a] - centre;
                        let slack = reach * 2f64.powi(-22) + 4.0 * centre.abs() * f64::EPSILON;
                        prop_assert!(held.min()[a] - (o[a] + f64::from(bounds[a][k])) <= slack);
                        prop_assert!((o[a] + f64::from(bounds[3 + a][k])) - held.max()[a] <= slack);
                    }
                }
            }
            // The rounding the lanes allow for covers every bound's, about the new centre.
            for node in &tree.nodes {
                for (side, bounds) in node.bounds.iter().enumerate() {
                    for &f in bounds.iter().filter(|f| f.is_finite()) {
                        let a = side % 3;
                        let error = crate::math::Dd::diff(o[a], -f64::from(f)).lo.abs();
                        prop_assert!(error <= tree.reach.rounding[a]);
                    }
                }
            }
        }
    }

    /// An object whose box becomes unbounded cannot be refitted: the caller rebuilds.
    #[test]
    fn an_unbounded_box_asks_for_a_rebuild() {
        let boxes = [
            Aabb::new(DVec3::ZERO, DVec3::ONE),
            Aabb::new(DVec3::X, DVec3::splat(2.0)),
        ];
        let (mut tree, _) = Tree::build(2, |i| boxes[i], Shape::OBJECTS, false);
        assert!(
            tree.refit(None, |p| if p == 0 { Aabb::UNIVERSE } else { boxes[1] })
                .is_none()
        );
        let (mut tree, _) = Tree::build(2, |i| boxes[i], Shape::OBJECTS, false);
        assert!(tree.refit(None, |_| Aabb::EMPTY).is_none());
    }

    /// A refit to where the objects were built keeps the cost the build had, and spreading
    /// them apart while keeping the tree raises it.
    #[test]
    fn the_cost_rises_as_a_refitted_tree_loses_its_grouping() {
        let boxes: Vec<Aabb> = (0..200)
            .map(|i| {
                let c = DVec3::new(
                    f64::from(i % 10),
                    f64::from(i / 10 % 10),
                    f64::from(i / 100),
                );
                Aabb::new(c, c + 0.5)
            })
            .collect();
        let (mut tree, _) = Tree::build(boxes.len(), |i| boxes[i], Shape::OBJECTS, false);
        let built = tree.sah_cost();
        let order = tree.order.clone();
        tree.refit(None, |p| boxes[order[p] as usize]).unwrap();
        assert_eq!(tree.sah_cost(), built);
        // Each object sent to the place of another, far from the ones it is grouped with.
        let shuffled = |p: usize| boxes[(order[p] as usize * 73) % boxes.len()];
        tree.refit(None, shuffled).unwrap();
        let (fresh, _) = Tree::build(boxes.len(), shuffled, Shape::OBJECTS, false);
        assert!(
            tree.sah_cost() > 1.5 * fresh.sah_cost(),
            "{} vs {}",
            tree.sah_cost(),
            fresh.sah_cost()
        );
    }
}
