//! Scenes that change: a [`Bvh`]'s objects moved and refitted, inserted and removed without
//! a rebuild, each object keeping the number it answers by.

use alloc::vec::Vec;

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

    /// Adds `object` and returns the number it answers by (in [`Bvh::hit_with_index`]
    /// and [`Bvh::original_index`]): the next after every number given so far, the first
    /// being `len()` of the `Vec` given to [`Bvh::new`]. Placed beside the leaf whose box
    /// grows least to take it (the surface area heuristic's greedy choice), in a free lane
    /// of that leaf's node or in a new node in the leaf's place; an unbounded object is
    /// tested on every ray, as at a build. The boxes on the way down grow to hold it.
    ///
    /// Insertions in a row make a tree worse than a build would: watch [`Bvh::cost`].
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
        match self.tree.place(at as u32, bounds) {
            Some(placed) => self.placed(at, placed),
            // Past the deepest tree the traversal's stack holds.
            None => self.rebuild(),
        }
        number
    }

    /// Removes the object numbered `number` (as [`Bvh::hit_with_index`] names it) and
    /// returns it; `None` for a number never given or already removed. The other objects
    /// keep their numbers. The boxes above it keep their size until the next
    /// [`Bvh::update`] or [`Bvh::rebuild`] (still holding every object: only looser).
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
                    let placed = bounds.and_then(|bounds| self.tree.place(q as u32, bounds));
                    let Some(placed) = placed else {
                        self.tree.bounded = b;
                        self.links.leaf_of.truncate(b);
                        return self.remove_last_and_rebuild(b);
                    };
                    self.placed(q, placed);
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

    /// Records where [`Tree::place`] put the leaf of the object at `position`.
    fn placed(&mut self, position: usize, placed: Placed) {
        self.links.leaf_of[position] = placed.leaf;
        if let Some((first, count, to)) = placed.moved {
            self.links.leaf_of[first..first + count].fill(to);
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

/// Where [`Tree::place`] put a leaf.
struct Placed {
    /// The new leaf, as `node * WIDTH + lane`.
    leaf: u32,
    /// The leaf that moved into a new node to make room: its first position, its count,
    /// and where it is now.
    moved: Option<(usize, usize, u32)>,
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

    /// Places a leaf of the one object at `position` with `bounds`: down the tree, into the
    /// lane whose box grows least (in surface area) to take it, growing each lane on the
    /// way; at a leaf, beside it in a free lane of its node, or with it in a new node in
    /// its place. Returns the new leaf, and the leaf that moved into a new node (its first
    /// position, count, and where it is now); `None` where the tree would grow deeper than
    /// its traversal's stack holds (nothing is placed, and the boxes on the way may have
    /// grown: the caller rebuilds).
    fn place(&mut self, position: u32, bounds: Bounds) -> Option<Placed> {
        self.in_order = false;
        if self.nodes.is_empty() {
            self.nodes.push(empty_node());
            self.depth = 1;
        }
        let mut n = 0;
        let mut level = 1;
        loop {
            let node = &self.nodes[n];
            let free = (0..WIDTH).find(|&k| !in_use(node, k));
            let best = (0..WIDTH)
                .filter(|&k| in_use(node, k))
                .map(|k| (growth(node, k, &bounds), k))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, k)| k);
            let Some(best) = best else {
                // A node emptied by removals.
                set_leaf(&mut self.nodes[n], 0, position, 1, bounds);
                let leaf = (n * WIDTH) as u32;
                return Some(Placed { leaf, moved: None });
            };
            if node.count[best] == 0 {
                // An inner lane: grow it and go down.
                grow(&mut self.nodes[n], best, bounds);
                n = self.nodes[n].index[best] as usize;
                level += 1;
                continue;
            }
            if let Some(k) = free {
                set_leaf(&mut self.nodes[n], k, position, 1, bounds);
                let leaf = (n * WIDTH + k) as u32;
                return Some(Placed { leaf, moved: None });
            }
            // A new node in the leaf's place, holding it and the new one.
            if level + 1 > MAX_DEPTH || self.nodes.len() >= u32::MAX as usize {
                return None;
            }
            let m = self.nodes.len();
            let old = &self.nodes[n];
            let (first, count) = (old.index[best], old.count[best]);
            let old_bounds = old.lane(best);
            let mut node = empty_node();
            set_leaf(&mut node, 0, first, count, old_bounds);
            set_leaf(&mut node, 1, position, 1, bounds);
            self.nodes.push(node);
            let parent = &mut self.nodes[n];
            parent.count[best] = 0;
            parent.index[best] = m as u32;
            grow(parent, best, bounds);
            self.depth = self.depth.max(level + 1);
            let moved = (first as usize, count as usize, (m * WIDTH) as u32);
            let leaf = (m * WIDTH + 1) as u32;
            return Some(Placed {
                leaf,
                moved: Some(moved),
            });
        }
    }
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

fn set_leaf(node: &mut Node, k: usize, first: u32, count: u32, (min, max): Bounds) {
    node.index[k] = first;
    node.count[k] = count;
    for a in 0..3 {
        node.bounds[a][k] = min[a];
        node.bounds[3 + a][k] = max[a];
    }
}

/// Grows lane `k`'s box to hold `bounds`.
fn grow(node: &mut Node, k: usize, (min, max): Bounds) {
    for a in 0..3 {
        node.bounds[a][k] = node.bounds[a][k].min(min[a]);
        node.bounds[3 + a][k] = node.bounds[3 + a][k].max(max[a]);
    }
}

/// How much lane `k`'s box grows, in surface area, to hold `bounds`; ties (no growth) go
/// to the smaller box, by a term far below any growth.
fn growth(node: &Node, k: usize, (min, max): &Bounds) -> f64 {
    let (lo, hi) = node.lane(k);
    let before = half_area(&(lo, hi));
    let after = half_area(&(
        [0, 1, 2].map(|a| lo[a].min(min[a])),
        [0, 1, 2].map(|a| hi[a].max(max[a])),
    ));
    (after - before) + before * f64::EPSILON
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
    /// live number at the position that holds it.
    fn check(bvh: &Bvh<Sphere>) -> Result<(), TestCaseError> {
        let tree = &bvh.tree;
        let mut seen = vec![0u32; tree.bounded];
        // (node, boxes of the lanes above it)
        let mut stack = vec![(0usize, 1usize, Vec::<(DVec3, DVec3)>::new())];
        while let Some((n, level, above)) = stack.pop().filter(|_| !tree.nodes.is_empty()) {
            prop_assert!(level <= tree.depth);
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
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100))]

        /// Random inserts (near the others, far away, tiny and huge) and removes keep every
        /// invariant of the tree.
        #[test]
        fn inserts_and_removes_keep_the_tree_whole(
            start in prop::collection::vec((prop::array::uniform3(-1.0f64..1.0), 1e-3f64..1.0), 0..30),
            offset in prop_oneof![Just(0.0), Just(1.7e6), Just(3.3e12)],
            changes in prop::collection::vec((any::<bool>(), prop::array::uniform3(-1.0f64..1.0), -6i32..6, any::<usize>()), 1..60),
        ) {
            let ball = |c: [f64; 3], r: f64| Sphere::new(DVec3::from(c) * 10.0 + offset, r).unwrap();
            let mut bvh = Bvh::new(start.iter().map(|&(c, r)| ball(c, r)).collect());
            check(&bvh)?;
            let mut live: Vec<usize> = (0..start.len()).collect();
            for (insert, c, scale, pick) in changes {
                if insert || live.is_empty() {
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
