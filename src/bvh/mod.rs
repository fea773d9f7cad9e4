//! A bounding volume hierarchy over any [`Hittable`]: the objects, in the order of the
//! crate's one tree (`crate::tree`), and the searches over them; `update.rs` is the public
//! API of changes (numbering, insert, remove, rebuild, optimize).

mod update;

use alloc::vec::Vec;

use glam::DVec3;

use crate::masked::sees;
use crate::record::{Found, Made};
use crate::simd::{Boxes, boxes};
use crate::tree::{Shape, Tally, Tree, Visits, permute, wins};
use crate::{Aabb, HitRecord, Hittable, Interval, Ray};

/// A bounding volume hierarchy: the closest hit (or any hit) among many objects without
/// testing them all.
///
/// Generic over the object type, so a `Bvh<Quad>` is monomorphized and inlined, while a
/// `Bvh<Box<dyn Hittable>>` mixes shapes. A `Bvh` is itself a [`Hittable`], so BVHs nest.
/// Objects with an unbounded box (an infinite [`Plane`](crate::Plane), say) are kept out of
/// the tree and tested on every ray.
///
/// The objects are stored reordered for locality; [`Bvh::hit_with_index`] and
/// [`Bvh::original_index`] translate back to positions in the `Vec` given to
/// [`Bvh::new`].
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Bvh, Hittable, Interval, Quad, Ray};
///
/// let tiles: Vec<Quad> = (0..100)
///     .map(|i| Quad::new(DVec3::new(i as f64, 0.0, 0.0), DVec3::X, DVec3::Y).unwrap())
///     .collect();
/// let bvh = Bvh::new(tiles);
/// let ray = Ray::new(DVec3::new(41.5, 0.5, 1.0), DVec3::NEG_Z);
/// let (index, hit) = bvh.hit_with_index(&ray, Interval::FORWARD).unwrap();
/// assert_eq!((index, hit.t), (41, 1.0));
/// ```
#[derive(Clone, Debug)]
pub struct Bvh<T> {
    /// Bounded objects first, in tree order, then the unbounded ones.
    objects: Vec<T>,
    tree: Tree,
    bbox: Aabb,
    /// The tree's [`Tree::sah_cost`] when it was built.
    built_cost: f64,
    /// What inserting and removing objects needs; empty until the first insert or remove.
    links: update::Links,
}

impl<T: Hittable> Bvh<T> {
    /// Offers `visit` the unbounded objects, then every leaf whose box the ray enters
    /// within `[ray_t.min, *t_max]`, nearer child first where `NEAREST`. `visit` gets a
    /// run of objects, the position of the first in `self.objects`, and `t_max`, which it
    /// lowers as it finds hits (later boxes are culled against it); it returns `true` to
    /// stop.
    #[inline(always)]
    fn walk<const NEAREST: bool, B: Boxes>(
        &self,
        token: B::Token,
        ray: &Ray,
        ray_t: Interval,
        t_max: &mut f64,
        tally: &mut impl Tally,
        mut visit: impl FnMut(&[T], usize, &mut f64) -> bool,
    ) {
        let objects = &self.objects;
        self.tree.walk_on::<NEAREST, B>(
            token,
            ray,
            ray_t,
            t_max,
            tally,
            #[inline(always)]
            |first, count, t_max| visit(&objects[first..first + count], first, t_max),
        );
    }
}

impl<T: Hittable> Bvh<T> {
    /// The tree over `objects`, built on every core where `parallel`.
    pub(super) fn built(mut objects: Vec<T>, parallel: bool) -> Self {
        let boxes: Vec<Aabb> = objects.iter().map(Hittable::bounding_box).collect();
        let (tree, bbox) = Tree::build(boxes.len(), |i| boxes[i], Shape::OBJECTS, parallel);
        drop(boxes);
        permute(&mut objects, &tree.order);
        let built_cost = tree.sah_cost();
        Bvh {
            objects,
            tree,
            bbox,
            built_cost,
            links: update::Links::default(),
        }
    }

    /// Builds the hierarchy (binned SAH; `docs/performance.md` in the repository has build times).
    ///
    /// # Panics
    /// If there are more than `u32::MAX` objects.
    #[must_use]
    pub fn new(objects: Vec<T>) -> Self {
        Self::built(objects, false)
    }

    /// [`Bvh::new`] with large subtrees built side by side on every core: the same tree.
    ///
    /// # Panics
    /// If there are more than `u32::MAX` objects.
    #[cfg(feature = "rayon")]
    #[cfg_attr(docsrs, doc(cfg(feature = "rayon")))]
    #[must_use]
    pub fn new_parallel(objects: Vec<T>) -> Self {
        Self::built(objects, true)
    }

    /// The number of objects.
    #[inline]
    #[must_use]
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether there are no objects.
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// The objects, in the BVH's own order (see [`Bvh::original_index`]).
    #[inline]
    #[must_use]
    pub fn objects(&self) -> &[T] {
        &self.objects
    }

    /// The number of `self.objects()[i]`: its position in the `Vec` given to
    /// [`Bvh::new`], or the number [`Bvh::insert`] gave it.
    ///
    /// # Panics
    /// If `i >= self.len()`.
    #[inline]
    #[must_use]
    pub fn original_index(&self, i: usize) -> usize {
        self.tree.order[i] as usize
    }

    /// The closest hit and the number of the object hit: its position in the `Vec` given
    /// to [`Bvh::new`], or the number [`Bvh::insert`] gave it. Of objects hit at exactly
    /// the same `t`, the one of smaller number wins, as the one given first does in a
    /// slice.
    #[must_use]
    pub fn hit_with_index(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        let mut kept = None;
        let (index, position, found) = boxes!(|token, B| self.closest::<false, B>(
            token,
            ray,
            ray_t,
            &mut (),
            &mut kept,
            |_, _| true
        ))?;
        let hit = match kept {
            Some(made) if found.is_made() => Some(made),
            _ => self.objects[position].record(ray, ray_t, &found),
        };
        match hit {
            Some(hit) => Some((index, hit)),
            // A record that cannot be made (past f64's range) is no hit: ask again, as the
            // objects' own `hit` would answer.
            None => self.hit_by_records(ray, ray_t),
        }
    }

    /// [`Bvh::hit_with_index`], counting only the crossings `filter` takes: each object's
    /// crossing ([`ObjectCandidate`]: the object's number, `t`, its own coordinates and
    /// part, the ray) is asked of `filter`, and where it is turned away the object is asked
    /// again beyond it, so the search goes on past a rejected crossing, inside the tree:
    /// cut-outs on quads and other shapes of a tree (a mesh's faces have
    /// [`Filtered`](crate::Filtered)). A rejected crossing costs no record.
    ///
    /// Asked at most once per crossing and query, and only about a crossing that would be
    /// the closest so far; asking again beyond a rejected crossing asks the object a
    /// second time, so an object whose `hit` is random (the book's fog) should not be
    /// filtered. A crossing at exactly the rejected one's `t` on the same object is passed
    /// over with it. `None` where the winner's record cannot be made (past `f64`'s range).
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Bvh, Hittable, Interval, ObjectCandidate, Quad, Ray};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// // A fence of two boards in a row, and a wall behind; the boards' lower halves are cut out.
    /// let board = |x: f64| Quad::new(DVec3::new(x, 0.0, 0.0), DVec3::X, DVec3::Y);
    /// let wall = Quad::new(DVec3::new(-5.0, -5.0, -3.0), 10.0 * DVec3::X, 10.0 * DVec3::Y)?;
    /// let scene = Bvh::new(vec![board(0.0)?, board(1.0)?, wall]);
    /// let cut = |c: &ObjectCandidate| c.object == 2 || c.coords.y >= 0.5; // beta: up the board
    ///
    /// let low = Ray::new(DVec3::new(0.5, 0.25, 1.0), DVec3::NEG_Z);
    /// let (index, hit) = scene.hit_filtered(&low, Interval::FORWARD, cut).unwrap();
    /// assert_eq!((index, hit.t), (2, 4.0)); // through the cut-out, to the wall
    /// let high = Ray::new(DVec3::new(1.5, 0.75, 1.0), DVec3::NEG_Z);
    /// assert_eq!(scene.hit_filtered(&high, Interval::FORWARD, cut).unwrap().0, 1);
    /// assert!(!scene.occluded_filtered(&low, Interval::new(0.0, 3.5), cut));
    /// # Ok(())
    /// # }
    /// ```
    #[must_use]
    pub fn hit_filtered(
        &self,
        ray: &Ray,
        ray_t: Interval,
        filter: impl Fn(&ObjectCandidate) -> bool,
    ) -> Option<(usize, HitRecord)> {
        let mut kept = None;
        let accept = |index: usize, found: &Found| filter(&ObjectCandidate::new(ray, index, found));
        let (index, position, found) = boxes!(|token, B| self.closest::<true, B>(
            token,
            ray,
            ray_t,
            &mut (),
            &mut kept,
            accept
        ))?;
        let hit = match kept {
            Some(made) if found.is_made() => Some(made),
            _ => self.objects[position].record(ray, ray_t, &found),
        };
        hit.map(|hit| (index, hit))
    }

    /// Whether any object has a crossing within `ray_t` that `filter` takes (see
    /// [`Bvh::hit_filtered`]): `hit_filtered(..).is_some()` for a filter that answers the
    /// same when asked the same.
    #[must_use]
    pub fn occluded_filtered(
        &self,
        ray: &Ray,
        ray_t: Interval,
        filter: impl Fn(&ObjectCandidate) -> bool,
    ) -> bool {
        let accept = |index: usize, found: &Found| filter(&ObjectCandidate::new(ray, index, found));
        boxes!(|token, B| self.any::<true, B>(token, ray, ray_t, &mut (), accept))
    }

    /// What [`Bvh::hit`](Hittable::hit) costs on `ray`: the nodes whose children's boxes it
    /// tests, and the objects it asks for a crossing. For looking into a tree's quality
    /// on the rays an application traces (a tree that visits many nodes per ray for few
    /// tests, or tests many objects, is worth [`Bvh::optimize`] or another build).
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Bvh, Interval, Quad, Ray};
    ///
    /// let tiles: Vec<Quad> = (0..100)
    ///     .map(|i| Quad::new(DVec3::new(i as f64, 0.0, 0.0), DVec3::X, DVec3::Y).unwrap())
    ///     .collect();
    /// let bvh = Bvh::new(tiles);
    /// let down = Ray::new(DVec3::new(41.5, 0.5, 1.0), DVec3::NEG_Z);
    /// let cost = bvh.hit_visits(&down, Interval::FORWARD);
    /// assert!(cost.nodes >= 1 && cost.tests >= 1 && cost.tests < 100);
    /// ```
    #[must_use]
    pub fn hit_visits(&self, ray: &Ray, ray_t: Interval) -> Visits {
        let mut visits = Visits::default();
        self.closest::<false, [f32; 8]>((), ray, ray_t, &mut visits, &mut None, |_, _| true);
        visits
    }

    /// What [`Bvh::occluded`](Hittable::occluded) costs on `ray`, as
    /// [`Bvh::hit_visits`] counts.
    #[must_use]
    pub fn occluded_visits(&self, ray: &Ray, ray_t: Interval) -> Visits {
        let mut visits = Visits::default();
        self.any::<false, [f32; 8]>((), ray, ray_t, &mut visits, |_, _| true);
        visits
    }

    /// The closest crossing by the objects' `find`: the object's number, its position in
    /// `self.objects`, and the crossing, whose record is put in `kept` where it is
    /// [made](Found::is_made). (Inlined always, as `any`, so that `boxes!` compiles all of
    /// it for AVX2.)
    #[inline(always)]
    fn closest<const FILTERED: bool, B: Boxes>(
        &self,
        token: B::Token,
        ray: &Ray,
        ray_t: Interval,
        tally: &mut impl Tally,
        kept: &mut Option<HitRecord>,
        accept: impl Fn(usize, &Found) -> bool,
    ) -> Option<(usize, usize, Found)> {
        // The places for made records live in the dispatched search, where the compiler
        // sees that quads and meshes never fill them, and drops them; the winner's record
        // leaves it once. (Tried: zeroed by the caller on every query; slower on primary
        // rays.)
        let (mut made, mut free) = ([Made::new(), Made::new()], 0);
        let mut closest: Option<(usize, usize, Found)> = None;
        let mut t_max = ray_t.max;
        let mut tests = 0u32;
        self.walk::<true, B>(
            token,
            ray,
            ray_t,
            &mut t_max,
            tally,
            #[inline(always)]
            |objects, first, t_max| {
                for (k, (object, &index)) in
                    objects.iter().zip(&self.tree.order[first..]).enumerate()
                {
                    let index = index as usize;
                    if !sees(ray, object) {
                        continue;
                    }
                    tests += 1;
                    // Candidates write the place that does not hold a made winner's
                    // record, so that one that ties and loses does not replace it (the
                    // two take turns, as in a list). A crossing `accept` turns away is
                    // passed over: the object is asked again beyond it (only with
                    // `FILTERED`: the tree's own queries keep the one call as it was).
                    let mut min = ray_t.min;
                    let candidate = if !FILTERED {
                        object.find(ray, Interval::new(min, *t_max), &mut made[free])
                    } else {
                        loop {
                            let found =
                                object.find(ray, Interval::new(min, *t_max), &mut made[free]);
                            match found {
                                Some(f) if !accept(index, &f) => {
                                    min = f.t.next_up();
                                    if min > *t_max {
                                        break None;
                                    }
                                }
                                _ => break found,
                            }
                        }
                    };
                    if let Some(found) = candidate
                        && wins(found.t, *t_max, || {
                            (index, closest.map(|(best, _, _)| best))
                        })
                    {
                        if found.is_made() {
                            free ^= 1;
                        }
                        *t_max = found.t;
                        closest = Some((index, first + k, found));
                    }
                }
                false
            },
        );
        tally.tests(tests);
        if let Some((_, _, found)) = closest
            && found.is_made()
        {
            *kept = Some(*made[free ^ 1].kept_mut());
        }
        closest
    }

    /// Whether any object occludes `ray` within `ray_t`; with `FILTERED`, whether any has
    /// a crossing that `accept` takes (asked of each object's crossings by `find`, from
    /// the nearest on, until one is taken).
    #[inline(always)]
    fn any<const FILTERED: bool, B: Boxes>(
        &self,
        token: B::Token,
        ray: &Ray,
        ray_t: Interval,
        tally: &mut impl Tally,
        accept: impl Fn(usize, &Found) -> bool,
    ) -> bool {
        let mut found = false;
        let mut t_max = ray_t.max;
        let mut tests = 0u32;
        self.walk::<false, B>(
            token,
            ray,
            ray_t,
            &mut t_max,
            tally,
            #[inline(always)]
            |objects, first, _| {
                if !FILTERED {
                    found = objects.iter().any(|o| {
                        if !sees(ray, o) {
                            return false;
                        }
                        tests += 1;
                        o.occluded(ray, ray_t)
                    });
                    return found;
                }
                found = objects
                    .iter()
                    .zip(&self.tree.order[first..])
                    .any(|(o, &index)| {
                        if !sees(ray, o) {
                            return false;
                        }
                        tests += 1;
                        let (mut made, mut min) = (Made::new(), ray_t.min);
                        while let Some(f) = o.find(ray, Interval::new(min, ray_t.max), &mut made) {
                            if accept(index as usize, &f) {
                                return true;
                            }
                            min = f.t.next_up();
                            if min > ray_t.max {
                                break;
                            }
                        }
                        false
                    });
                found
            },
        );
        tally.tests(tests);
        found
    }

    /// [`Bvh::hit_with_index`] by every object's [`Hittable::hit`].
    #[cold]
    fn hit_by_records(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        let mut closest: Option<(usize, HitRecord)> = None;
        let mut t_max = ray_t.max;
        // (Rare: the arrays' node test, without detecting AVX2.)
        self.walk::<true, [f32; 8]>(
            (),
            ray,
            ray_t,
            &mut t_max,
            &mut (),
            |objects, first, t_max| {
                for (object, &index) in objects.iter().zip(&self.tree.order[first..]) {
                    let index = index as usize;
                    if sees(ray, object)
                        && let Some(hit) = object.hit(ray, Interval::new(ray_t.min, *t_max))
                        && wins(hit.t, *t_max, || (index, closest.as_ref().map(|(b, _)| *b)))
                    {
                        *t_max = hit.t;
                        closest = Some((index, hit));
                    }
                }
                false
            },
        );
        closest
    }
}

/// An object's crossing that a [`Bvh::hit_filtered`] filter is asked about.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct ObjectCandidate<'a> {
    /// The ray.
    pub ray: &'a Ray,
    /// The object's number (as [`Bvh::hit_with_index`] gives it).
    pub object: usize,
    /// Where along the ray, as the hit would report it.
    pub t: f64,
    /// The object's own coordinates of the crossing ([`Found::coords`]: a quad's
    /// `(alpha, beta)`, a mesh's barycentrics).
    pub coords: DVec3,
    /// Which part of the object ([`Found::part`]: a mesh's face in its tree's order, a
    /// box's face).
    pub part: u32,
}

impl<'a> ObjectCandidate<'a> {
    fn new(ray: &'a Ray, object: usize, found: &Found) -> Self {
        Self {
            ray,
            object,
            t: found.t,
            coords: found.coords,
            part: found.part,
        }
    }
}

/// Collects objects into a tree, as [`Bvh::new`] of the collected `Vec`.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Bvh, Hittable, Interval, Ray, Sphere};
///
/// let row: Bvh<Sphere> = (0..10)
///     .map(|i| Sphere::new(DVec3::new(3.0 * f64::from(i), 0.0, 0.0), 1.0).unwrap())
///     .collect();
/// let ray = Ray::new(DVec3::new(9.0, 5.0, 0.0), DVec3::NEG_Y);
/// assert_eq!(row.hit(&ray, Interval::FORWARD).unwrap().t, 4.0);
/// ```
impl<T: Hittable> FromIterator<T> for Bvh<T> {
    fn from_iter<I: IntoIterator<Item = T>>(objects: I) -> Self {
        Self::new(objects.into_iter().collect())
    }
}

impl<T: Hittable> Hittable for Bvh<T> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.hit_with_index(ray, ray_t).map(|(_, hit)| hit)
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    /// Stops at the first object found that occludes, in any order.
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        boxes!(|token, B| self.any::<false, B>(token, ray, ray_t, &mut (), |_, _| true))
    }
}

#[cfg(test)]
mod tests {
    use super::Bvh;
    use crate::simd::boxes;
    use crate::{Interval, Quad, Ray, Triangle};
    use glam::DVec3;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100))]

        /// A `Bvh`'s queries compiled for AVX2 (where this CPU has it) answer as the
        /// portable ones, bit for bit: which object, `t` and its coordinates, on rays aimed
        /// at the corners and edges the triangles share, at offsets to 1e12 and with
        /// directions of every length.
        #[test]
        fn wide_bvh_queries_answer_as_portable_ones(
            corners in prop::collection::vec(prop::array::uniform3(-1.0f64..1.0), 3..40),
            offset in prop_oneof![Just(0.0), Just(1e6), Just(1e9), Just(-1e12)],
            scale in prop_oneof![Just(1.0), Just(1e-3), Just(1e3)],
            aims in prop::collection::vec((any::<prop::sample::Index>(), 0.0f64..1.0), 1..16),
            from in prop::array::uniform3(-4.0f64..4.0),
            length in -30i32..=30,
        ) {
            let place = |c: &[f64; 3]| DVec3::from(*c) * scale + DVec3::splat(offset);
            // A fan: consecutive triangles share an edge with the first corner.
            let tris: Vec<Quad<Triangle>> = corners
                .windows(2)
                .skip(1)
                .filter_map(|w| {
                    let (a, b, c) = (place(&corners[0]), place(&w[0]), place(&w[1]));
                    Quad::with_interior(a, b - a, c - a, Triangle).ok()
                })
                .collect();
            prop_assume!(!tris.is_empty());
            let bvh = Bvh::new(tris.clone());
            let origin = DVec3::from(from) * scale + DVec3::splat(offset);
            for &(pick, along) in &aims {
                // On the shared edge from the first corner, or at a corner itself.
                let t = &tris[pick.index(tris.len())];
                let target = t.plane().q() + along * t.plane().u();
                let ray = Ray::new(origin, (target - origin) * 2f64.powi(length));
                for ray_t in [Interval::FORWARD, Interval::new(0.0, 2f64.powi(-length))] {
                    let key = |c: Option<(usize, usize, crate::record::Found)>| {
                        c.map(|(i, p, f)| (i, p, f.t.to_bits(), f.coords.to_array().map(f64::to_bits)))
                    };
                    prop_assert_eq!(
                        key(bvh.closest::<false, [f32; 8]>((), &ray, ray_t, &mut (), &mut None, |_, _| true)),
                        key(boxes!(|token, B| bvh.closest::<false, B>(token, &ray, ray_t, &mut (), &mut None, |_, _| true)))
                    );
                    prop_assert_eq!(
                        bvh.any::<false, [f32; 8]>((), &ray, ray_t, &mut (), |_, _| true),
                        boxes!(|token, B| bvh.any::<false, B>(token, &ray, ray_t, &mut (), |_, _| true))
                    );
                }
            }
        }
    }
}
