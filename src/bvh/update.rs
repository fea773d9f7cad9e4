//! Scenes that change: a [`Bvh`]'s objects moved and refitted, inserted and removed without
//! a rebuild, each object keeping the number it answers by.

use alloc::vec::Vec;

use super::Bvh;
use crate::Hittable;
use crate::TreeCost;
use crate::tree::{Lane, Placed, ROOT, WIDTH};

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
        *self = Self::built(objects, false);
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
    /// nodes of eight). Objects keep their numbers and their positions. A `share` of 0 only
    /// shrinks the boxes; a NaN `share` counts as 0.
    ///
    /// Linear in the nodes, plus a search for each lane moved: cheaper than
    /// [`Bvh::rebuild`] at small shares, and worth less (`docs/performance.md`, "Scenes
    /// that change", measures both, and how much of a rebuild's gain a `share` of 0.1 wins
    /// back).
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
        if self.tree.is_empty() {
            return;
        }
        // Shrinking may leave nodes empty, and the tree shallower.
        self.tree.tighten_all();
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
        self.tree.tighten_all();
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
        for (id, first, count) in self.tree.leaves() {
            links.leaf_of[first..first + count].fill(id);
        }
        links.made = true;
    }
}

#[cfg(test)]
mod tests {
    use super::REMOVED;
    use crate::{Bvh, Hittable, Sphere};
    use glam::DVec3;
    use proptest::prelude::*;

    /// What every tree must hold, however it was changed ([`Tree::check`](crate::tree::Tree::check)),
    /// with the links: each position's leaf as the links name it, and every live number at
    /// the position that holds it. Returns the levels of nodes.
    fn check(bvh: &Bvh<Sphere>) -> Result<usize, TestCaseError> {
        let levels = bvh.tree.check(
            |p| bvh.objects[p].bounding_box(),
            |p, leaf| {
                if bvh.links.made {
                    prop_assert_eq!(bvh.links.leaf_of[p] as usize, leaf);
                }
                Ok(())
            },
        )?;
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
                    prop_assert_eq!(check(&bvh)?, bvh.tree.depth());
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

    /// Balls inserted each inside the last grow the tree a level every seven (each new
    /// ball's cheapest place is beside the innermost), to the deepest tree an insert makes
    /// ([`MAX_DEPTH`](crate::tree::MAX_DEPTH) levels; one more, and the insert rebuilds):
    /// there a ray through the centre enters every child of every node, and the walk
    /// answers as the loop over the balls. (The stacks' own worst case, every level's
    /// children pending at once, is `traverse`'s `walks_at_each_stack_bound_...` test.)
    #[test]
    fn inserts_of_nested_balls_reach_the_deepest_tree_which_answers_as_the_loop() {
        use crate::Interval;
        use crate::tree::MAX_DEPTH;
        let mut bvh = Bvh::new(Vec::new());
        let mut balls = Vec::new();
        let rays = [
            crate::Ray::new(DVec3::new(-5.0, 1e-7, 0.0), DVec3::X),
            crate::Ray::new(DVec3::new(0.0, 2.0, 1e-7), DVec3::NEG_Y),
            crate::Ray::new(DVec3::ZERO, DVec3::new(0.3, -0.2, 1.0)),
        ];
        let mut deepest = 0;
        for i in 0..8 * MAX_DEPTH {
            let centre = DVec3::new(1e-4 * (i as f64).sin(), 0.0, 0.0);
            let ball = Sphere::new(centre, 0.985f64.powi(i as i32)).unwrap();
            bvh.insert(ball);
            balls.push(ball);
            if bvh.tree.depth() > deepest {
                deepest = bvh.tree.depth();
                // Stopped short of the innermost ball, from its centre: no hit, every
                // node's every child entered at 0.
                for (ray, ray_t) in rays
                    .iter()
                    .flat_map(|r| [(r, Interval::FORWARD), (r, Interval::new(0.0, 1e-9))])
                {
                    let want = crate::Hittable::hit(&balls, ray, ray_t);
                    let got = bvh.hit(ray, ray_t);
                    assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "depth {deepest}");
                    assert_eq!(bvh.occluded(ray, ray_t), want.is_some(), "depth {deepest}");
                }
            }
        }
        assert_eq!(deepest, MAX_DEPTH);
        assert!(check(&bvh).is_ok());
    }
}
