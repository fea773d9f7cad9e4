//! The walk down a [`LightTree`]: the probability of each choice from a shading point, the
//! light it picks, and the density of a direction, which follows the same choices.

use glam::{DVec2, DVec3};

use super::cluster::share;
use super::{LightTree, MAX_DEPTH, NONE};
use crate::{Interval, PdfHittable, Ray};
use crate::{LightSample, ShadingContext};

impl<T: PdfHittable> LightTree<T> {
    /// The light the walk picks from `at` with `u` in `[0, 1)`, with its probability (the
    /// same, bit for bit, as [`LightTree::probability`]) and what is left of `u`; `None`
    /// for an empty tree or a point that is not finite.
    ///
    /// ```
    /// use hitkit::glam::{DVec2, DVec3};
    /// use hitkit::{Emission, LightTree, PdfHittable, Quad, ShadingContext};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// let lamps = vec![
    ///     Quad::new(DVec3::new(-3.0, 2.0, 0.0), DVec3::X, DVec3::Z)?,
    ///     Quad::new(DVec3::new(2.0, 2.0, 0.0), DVec3::X, DVec3::Z)?,
    /// ];
    /// let tree = LightTree::new(lamps, &[1.0, 1.0], &[Emission::OneSide(DVec3::NEG_Y); 2])?;
    /// let floor = ShadingContext::on_surface(DVec3::new(2.5, 0.0, 0.5), DVec3::Y);
    /// let (u, v) = (0.3, 0.7);
    /// let pick = tree.pick(&floor, u).expect("the lamps face the floor");
    /// assert_eq!(pick.probability, tree.probability(&floor, pick.light));
    /// let lamp = &tree.lights()[pick.light];
    /// let sample = lamp.sample_light(&floor, DVec2::new(pick.rest, v)).unwrap();
    /// // Next-event estimation divides by both: the pick, then the lamp's own density.
    /// let weight = 1.0 / (pick.probability * sample.pdf);
    /// assert!(weight > 0.0 && weight.is_finite());
    /// # Ok(())
    /// # }
    /// ```
    #[must_use]
    pub fn pick(&self, at: &ShadingContext, u: f64) -> Option<crate::LightPick> {
        self.pick_sided(at, u, false)
    }

    /// [`LightTree::pick`] from a surface that only reflects: one that receives light on
    /// the side `at.normal` points to alone (an opaque wall or floor; with a hit, its
    /// `normal` faces the ray that found it). Each cluster is weighed by the signed
    /// cosine there, a light wholly behind the surface is never picked, and where nothing
    /// can light the surface (every light behind it or facing away), nothing is. Without
    /// a normal, [`LightTree::pick`].
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{LightTree, Quad, ShadingContext};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// // A lamp on each side of a wall at y = 0, each facing the wall (a quad emits from
    /// // the side `u x v` points to).
    /// let above = Quad::new(DVec3::new(0.0, 1.0, 0.0), DVec3::X, DVec3::Z)?; // faces down
    /// let below = Quad::new(DVec3::new(0.0, -1.0, 0.0), DVec3::Z, DVec3::X)?; // faces up
    /// let tree = LightTree::from_lights(vec![above, below], &[1.0, 1.0])?;
    /// let wall = ShadingContext::on_surface(DVec3::new(0.5, 0.0, 0.5), DVec3::Y);
    /// assert_eq!(tree.probability_reflecting(&wall, 0), 1.0);
    /// assert_eq!(tree.probability_reflecting(&wall, 1), 0.0); // behind: never picked
    /// assert_eq!(tree.pick_reflecting(&wall, 0.9).map(|p| p.light), Some(0));
    /// assert_eq!(tree.probability(&wall, 1), 0.5); // from either side
    /// # Ok(())
    /// # }
    /// ```
    #[must_use]
    pub fn pick_reflecting(&self, at: &ShadingContext, u: f64) -> Option<crate::LightPick> {
        self.pick_sided(at, u, true)
    }

    /// [`LightTree::pick`], from one side alone where `one_sided` (and there is a normal).
    fn pick_sided(&self, at: &ShadingContext, u: f64, one_sided: bool) -> Option<crate::LightPick> {
        let (origin, normal) = (at.point, at.unit_normal());
        if !origin.is_finite() {
            return None;
        }
        let chosen = self.choose(origin, normal, one_sided && normal.is_some(), u)?;
        Some(crate::LightPick {
            light: chosen.light,
            probability: chosen.probability(),
            rest: chosen.rest,
        })
    }

    /// The probability that a sample from `at` picks light `i`: the product of the
    /// choices on the walk down to it.
    ///
    /// # Panics
    /// If `i >= self.lights().len()`.
    #[must_use]
    pub fn probability(&self, at: &ShadingContext, i: usize) -> f64 {
        self.probability_sided(at, i, false)
    }

    /// [`LightTree::probability`] from a surface that only reflects (see
    /// [`LightTree::pick_reflecting`]): 0 for a light wholly behind it.
    ///
    /// # Panics
    /// If `i >= self.lights().len()`.
    #[must_use]
    pub fn probability_reflecting(&self, at: &ShadingContext, i: usize) -> f64 {
        self.probability_sided(at, i, true)
    }

    /// [`LightTree::probability`], from one side alone where `one_sided`.
    fn probability_sided(&self, at: &ShadingContext, i: usize, one_sided: bool) -> f64 {
        let (origin, normal) = (at.point, at.unit_normal());
        if !origin.is_finite() {
            return 0.0;
        }
        let Some(slots) = self.slots() else {
            return 0.0;
        };
        match self.leaves[i] {
            NONE if self.infinite.contains(&(i as u32)) => slots.each,
            NONE => 0.0,
            _ if !slots.tree => 0.0,
            leaf => {
                let one_sided = one_sided && normal.is_some();
                self.reaching(leaf as usize, origin, normal, one_sided) * slots.each
            }
        }
    }

    /// [`PdfHittable::sample_light`] from a surface that only reflects (see
    /// [`LightTree::pick_reflecting`]); its density is
    /// [`LightTree::light_pdf_reflecting`]'s. `None` also where nothing can light the
    /// surface.
    #[must_use]
    pub fn sample_light_reflecting(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        self.sample_light_at(at, u, true)
    }

    /// [`PdfHittable::light_pdf`] from a surface that only reflects (see
    /// [`LightTree::pick_reflecting`]): the density of
    /// [`LightTree::sample_light_reflecting`]'s directions.
    #[must_use]
    pub fn light_pdf_reflecting(&self, at: &ShadingContext, direction: DVec3) -> f64 {
        let normal = at.unit_normal();
        self.density(at.point, normal, normal.is_some(), direction)
    }

    /// The first choices (the infinite lights, then the tree where it holds a light of
    /// power), their count and the probability of each; `None` where there is nothing
    /// to pick.
    #[inline]
    fn slots(&self) -> Option<Slots> {
        let tree = self.nodes.first().is_some_and(|r| r.cluster.power > 0.0);
        let count = self.infinite.len() + usize::from(tree);
        (count > 0).then(|| Slots {
            count,
            each: 1.0 / count as f64,
            tree,
        })
    }

    /// The first choice and then, where it is the tree, the walk: the light `x` in
    /// `[0, 1)` picks, with what is left of `x`, its leaf (`None` for an infinite light)
    /// and the probabilities of both choices. With no infinite light the first choice is
    /// the tree's, of probability 1, and `x` goes to the walk unchanged.
    pub(super) fn choose(
        &self,
        origin: DVec3,
        normal: Option<DVec3>,
        one_sided: bool,
        x: f64,
    ) -> Option<Chosen> {
        let Slots { count, each, .. } = self.slots()?;
        let below_one = 1.0 - f64::EPSILON / 2.0;
        let scaled = if x > 0.0 { x.min(below_one) } else { 0.0 } * count as f64;
        let k = (scaled as usize).min(count - 1);
        let rest = (scaled - k as f64).clamp(0.0, below_one);
        if let Some(&light) = self.infinite.get(k) {
            return Some(Chosen {
                light: light as usize,
                rest,
                leaf: None,
                walk: 1.0,
                slot: each,
            });
        }
        let (light, rest, leaf, walk) = self.pick_at(origin, normal, one_sided, rest)?;
        Some(Chosen {
            light,
            rest,
            leaf: Some(leaf),
            walk,
            slot: each,
        })
    }

    /// The probability that the walk reaches node `n`: the product of the choices on the
    /// way down to it, found on the way up and multiplied root first, as the walk down
    /// multiplies them (so that the two agree bit for bit).
    pub(super) fn reaching(
        &self,
        mut n: usize,
        origin: DVec3,
        normal: Option<DVec3>,
        one_sided: bool,
    ) -> f64 {
        if self.behind(origin, normal, one_sided) {
            return 0.0;
        }
        // One a level: at most 63 (see `MAX_DEPTH`).
        let mut choices = [0.0; MAX_DEPTH];
        let mut depth = 0;
        while let Some(&parent) = self.parents.get(n).filter(|&&p| p != NONE) {
            let parent = parent as usize;
            let Some(left) = self.left_probability(parent, origin, normal, one_sided) else {
                return 0.0;
            };
            choices[depth] = if n == parent + 1 { left } else { 1.0 - left };
            depth += 1;
            n = parent;
        }
        choices[..depth].iter().rev().fold(1.0, |p, &c| p * c)
    }

    /// Whether a tree of one light (no choice to weigh it) holds nothing that can light a
    /// one-sided surface: its light behind it or facing away (importance 0). A tree of
    /// more finds that out at its root's children.
    #[inline]
    fn behind(&self, origin: DVec3, normal: Option<DVec3>, one_sided: bool) -> bool {
        one_sided
            && self.nodes.first().is_some_and(|root| {
                root.leaf && root.cluster.importance::<true>(origin, normal) == 0.0
            })
    }

    /// The probability that the walk at inner node `n` goes to its first child; `None`
    /// where it can go to neither (see [`PdfHittable::sample_light`]).
    ///
    /// By importance; where both children's is 0 (every light faces away from the point,
    /// or is too dim to count), by power, but from a one-sided surface, which nothing
    /// there can light (its lights all behind it or facing away): `None`.
    #[inline]
    pub(super) fn left_probability(
        &self,
        n: usize,
        origin: DVec3,
        normal: Option<DVec3>,
        one_sided: bool,
    ) -> Option<f64> {
        let (a, b) = (
            &self.nodes[n + 1].cluster,
            &self.nodes[self.nodes[n].index as usize].cluster,
        );
        // Each side's importance its own code: the either-side one knows its cosine is
        // never negative.
        let (ia, ib) = if one_sided {
            (
                a.importance::<true>(origin, normal),
                b.importance::<true>(origin, normal),
            )
        } else {
            (
                a.importance::<false>(origin, normal),
                b.importance::<false>(origin, normal),
            )
        };
        // From a one-sided surface, importance 0 is a bound (nothing the clusters hold can
        // light it: behind it, or facing away): no light, as pbrt-v4's sampler answers.
        share(ia, ib).or_else(|| {
            if one_sided {
                None
            } else {
                share(a.power, b.power)
            }
        })
    }

    /// The walk from the root: the light `x` in `[0, 1)` picks, what is left of `x`,
    /// rescaled to `[0, 1)`, its leaf and its probability (the choices multiplied root
    /// first); `None` for an empty tree, and where the walk picks no light (see
    /// [`LightTree::left_probability`]).
    pub(super) fn pick_at(
        &self,
        origin: DVec3,
        normal: Option<DVec3>,
        one_sided: bool,
        x: f64,
    ) -> Option<(usize, f64, usize, f64)> {
        if self.nodes.is_empty() || self.behind(origin, normal, one_sided) {
            return None;
        }
        // Into [0, 1) (NaN to 0); each choice rescales what is left of it to [0, 1).
        let below_one = 1.0 - f64::EPSILON / 2.0;
        let mut x = if x > 0.0 { x.min(below_one) } else { 0.0 };
        let mut n = 0;
        let mut p = 1.0;
        while !self.nodes[n].leaf {
            let left = self.left_probability(n, origin, normal, one_sided)?;
            if x < left {
                x /= left;
                n += 1;
                p *= left;
            } else {
                x = (x - left) / (1.0 - left);
                n = self.nodes[n].index as usize;
                p *= 1.0 - left;
            }
            x = x.clamp(0.0, below_one);
        }
        Some((self.nodes[n].index as usize, x, n, p))
    }

    pub(super) fn sample(
        &self,
        origin: DVec3,
        normal: Option<DVec3>,
        one_sided: bool,
        u: DVec2,
    ) -> DVec3 {
        if !origin.is_finite() {
            return DVec3::ZERO;
        }
        self.choose(origin, normal, one_sided, u.x)
            .map_or(DVec3::ZERO, |c| {
                self.lights[c.light].sample_direction(origin, DVec2::new(c.rest, u.y))
            })
    }

    /// [`PdfHittable::sample_light`]: the walk's pick sampled, its surface found, and the
    /// density, in which the picked light's probability is the walk's own (the same
    /// product, bit for bit, that the density finds by walking up from its leaf).
    pub(super) fn sample_light_at(
        &self,
        at: &ShadingContext,
        u: DVec2,
        one_sided: bool,
    ) -> Option<LightSample> {
        let (origin, normal) = (at.point, at.unit_normal());
        if !origin.is_finite() {
            return None;
        }
        let one_sided = one_sided && normal.is_some();
        let c = self.choose(origin, normal, one_sided, u.x)?;
        let light = &self.lights[c.light];
        let direction = light.sample_direction(origin, DVec2::new(c.rest, u.y));
        if direction == DVec3::ZERO {
            // A light of no density (a point, spot or sun) samples itself.
            let u = DVec2::new(c.rest, u.y);
            return crate::sample::delta_pick(light.sample_light(at, u), c.probability(), c.light);
        }
        let known = c.leaf.map(|leaf| (leaf, c.walk));
        LightSample::along_with(self, at, direction, |d| {
            self.density_with(origin, normal, one_sided, d, known)
        })
    }

    pub(super) fn density(
        &self,
        origin: DVec3,
        normal: Option<DVec3>,
        one_sided: bool,
        direction: DVec3,
    ) -> f64 {
        self.density_with(origin, normal, one_sided, direction, None)
    }

    /// [`LightTree::density`], given the probability of reaching one leaf where it is
    /// known (`(node, probability)`).
    fn density_with(
        &self,
        origin: DVec3,
        normal: Option<DVec3>,
        one_sided: bool,
        direction: DVec3,
        known: Option<(usize, f64)>,
    ) -> f64 {
        let ray = Ray::new(origin, direction);
        let Some(Slots { each, tree, .. }) = self.slots().filter(|_| ray.is_valid()) else {
            return 0.0;
        };
        if let [only] = self.lights.as_slice() {
            // Picked always (but from a one-sided surface it cannot light): its own
            // density, and no box test before it.
            if self.behind(origin, normal, one_sided) {
                return 0.0;
            }
            return only.pdf_value(origin, direction);
        }
        let infinite = |sum: f64| {
            self.infinite.iter().fold(sum, |sum, &i| {
                sum + each * self.lights[i as usize].pdf_value(origin, direction)
            })
        };
        if !tree {
            return infinite(0.0);
        }
        // The lights the direction reaches, found by the boxes the ray meets (a light it
        // reaches lies in the box of every node above it); the walk's probability only for
        // those (most directions reach none, or one), from its leaf up.
        // At most `MAX_DEPTH` entries (see `MAX_DEPTH`).
        let mut stack = [0u32; MAX_DEPTH + 2];
        let mut top = 1;
        let mut sum = 0.0;
        while top > 0 {
            top -= 1;
            let n = stack[top] as usize;
            let node = &self.nodes[n];
            if !node.cluster.bbox.hit(&ray, Interval::FORWARD) {
                continue;
            }
            if node.leaf {
                let pdf = self.lights[node.index as usize].pdf_value(origin, direction);
                if pdf > 0.0 {
                    let p = match known {
                        Some((leaf, p)) if leaf == n => p,
                        _ => self.reaching(n, origin, normal, one_sided),
                    };
                    sum += p * pdf;
                }
                continue;
            }
            stack[top] = node.index;
            stack[top + 1] = n as u32 + 1;
            top += 2;
        }
        infinite(sum * each)
    }
}

/// [`LightTree`]'s first choices: `count` of them (its infinite lights, then the tree
/// where it holds a light of power), each of probability `each`.
#[derive(Clone, Copy)]
struct Slots {
    count: usize,
    each: f64,
    tree: bool,
}

/// What [`LightTree::choose`] picked.
pub(super) struct Chosen {
    pub(super) light: usize,
    /// What is left of the number that picked it, in `[0, 1)`.
    pub(super) rest: f64,
    /// Its leaf, for a light of the tree.
    pub(super) leaf: Option<usize>,
    /// The probability of the walk down the tree (1 for an infinite light), and of the
    /// first choice.
    pub(super) walk: f64,
    pub(super) slot: f64,
}

impl Chosen {
    /// The probability of the pick: the walk's times the first choice's, as
    /// [`LightTree::probability`] multiplies them.
    #[inline]
    pub(super) fn probability(&self) -> f64 {
        self.walk * self.slot
    }
}
