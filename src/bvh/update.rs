//! Scenes that change: a [`Bvh`]'s objects moved and refitted, inserted and removed without
//! a rebuild, each object keeping the number it answers by.

use alloc::collections::BinaryHeap;
use alloc::vec::Vec;
use core::cmp::Reverse;

use super::build::{build, cover, offsets};
use super::{Bounds, Bvh, MAX_DEPTH, Node, Tree, TreeCost, WIDTH, half_area};
use crate::{Aabb, Hittable};

/// What inserting and removing objects needs, made at the first insert or remove (a tree
/// that is only built and refitted never pays for it).
#[derive(Clone, Debug, Default)]
pub(super) struct Links {
    /// Whether they are made.
    made: bool,
    /// For each position in the tree (below `Tree::bounded`), its leaf, as
    /// `node * WIDTH + lane`.
    leaf_of: Vec<u32>,
    /// For each number ever given, the object's position; `u32::MAX` once removed.
    positions: Vec<u32>,
}

/// No position: the object was removed.
const REMOVED: u32 = u32::MAX;

impl<T: Hittable> Bvh<T> {
    /// Lets `edit` change the objects (in the BVH's own order: see
    /// [`Bvh::original_index`]), then refits the tree to where they now are: every box
    /// recomputed bottom up, the tree's shape and the objects' order kept, so every object
    /// answers by the same number as before. The tree answers exactly as the loop over its
    /// objects after any update, as after a build. Where an object in the tree can no
    /// longer be held (its box unbounded or empty, or past `f32`'s range from the others),
    /// the tree is rebuilt instead.
    ///
    /// A refit is linear in the objects and does not allocate, but the tree it keeps was
    /// chosen for where the objects were: watch [`Bvh::cost`], and [`Bvh::rebuild`] when
    /// it has grown too dear.
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Bvh, Hittable, Interval, Ray, Sphere};
    ///
    /// let mut balls: Bvh<Sphere> = (0..10)
    ///     .map(|i| Sphere::new(DVec3::new(f64::from(i), 0.0, 0.0), 0.25).unwrap())
    ///     .collect();
    /// let down = Ray::new(DVec3::new(3.0, 0.0, 5.0), DVec3::NEG_Z);
    /// assert!(balls.hit(&down, Interval::FORWARD).is_some());
    ///
    /// // Every ball moves up by 10; the numbers they answer by stay.
    /// balls.update(|objects| {
    ///     for ball in objects {
    ///         *ball = Sphere::new(ball.center() + DVec3::Z * 10.0, ball.radius()).unwrap();
    ///     }
    /// });
    /// assert!(balls.hit(&down, Interval::FORWARD).is_none());
    /// let from_above = Ray::new(DVec3::new(3.0, 0.0, 20.0), DVec3::NEG_Z);
    /// let (index, hit) = balls.hit_with_index(&from_above, Interval::FORWARD).unwrap();
    /// assert_eq!((index, hit.t), (3, 9.75));
    /// assert!(!balls.cost().needs_rebuild());
    /// ```
    pub fn update(&mut self, edit: impl FnOnce(&mut [T])) {
        edit(&mut self.objects);
        let objects = &self.objects;
        match self.tree.refit(None, |p| objects[p].bounding_box()) {
            Some(bbox) => self.bbox = bbox,
            None => self.rebuild(),
        }
    }

    /// Builds the tree again over the objects where they are now, keeping the numbers they
    /// answer by.
    pub fn rebuild(&mut self) {
        let objects = core::mem::take(&mut self.objects);
        let numbers = core::mem::take(&mut self.tree.order);
        let (made, next) = (self.links.made, self.links.positions.len());
        *self = build(objects, false);
        // The build numbered the objects by the positions it was given them in.
        for number in &mut self.tree.order {
            *number = numbers[*number as usize];
        }
        if made {
            // Numbers once given are not given again.
            self.links.positions = alloc::vec![REMOVED; next];
            self.link();
        }
    }

    /// The tree's cost by the surface area heuristic, now and at its last build: see
    /// [`TreeCost`] for when to [`Bvh::rebuild`].
    #[must_use]
    pub fn cost(&self) -> TreeCost {
        TreeCost {
            built: self.built_cost,
            now: self.tree.sah_cost(),
        }
    }

    /// Mends a tree that updates have worn: every inner box shrunk to what is under it
    /// (after [`Bvh::remove`] they are looser than they need be), then the lanes, leaves
    /// and subtrees alike, that widen their node most, up to `share` (0 to 1) of all the
    /// lanes, taken out and put back, worst first, where the surface area heuristic now
    /// places them, as [`Bvh::insert`] places an object (the reinsertion of Bittner et al.
    /// 2013, "Fast insertion-based optimization of bounding volume hierarchies", made for
    /// nodes of four). Objects keep their numbers and their positions. A `share` of 0 only
    /// shrinks the boxes; a NaN `share` counts as 0.
    ///
    /// Linear in the nodes, plus a search for each lane moved: cheaper than
    /// [`Bvh::rebuild`] at small shares, and worth less (the README's updates tables
    /// measure both, and how much of a rebuild's gain a `share` of 0.1 wins back).
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Bvh, Hittable, Interval, Ray, Sphere};
    ///
    /// let ball = |x: f64, y: f64| Sphere::new(DVec3::new(x, y, 0.0), 0.25).unwrap();
    /// let mut balls: Bvh<Sphere> = (0..100u32).map(|i| ball(f64::from(i), 0.0)).collect();
    /// // Half of the balls leave the row for a column far from it.
    /// for i in (0..100u32).step_by(2) {
    ///     balls.remove(i as usize);
    ///     balls.insert(ball(-100.0, f64::from(i)));
    /// }
    /// let worn = balls.cost().now;
    /// balls.optimize(0.25);
    /// assert!(balls.cost().now < worn);
    /// let ray = Ray::new(DVec3::new(-100.0, 42.0, 5.0), DVec3::NEG_Z);
    /// assert_eq!(balls.hit_with_index(&ray, Interval::FORWARD).unwrap().1.t, 4.75);
    /// ```
    pub fn optimize(&mut self, share: f64) {
        if self.tree.nodes.is_empty() {
            return;
        }
        // Shrinking may leave nodes empty, and the tree shallower.
        self.tree.depth = self.tree.tighten(0).map_or(1, |(_, height)| height);
        // What the worst lanes hold: found again by it, as lanes move.
        let worst: Vec<(u32, u32)> = (self.tree.worst_lanes(share).into_iter())
            .map(|id| self.tree.holds(id))
            .collect();
        if worst.is_empty() {
            return;
        }
        self.link();
        let mut lineage = self.tree.lineage();
        for (index, count) in worst {
            let id = if count > 0 {
                self.links.leaf_of[index as usize]
            } else {
                lineage.up[index as usize]
            };
            // A node left empty, and spare, by an earlier take.
            if id == ROOT || self.tree.holds(id) != (index, count) {
                continue;
            }
            let lane = self.tree.take(id, &mut lineage);
            let Some(placed) = self.tree.place(lane, Some(&mut lineage)) else {
                // Past the deepest tree the traversal's stack holds.
                return self.rebuild();
            };
            self.placed(&lane, &placed);
        }
        // Heights only grew as lanes came and went: the true depth.
        self.tree.depth = self.tree.tighten(0).map_or(1, |(_, height)| height);
    }

    /// Adds `object` and returns the number it answers by (in [`Bvh::hit_with_index`]
    /// and [`Bvh::original_index`]): the next after every number given so far, the first
    /// being `len()` of the `Vec` given to [`Bvh::new`]. Placed where it adds least to the
    /// tree's cost by the surface area heuristic (in a free lane of a node, or with a leaf
    /// in a new node in that leaf's place), found by a branch-and-bound search from the
    /// root; the boxes on the way down grow to hold it. An unbounded object is tested on
    /// every ray, as at a build.
    ///
    /// Insertions in a row make a tree worse than a build would: watch [`Bvh::cost`], and
    /// [`Bvh::optimize`] or [`Bvh::rebuild`].
    ///
    /// # Panics
    /// If `u32::MAX` numbers have been given.
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Bvh, Hittable, Interval, Ray, Sphere};
    ///
    /// let ball = |x: f64| Sphere::new(DVec3::new(x, 0.0, 0.0), 0.25).unwrap();
    /// let mut balls = Bvh::new(vec![ball(0.0), ball(1.0)]);
    /// let third = balls.insert(ball(2.0));
    /// assert_eq!(third, 2);
    /// let ray = Ray::new(DVec3::new(2.0, 0.0, 5.0), DVec3::NEG_Z);
    /// assert_eq!(balls.hit_with_index(&ray, Interval::FORWARD).unwrap().0, third);
    ///
    /// // Removed, it is hit no more; its number is not given again.
    /// assert!(balls.remove(third).is_some());
    /// assert!(balls.hit(&ray, Interval::FORWARD).is_none());
    /// assert_eq!(balls.insert(ball(2.0)), 3);
    /// ```
    pub fn insert(&mut self, object: T) -> usize {
        self.link();
        let number = self.links.positions.len();
        let number32 = u32::try_from(number)
            .ok()
            .filter(|&n| n != REMOVED)
            .expect("a Bvh gives at most u32::MAX numbers");
        let b = object.bounding_box();
        self.bbox = self.bbox.union(&b);
        let last = self.objects.len();
        self.objects.push(object);
        self.tree.order.push(number32);
        self.links.positions.push(last as u32);
        let Some(bounds) = self.tree.lane_bounds(&b) else {
            // Tested on every ray, after the tree's objects.
            return number;
        };
        // Into the tree's part, at its end: the first unbounded object (if any) moves to
        // the end of the list.
        let at = self.tree.bounded;
        self.swap(at, last);
        self.tree.bounded += 1;
        self.links.leaf_of.push(0);
        let lane = Lane::leaf(at, bounds);
        match self.tree.place(lane, None) {
            Some(placed) => self.placed(&lane, &placed),
            // Past the deepest tree the traversal's stack holds.
            None => self.rebuild(),
        }
        number
    }

    /// Removes the object numbered `number` (as [`Bvh::hit_with_index`] names it) and
    /// returns it; `None` for a number never given or already removed. The other objects
    /// keep their numbers. The boxes above it keep their size until the next
    /// [`Bvh::update`], [`Bvh::optimize`] or [`Bvh::rebuild`] (still holding every object:
    /// only looser).
    pub fn remove(&mut self, number: usize) -> Option<T> {
        self.link();
        let p = *self
            .links
            .positions
            .get(number)
            .filter(|&&p| p != REMOVED)? as usize;
        if p < self.tree.bounded {
            // Out of its leaf: to the leaf's last position, which the leaf gives up.
            let leaf = self.links.leaf_of[p];
            let (first, count) = self.tree.lane(leaf);
            let q = first + count - 1;
            self.swap(p, q);
            self.tree.shrink(leaf);
            // The tree's last object fills that position: it leaves its own leaf (the
            // last position of it, as of the whole tree) for a leaf of its own there.
            let b = self.tree.bounded - 1;
            if q != b {
                self.swap(q, b);
                let other = self.links.leaf_of[b];
                if self.tree.lane(other).1 == 1 {
                    self.tree.move_leaf(other, q as u32);
                    self.links.leaf_of[q] = other;
                } else {
                    self.tree.shrink(other);
                    let bounds = self.tree.lane_bounds(&self.objects[q].bounding_box());
                    // It was in the tree, about the same origin: its bounds are finite.
                    let lane = bounds.map(|bounds| Lane::leaf(q, bounds));
                    let placed = lane.and_then(|lane| Some((lane, self.tree.place(lane, None)?)));
                    let Some((lane, placed)) = placed else {
                        self.tree.bounded = b;
                        self.links.leaf_of.truncate(b);
                        return self.remove_last_and_rebuild(b);
                    };
                    self.placed(&lane, &placed);
                }
            }
            self.tree.bounded = b;
            self.links.leaf_of.truncate(b);
            // Now first among the unbounded: swapped with the last of them below.
            debug_assert_eq!(self.links.positions[number] as usize, b);
        }
        let p = self.links.positions[number] as usize;
        let last = self.objects.len() - 1;
        self.swap(p, last);
        self.tree.order.pop();
        self.links.positions[number] = REMOVED;
        self.objects.pop()
    }

    /// Finishes a removal whose object sits at `position`, out of the tree, by a rebuild
    /// (a leaf could not be placed within the deepest tree the traversal's stack holds).
    #[cold]
    fn remove_last_and_rebuild(&mut self, position: usize) -> Option<T> {
        let last = self.objects.len() - 1;
        let number = self.tree.order[position] as usize;
        self.swap(position, last);
        self.tree.order.pop();
        self.links.positions[number] = REMOVED;
        let removed = self.objects.pop();
        self.rebuild();
        removed
    }

    /// Records where [`Tree::place`] put `lane`, and the leaf it moved.
    fn placed(&mut self, lane: &Lane, placed: &Placed) {
        let leaf_of = &mut self.links.leaf_of;
        // A subtree's nodes stay where they are: only a leaf changes its name.
        let mut name = |lane: &Lane, id: u32| {
            if lane.count > 0 {
                leaf_of[lane.index as usize..(lane.index + lane.count) as usize].fill(id);
            }
        };
        name(lane, placed.lane);
        if let Some((kept, node)) = &placed.pair {
            name(kept, node * WIDTH as u32);
        }
    }

    /// Swaps the objects at positions `a` and `b`, and what names them.
    fn swap(&mut self, a: usize, b: usize) {
        self.objects.swap(a, b);
        self.tree.order.swap(a, b);
        for p in [a, b] {
            self.links.positions[self.tree.order[p] as usize] = p as u32;
        }
    }

    /// Makes the links, if they are not made yet (keeping `positions`' length, the next
    /// number, where it is longer than the numbers in use need).
    fn link(&mut self) {
        let links = &mut self.links;
        if links.made {
            return;
        }
        let next = self
            .tree
            .order
            .iter()
            .map(|&n| n as usize + 1)
            .max()
            .unwrap_or(0);
        links
            .positions
            .resize(next.max(links.positions.len()), REMOVED);
        for (p, &number) in self.tree.order.iter().enumerate() {
            links.positions[number as usize] = p as u32;
        }
        links.leaf_of = alloc::vec![0; self.tree.bounded];
        for (n, node) in self.tree.nodes.iter().enumerate() {
            for k in 0..WIDTH {
                let (first, count) = (node.index[k] as usize, node.count[k] as usize);
                links.leaf_of[first..first + count].fill((n * WIDTH + k) as u32);
            }
        }
        links.made = true;
    }
}

/// Where [`Tree::place`] put a lane.
struct Placed {
    /// The lane it took, as `node * WIDTH + lane`.
    lane: u32,
    /// Where it was paired with what a lane held: that (now in lane 0 of the new node),
    /// and the new node.
    pair: Option<(Lane, u32)>,
}

impl Tree {
    /// `b` as a leaf's bounds about the tree's origin, rounded outward, with the tree's
    /// rounding and compactness grown to cover them; `None` where `b` is not bounded or
    /// lies past `f32`'s range from the origin (such an object is tested on every ray). A
    /// tree without nodes takes `b`'s centre as its origin first.
    fn lane_bounds(&mut self, b: &Aabb) -> Option<Bounds> {
        if !b.is_bounded() {
            return None;
        }
        if self.nodes.is_empty() {
            self.origin = 0.5 * b.min() + 0.5 * b.max();
            (self.rounding, self.compact) = ([0.0; 3], true);
        }
        let bounds = offsets(b, self.origin)?;
        cover(&mut self.rounding, &mut self.compact, self.origin, &bounds);
        Some(bounds)
    }

    /// The first position and count of the leaf `node * WIDTH + lane`.
    fn lane(&self, leaf: u32) -> (usize, usize) {
        let (n, k) = (leaf as usize / WIDTH, leaf as usize % WIDTH);
        (
            self.nodes[n].index[k] as usize,
            self.nodes[n].count[k] as usize,
        )
    }

    /// Takes the last position off a leaf; a leaf left with none becomes an unused lane.
    fn shrink(&mut self, leaf: u32) {
        self.in_order = false;
        let (n, k) = (leaf as usize / WIDTH, leaf as usize % WIDTH);
        let node = &mut self.nodes[n];
        node.count[k] -= 1;
        if node.count[k] == 0 {
            clear(node, k);
        }
    }

    /// Moves a leaf of one object to position `to`.
    fn move_leaf(&mut self, leaf: u32, to: u32) {
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
    fn place(&mut self, lane: Lane, lineage: Option<&mut Lineage>) -> Option<Placed> {
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
    fn best_spot(
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
    fn tighten(&mut self, n: usize) -> Option<(Bounds, usize)> {
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

    /// The lanes (leaves and subtrees) whose nodes' boxes shrink most without them (in
    /// surface area), the `share` of all lanes in use at most, worst first; only those
    /// whose node does shrink.
    fn worst_lanes(&self, share: f64) -> Vec<u32> {
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
    fn holds(&self, id: u32) -> (u32, u32) {
        let (n, k) = (id as usize / WIDTH, id as usize % WIDTH);
        (self.nodes[n].index[k], self.nodes[n].count[k])
    }

    /// What [`Bvh::optimize`] keeps as it moves lanes: see [`Lineage`].
    fn lineage(&self) -> Lineage {
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
    fn heights(&self, n: usize, heights: &mut [u8]) -> u8 {
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
    fn take(&mut self, id: u32, lineage: &mut Lineage) -> Lane {
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

/// For each node, the lane that leads to it (as `node * WIDTH + lane`; [`ROOT`] for the
/// root and for nodes no lane leads to) and its height (the levels of nodes from it
/// down; at least that, as lanes leave), kept by [`Bvh::optimize`] as it moves lanes.
struct Lineage {
    up: Vec<u32>,
    height: Vec<u8>,
}

impl Lineage {
    /// Records that [`Tree::place`] put `lane` in lane `k` of node `n` (of `nodes` in all),
    /// as `placed` says: the lanes that now lead to moved and new nodes, and the heights
    /// above them.
    fn placed(&mut self, nodes: usize, n: usize, k: usize, lane: &Lane, placed: &Placed) {
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
struct Lane {
    index: u32,
    count: u32,
    bounds: Bounds,
    height: usize,
}

impl Lane {
    /// A leaf of one object.
    fn leaf(position: usize, bounds: Bounds) -> Self {
        Self {
            index: position as u32,
            count: 1,
            bounds,
            height: 0,
        }
    }

    /// What the surface area heuristic weighs the lane's area by: its objects' tests, or
    /// a node's visit.
    fn weight(&self, traversal_cost: f64) -> f64 {
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
const SEARCH: usize = 256;

/// A node [`Tree::place`]'s search reached: which, at what level, and by which lane of
/// which earlier visit.
#[derive(Clone, Copy, Debug)]
struct Visit {
    node: u32,
    level: u32,
    from: u32,
    lane: u8,
}

/// The root's visit comes from no other.
const ROOT: u32 = u32::MAX;

/// Where in a node [`Tree::place`] puts a lane.
#[derive(Clone, Copy, Debug)]
enum Spot {
    /// In this unused lane.
    Free(usize),
    /// With what this lane holds (of the height given), in a new node in its place.
    Pair(usize, usize),
}

/// The box of no lane.
const EMPTY: Bounds = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// The smallest box holding `a` and `b`.
fn union(a: &Bounds, b: &Bounds) -> Bounds {
    (
        [0, 1, 2].map(|i| a.0[i].min(b.0[i])),
        [0, 1, 2].map(|i| a.1[i].max(b.1[i])),
    )
}

/// A node of four unused lanes.
fn empty_node() -> Node {
    let mut node = Node {
        bounds: [[0.0; WIDTH]; 6],
        index: [0; WIDTH],
        count: [0; WIDTH],
    };
    for k in 0..WIDTH {
        clear(&mut node, k);
    }
    node
}

/// Makes lane `k` unused: no object, an empty box.
fn clear(node: &mut Node, k: usize) {
    node.index[k] = 0;
    node.count[k] = 0;
    for a in 0..3 {
        node.bounds[a][k] = f32::INFINITY;
        node.bounds[3 + a][k] = f32::NEG_INFINITY;
    }
}

/// Whether lane `k` holds a leaf or a node (the root, node 0, is no one's child).
fn in_use(node: &Node, k: usize) -> bool {
    node.count[k] > 0 || node.index[k] != 0
}

fn set_lane(node: &mut Node, k: usize, lane: &Lane) {
    node.index[k] = lane.index;
    node.count[k] = lane.count;
    set_bounds(node, k, lane.bounds);
}

fn set_bounds(node: &mut Node, k: usize, (min, max): Bounds) {
    for a in 0..3 {
        node.bounds[a][k] = min[a];
        node.bounds[3 + a][k] = max[a];
    }
}

/// Grows lane `k`'s box to hold `bounds`.
fn grow(node: &mut Node, k: usize, bounds: Bounds) {
    set_bounds(node, k, union(&node.lane(k), &bounds));
}

#[cfg(test)]
mod tests {
    use super::{REMOVED, WIDTH};
    use crate::math::Dd;
    use crate::{Bvh, Hittable, Sphere};
    use glam::DVec3;
    use proptest::prelude::*;

    /// What every tree must hold, however it was changed: each position of the tree in
    /// exactly one leaf, which the links name; each object's box inside every lane on its
    /// way down (as traversal computes them: `origin + bound` in `f64`); the rounding the
    /// `f32` lanes allow for covering every bound's; no more levels than `depth`; and every
    /// live number at the position that holds it. Returns the levels of nodes.
    fn check(bvh: &Bvh<Sphere>) -> Result<usize, TestCaseError> {
        let tree = &bvh.tree;
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
                        if bvh.links.made {
                            prop_assert_eq!(bvh.links.leaf_of[p] as usize, n * WIDTH + k);
                        }
                        let b = bvh.objects[p].bounding_box();
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
                        prop_assert!(error <= tree.rounding[a]);
                    }
                }
            }
        }
        prop_assert!(
            seen.iter().all(|&s| s == 1),
            "a position in no leaf or in two"
        );
        if bvh.links.made {
            for (number, &p) in bvh.links.positions.iter().enumerate() {
                if p != REMOVED {
                    prop_assert_eq!(bvh.tree.order[p as usize] as usize, number);
                }
            }
        }
        Ok(levels)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100))]

        /// Random inserts (near the others, far away, tiny and huge), removes and
        /// optimizations keep every invariant of the tree; an optimization changes no
        /// object's position.
        #[test]
        fn inserts_removes_and_optimizations_keep_the_tree_whole(
            start in prop::collection::vec((prop::array::uniform3(-1.0f64..1.0), 1e-3f64..1.0), 0..30),
            offset in prop_oneof![Just(0.0), Just(1.7e6), Just(3.3e12)],
            changes in prop::collection::vec((0u8..9, prop::array::uniform3(-1.0f64..1.0), -6i32..6, any::<usize>()), 1..60),
        ) {
            let ball = |c: [f64; 3], r: f64| Sphere::new(DVec3::from(c) * 10.0 + offset, r).unwrap();
            let mut bvh = Bvh::new(start.iter().map(|&(c, r)| ball(c, r)).collect());
            check(&bvh)?;
            let mut live: Vec<usize> = (0..start.len()).collect();
            for (change, c, scale, pick) in changes {
                if change == 8 {
                    let order = bvh.tree.order.clone();
                    // Shares from none to all, and past both ends.
                    bvh.optimize([0.0, 0.1, 0.5, 1.0, 2.0, -1.0, f64::NAN][pick % 7]);
                    prop_assert_eq!(&bvh.tree.order, &order);
                    // The depth made exact again.
                    prop_assert_eq!(check(&bvh)?, bvh.tree.depth);
                } else if change < 4 || live.is_empty() {
                    let number = bvh.insert(ball(c, 10f64.powi(scale)));
                    live.push(number);
                } else {
                    let number = live.swap_remove(pick % live.len());
                    prop_assert!(bvh.remove(number).is_some());
                    prop_assert!(bvh.remove(number).is_none());
                }
                prop_assert_eq!(bvh.len(), live.len());
                check(&bvh)?;
            }
        }
    }
}
