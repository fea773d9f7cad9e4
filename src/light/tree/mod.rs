//! Many lights: a tree over them that picks one by its importance from the shading point
//! (after Conty Estevez and Kulla 2018, "Importance Sampling of Many Lights with Adaptive
//! Tree Splitting", the method of pbrt-v4's `BVHLightSampler`).

mod build;
mod cluster;
mod sample;

use alloc::vec::Vec;
use core::f64::consts::PI;

use glam::{DVec2, DVec3};

use build::{Prim, build};
use cluster::Cluster;

use crate::tree::wins;
use crate::{
    Aabb, Emission, GeometryError, HitRecord, Hittable, Interval, LightSample, PdfHittable, Quad,
    Ray, ShadingContext, Triangle, TriangleMesh,
};

/// Lights picked by their importance from the point being shaded, as one [`PdfHittable`]:
/// a binary tree over the lights whose every node bounds what is under it (a box, the
/// total power, a cone of the directions its lights face). `sample_direction` walks down
/// from the root, choosing between two children in proportion to a bound on the light
/// each can send to the point (power over squared distance, cut where the cluster's cone
/// of emission faces away; Conty Estevez and Kulla 2018), then samples the light it
/// reaches. `pdf_value` is the density of that walk: the sum, over every light the
/// direction reaches, of the probability of walking to it times its own density, so a
/// renderer that mixes it with other strategies stays unbiased. A light far, dim or
/// facing away is picked seldom or never, where a [`Mixture`](crate::Mixture) picks it at
/// its fixed weight. A sample costs a walk of the tree's depth; a density, the box tests
/// of the nodes its ray meets and a walk up from each light it reaches, where a
/// `Mixture`'s density visits every light.
///
/// [`PdfHittable::sample_light`] from a [`ShadingContext`] with a normal weighs each
/// cluster by the cosine at the surface too, on either side of it (as pbrt-v4 does): a
/// light behind the surface is picked as a light in front of it would be, so a normal
/// facing either way gives light. From a surface that only reflects
/// ([`LightTree::pick_reflecting`] and its siblings), by the signed cosine: a light
/// wholly behind it is never picked. As a [`Hittable`], the tree is the list of its lights
/// (the closest hit; ties go to the earlier light).
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{Emission, LightTree, PdfHittable, Quad, ShadingContext};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// // A row of ceiling panels facing down, 10 apart.
/// let panel = |x: f64| Quad::new(DVec3::new(x, 3.0, 0.0), DVec3::X, DVec3::Z);
/// let panels = (0..100).map(|i| panel(10.0 * f64::from(i))).collect::<Result<Vec<_>, _>>()?;
/// let powers = vec![1.0; panels.len()];
/// let emission = vec![Emission::OneSide(DVec3::NEG_Y); panels.len()];
/// let lights = LightTree::new(panels, &powers, &emission)?;
///
/// // Under panel 42, the walk picks it 40 times as often as a uniform choice would; below
/// // a surface facing up, more often still.
/// let under = DVec3::new(420.5, 0.0, 0.5);
/// assert!(lights.probability(&ShadingContext::at(under), 42) > 0.4);
/// let floor = ShadingContext::on_surface(under, DVec3::Y);
/// assert!(lights.probability(&floor, 42) > 0.55);
/// let sample = lights.sample_light(&floor, DVec2::new(0.3, 0.7)).unwrap();
/// assert!(sample.pdf > 0.0 && sample.record.point.y == 3.0);
/// // Seen from high above the panels, every one faces away: their importance there is 0,
/// // and the walk falls back on power alone.
/// let above = DVec3::new(420.5, 1000.0, 0.5);
/// assert!((lights.probability(&ShadingContext::at(above), 42) - 0.01).abs() < 1e-15);
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug)]
pub struct LightTree<T> {
    lights: Vec<T>,
    /// Depth first: an inner node's first child follows it.
    nodes: Vec<Node>,
    /// For each node, its parent (`u32::MAX` for the root).
    parents: Vec<u32>,
    /// For each light, its leaf ([`NONE`] for an infinite light).
    leaves: Vec<u32>,
    /// The lights of unbounded box (an environment), kept beside the tree, and those of
    /// them with power, which are picked apart from it.
    unbounded: Vec<u32>,
    infinite: Vec<u32>,
}

/// A node of the tree: the bounds of its lights, and its second child or its light.
#[derive(Clone, Copy, Debug)]
struct Node {
    cluster: Cluster,
    /// The second child of an inner node, or the light of a leaf.
    index: u32,
    leaf: bool,
}

/// How deep the tree may grow, and what sizes its walks' buffers. The build splits by its
/// heuristic above depth 32 (the root's is 0; a split there may take off one light) and
/// by count, halving, from 32 on, and [`LightTree::new`] takes fewer than `2^31` lights:
/// a node at depth 32 holds fewer than `2^31 - 32`, so 31 halvings more leave one, and no
/// leaf is deeper than 63, no inner node deeper than 62. The walks through every node a
/// ray meets (`nearest`, `density_with`) keep, depth first, at most one entry for each
/// node above the one they are at and push two, `62 + 2` entries of their `MAX_DEPTH + 2`;
/// the walk up from a leaf (`reaching`) records one choice a level, at most 63 of
/// `MAX_DEPTH`. (The test `the_deepest_tree_walks_within_its_buffers` builds a tree to
/// the heuristic's depth; none of memory's size reaches 63 levels.)
const MAX_DEPTH: usize = 64;

/// No parent: the root's.
const NONE: u32 = u32::MAX;

impl<T: PdfHittable> LightTree<T> {
    /// The tree over `lights`, light `i` of power `powers[i]` (radiant flux, or anything
    /// proportional to it across the lights) emitting as `emission[i]` says.
    ///
    /// A light of power 0 is never picked, and its density never counts; at least one
    /// light must have power, unless there are none (then every density is 0 and every
    /// sample the zero vector, as for an empty [`Mixture`](crate::Mixture)).
    ///
    /// A light whose bounding box is unbounded (an environment, a sky dome of no size) is
    /// an *infinite* light, kept beside the tree as pbrt-v4's `BVHLightSampler` keeps them:
    /// each infinite light of power, and the tree as a whole, is picked alike (a sky and
    /// many lamps: the sky half the time), then sampled on its own; its power and emission
    /// do not weigh the pick.
    ///
    /// # Errors
    /// [`GeometryError::LengthMismatch`] if `powers` or `emission` differ in length from
    /// `lights`; [`GeometryError::NonFinite`] for a NaN or infinite power, or an emission
    /// normal that is not finite; [`GeometryError::InvalidParameter`] for a negative power,
    /// for powers all 0, for a light whose bounding box is empty, or for an emission cone
    /// whose angle is not in `(0, PI / 2]`;
    /// [`GeometryError::ZeroVector`] for an emission normal of length 0.
    ///
    /// # Panics
    /// If there are more than `u32::MAX / 2` lights.
    pub fn new(
        lights: Vec<T>,
        powers: &[f64],
        emission: &[Emission],
    ) -> Result<Self, GeometryError> {
        for (what, found) in [("powers", powers.len()), ("emission", emission.len())] {
            if found != lights.len() {
                return Err(GeometryError::LengthMismatch {
                    what,
                    expected: lights.len(),
                    found,
                });
            }
        }
        assert!(
            lights.len() <= (u32::MAX / 2) as usize,
            "a LightTree holds at most u32::MAX / 2 lights"
        );
        let mut prims = Vec::with_capacity(lights.len());
        let (mut unbounded, mut infinite) = (Vec::new(), Vec::new());
        for (i, light) in lights.iter().enumerate() {
            let bbox = light.bounding_box();
            if !bbox.is_empty() && !bbox.is_bounded() {
                cluster::checked(powers[i], emission[i])?;
                unbounded.push(i as u32);
                if powers[i] > 0.0 {
                    infinite.push(i as u32);
                }
                continue;
            }
            let cluster = Cluster::of(bbox, powers[i], emission[i])?;
            let centroid = 0.5 * (cluster.bbox.min() + cluster.bbox.max());
            prims.push(Prim {
                cluster,
                centroid,
                light: i as u32,
            });
        }
        if !lights.is_empty() && infinite.is_empty() && prims.iter().all(|p| p.cluster.power == 0.0)
        {
            return Err(GeometryError::InvalidParameter {
                what: "sum of powers",
                value: 0.0,
                domain: "(0, infinity)",
            });
        }
        let mut nodes = Vec::with_capacity(2 * lights.len());
        if !prims.is_empty() {
            build(&mut prims, &mut nodes, 0);
        }
        let mut parents = alloc::vec![NONE; nodes.len()];
        let mut leaves = alloc::vec![NONE; lights.len()];
        for (n, node) in nodes.iter().enumerate() {
            if node.leaf {
                leaves[node.index as usize] = n as u32;
            } else {
                parents[n + 1] = n as u32;
                parents[node.index as usize] = n as u32;
            }
        }
        Ok(Self {
            lights,
            nodes,
            parents,
            leaves,
            unbounded,
            infinite,
        })
    }

    /// The tree over `lights`, light `i` of power `powers[i]`, each emitting as it says
    /// ([`PdfHittable::emission`]: a quad from the side its normal faces, an instance as
    /// its object in world space, anything else everywhere). [`LightTree::new`] takes the
    /// sides from the caller instead (a two-sided lamp).
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Emission, LightTree, PdfHittable, Quad, ShadingContext};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// // X x Z = -Y: both panels face down.
    /// let panels = vec![
    ///     Quad::new(DVec3::new(0.0, 3.0, 0.0), DVec3::X, DVec3::Z)?,
    ///     Quad::new(DVec3::new(4.0, 3.0, 0.0), DVec3::X, DVec3::Z)?,
    /// ];
    /// assert_eq!(panels[0].emission(), Emission::OneSide(DVec3::NEG_Y));
    /// let tree = LightTree::from_lights(panels, &[1.0, 1.0])?;
    /// // From above, every panel faces away: picked by power alone.
    /// let above = ShadingContext::at(DVec3::new(0.5, 10.0, 0.5));
    /// assert_eq!(tree.probability(&above, 0), 0.5);
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// As [`LightTree::new`].
    pub fn from_lights(lights: Vec<T>, powers: &[f64]) -> Result<Self, GeometryError> {
        let emission: Vec<Emission> = lights.iter().map(PdfHittable::emission).collect();
        Self::new(lights, powers, &emission)
    }

    /// The lights, in the order given.
    #[inline]
    #[must_use]
    pub fn lights(&self) -> &[T] {
        &self.lights
    }
}

impl LightTree<Quad<Triangle>> {
    /// The faces of an emissive mesh as lights, each its own emitter, of power
    /// `PI * radiance * area` (the flux of a diffuse emitter of that radiance; twice that
    /// where `two_sided`), facing the side its corners wind counterclockwise around (the
    /// side [`TriangleMesh`]'s geometric normal faces), or both. Degenerate faces (of no
    /// area) are left out; each light carries the mesh's material.
    ///
    /// # Errors
    /// As [`LightTree::new`]: a radiance that is negative, not finite, or 0.
    pub fn from_mesh(
        mesh: &TriangleMesh,
        radiance: f64,
        two_sided: bool,
    ) -> Result<Self, GeometryError> {
        let mut emitters = Emitters::default();
        for face in mesh.faces() {
            emitters.push(face.corners(), radiance, two_sided, mesh.material());
        }
        emitters.tree()
    }
}

/// Triangles gathered as the lights of a [`LightTree`], each of power
/// `PI * radiance * area` (twice that two-sided) and facing as its corners wind: what
/// [`LightTree::from_mesh`] and a scene loader's emitters build.
#[derive(Default)]
pub(crate) struct Emitters {
    faces: Vec<Quad<Triangle>>,
    powers: Vec<f64>,
    emission: Vec<Emission>,
}

impl Emitters {
    /// The triangle `[a, b, c]` as a light, unless it is degenerate (of no area); whether
    /// it was taken.
    pub(crate) fn push(
        &mut self,
        [a, b, c]: [DVec3; 3],
        radiance: f64,
        two_sided: bool,
        material: crate::MaterialId,
    ) -> bool {
        let Ok(quad) = Quad::with_interior(a, b - a, c - a, Triangle) else {
            return false;
        };
        let normal = quad.plane().normal();
        let sides = if two_sided { 2.0 } else { 1.0 };
        self.powers.push(sides * PI * radiance * quad.area());
        self.emission.push(if two_sided {
            Emission::BothSides(normal)
        } else {
            Emission::OneSide(normal)
        });
        self.faces.push(quad.with_material(material));
        true
    }

    /// Whether no light was gathered.
    #[cfg(feature = "gltf")]
    pub(crate) fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// The tree over the lights gathered.
    pub(crate) fn tree(self) -> Result<LightTree<Quad<Triangle>>, GeometryError> {
        LightTree::new(self.faces, &self.powers, &self.emission)
    }

    /// The lights gathered, their powers and emission.
    #[cfg(feature = "gltf")]
    pub(crate) fn into_parts(self) -> (Vec<Quad<Triangle>>, Vec<f64>, Vec<Emission>) {
        (self.faces, self.powers, self.emission)
    }
}

impl<T: PdfHittable> LightTree<T> {
    /// The nearest of the lights' hits by `hit_light` (`hit` or `light_hit`), found under
    /// every node whose box the ray meets, and that light's index; of hits at the same
    /// `t`, the earlier light's, as the list's loop keeps them.
    #[inline]
    fn nearest(
        &self,
        ray: &Ray,
        ray_t: Interval,
        hit_light: impl Fn(&T, &Ray, Interval) -> Option<HitRecord>,
    ) -> Option<(usize, HitRecord)> {
        let mut best: Option<(usize, HitRecord)> = None;
        // At most `MAX_DEPTH` entries (see `MAX_DEPTH`).
        let mut stack = [0u32; MAX_DEPTH + 2];
        let mut top = usize::from(!self.nodes.is_empty());
        while top > 0 {
            top -= 1;
            let n = stack[top];
            let node = &self.nodes[n as usize];
            let reach = Interval::new(ray_t.min, best.as_ref().map_or(ray_t.max, |b| b.1.t));
            if !node.cluster.bbox.hit(ray, reach) {
                continue;
            }
            if node.leaf {
                let i = node.index as usize;
                if let Some(hit) = hit_light(&self.lights[i], ray, reach)
                    && wins(hit.t, reach.max, || (i, best.as_ref().map(|(j, _)| *j)))
                {
                    best = Some((i, hit));
                }
                continue;
            }
            stack[top] = node.index;
            stack[top + 1] = n + 1;
            top += 2;
        }
        for &i in &self.unbounded {
            let i = i as usize;
            let reach = Interval::new(ray_t.min, best.as_ref().map_or(ray_t.max, |b| b.1.t));
            if let Some(hit) = hit_light(&self.lights[i], ray, reach)
                && wins(hit.t, reach.max, || (i, best.as_ref().map(|(j, _)| *j)))
            {
                best = Some((i, hit));
            }
        }
        best
    }
}

impl<T: PdfHittable> Hittable for LightTree<T> {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.nearest(ray, ray_t, T::hit).map(|(_, hit)| hit)
    }

    fn bounding_box(&self) -> Aabb {
        let tree = self
            .nodes
            .first()
            .map_or(Aabb::EMPTY, |root| root.cluster.bbox);
        self.unbounded.iter().fold(tree, |b, &i| {
            b.union(&self.lights[i as usize].bounding_box())
        })
    }
}

impl<T: PdfHittable> PdfHittable for LightTree<T> {
    /// The sum, over the lights the direction reaches, of the probability that the walk
    /// picks each (from `origin`, with no normal) times its density; 0 for an empty tree
    /// or an invalid direction.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.density(origin, None, false, direction)
    }

    /// `u.x` makes the walk's choices (each rescaled to `[0, 1)` within the choice made)
    /// and, what is left of it, the chosen light's own `u.x`. The zero vector for an empty
    /// tree or an origin that is not finite (and, [`sample_light`](PdfHittable::sample_light) with a normal,
    /// where the walk picks no light).
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.sample(origin, None, false, u)
    }

    /// As [`sample_direction`](PdfHittable::sample_direction), with the context's normal:
    /// each choice weighs the cosine at the surface too, in absolute value (the normal's
    /// side does not matter; [`LightTree::sample_light_reflecting`] for a surface that
    /// only reflects). `None` for an empty tree, a point that is not finite, or a sampled
    /// direction along which no light's surface is found (see [`LightSample::along`]);
    /// never because of where the lights lie.
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        self.sample_light_at(at, u, false)
    }

    /// As [`pdf_value`](PdfHittable::pdf_value), with the context's normal (see
    /// [`sample_light`](PdfHittable::sample_light)).
    fn light_pdf(&self, at: &ShadingContext, direction: DVec3) -> f64 {
        self.density(at.point, at.unit_normal(), false, direction)
    }

    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        self.nearest(ray, ray_t, |light, ray, ray_t| {
            light.light_hit(ray, ray_t).map(|(_, hit)| hit)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{Emission, LightTree};
    use crate::{
        GeometryError, Hittable, Interval, PdfHittable, Quad, Ray, ShadingContext, Sphere,
    };
    use alloc::boxed::Box;
    use alloc::vec::Vec;
    use glam::{DVec2, DVec3};
    use proptest::prelude::*;

    /// A light of one of three kinds (a panel facing one way, one facing both ways, a
    /// sphere emitting everywhere) at `at`, of size `size`, turned by `turn`.
    fn light(kind: u8, at: DVec3, size: f64, turn: DVec3) -> (Box<dyn PdfHittable>, Emission) {
        let (u, v) = turn.normalize_or(DVec3::Y).any_orthonormal_pair();
        match kind % 3 {
            0 => (
                Box::new(Quad::new(at, u * size, v * size).unwrap()),
                Emission::OneSide(u.cross(v)),
            ),
            1 => (
                Box::new(Quad::new(at, u * size, v * size).unwrap()),
                Emission::BothSides(v.cross(u)),
            ),
            _ => (
                Box::new(Sphere::new(at, 0.5 * size).unwrap()),
                Emission::Everywhere,
            ),
        }
    }

    type Spec = (u8, [f64; 3], f64, [f64; 3], f64);

    fn tree(specs: &[Spec], offset: f64) -> LightTree<Box<dyn PdfHittable>> {
        let (mut lights, mut emission, mut powers) = (Vec::new(), Vec::new(), Vec::new());
        for &(kind, at, size, turn, power) in specs {
            let (l, e) = light(kind, DVec3::from(at) + offset, size, DVec3::from(turn));
            lights.push(l);
            emission.push(e);
            powers.push(power);
        }
        LightTree::new(lights, &powers, &emission).unwrap()
    }

    fn specs() -> impl Strategy<Value = Vec<Spec>> {
        prop::collection::vec(
            (
                any::<u8>(),
                prop::array::uniform3(-10.0f64..10.0),
                prop_oneof![Just(1e-3), 0.1f64..3.0],
                prop::array::uniform3(-1.0f64..1.0),
                // Some lights of no power, one in six; powers over twelve decades.
                prop_oneof![1 => Just(0.0), 5 => (-6.0f64..6.0).prop_map(|e| 10f64.powf(e))],
            ),
            1..40,
        )
        .prop_filter("some power", |s| s.iter().any(|l| l.4 > 0.0))
    }

    /// The walk from the root for `x`, from `at` (one-sided where it says so and has a
    /// normal).
    fn pick_at<T: PdfHittable>(
        tree: &LightTree<T>,
        at: &ShadingContext,
        one_sided: bool,
        x: f64,
    ) -> Option<(usize, f64, usize, f64)> {
        let n = at.unit_normal();
        tree.pick_at(at.point, n, one_sided && n.is_some(), x)
    }

    /// A point, with or without a normal, receiving on one side or both.
    fn origin() -> impl Strategy<Value = (DVec3, Option<DVec3>, bool)> {
        (
            prop_oneof![
                prop::array::uniform3(-12.0f64..12.0).prop_map(DVec3::from),
                prop::array::uniform3(-1e6f64..1e6).prop_map(DVec3::from),
            ],
            prop::option::of(prop::array::uniform3(-1.0f64..1.0).prop_map(DVec3::from)),
            any::<bool>(),
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The walk's probabilities, found light by light from the leaf up, are a
        /// distribution over the lights of power (each in `[0, 1]`, summing to 1 within
        /// the rounding of the sum: each probability is a product of at most `depth`
        /// shares, each within an ulp, and the sum of `n` terms adds `n` more, with a
        /// normal as without; for a one-sided receiver, at most 1, its lights wholly behind
        /// of probability 0: the walk may find every child of a node behind it, and end
        /// on no light), and a stratified
        /// walk from the root lands on each light as often as that says: each light takes
        /// one interval of `x`, so `N` evenly spaced `x` land on it its probability times
        /// `N`, within one (and the rounding).
        #[test]
        fn the_walk_picks_each_light_with_its_probability(
            specs in specs(),
            offset in prop_oneof![Just(0.0), Just(1e9)],
            (o, normal, one_sided) in origin(),
        ) {
            let tree = tree(&specs, offset);
            let origin = o + offset;
            let at = ShadingContext { point: origin, normal };
            let one_sided = one_sided && at.unit_normal().is_some();
            let probability = |i| if one_sided { tree.probability_reflecting(&at, i) } else { tree.probability(&at, i) };
            let p: Vec<f64> = (0..specs.len()).map(probability).collect();
            let sum: f64 = p.iter().sum();
            let depth = 2 * specs.len();
            let rounding = (depth + specs.len()) as f64 * f64::EPSILON;
            if one_sided {
                prop_assert!(sum <= 1.0 + rounding, "sum {}", sum);
            } else {
                prop_assert!((sum - 1.0).abs() <= rounding, "sum {}", sum);
            }
            for (i, &pi) in p.iter().enumerate() {
                prop_assert!((0.0..=1.0).contains(&pi));
                if specs[i].4 == 0.0 {
                    prop_assert_eq!(pi, 0.0);
                }
                // Wholly behind a one-sided receiver (every corner of its box by more
                // than rounding): never picked.
                if let (true, Some(n)) = (one_sided, at.unit_normal()) {
                    let b = tree.lights()[i].bounding_box();
                    let corners = (0..8).map(|k| DVec3::select(
                        glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), b.max(), b.min()));
                    if corners.into_iter().all(|c| n.dot(c - origin) < -1e-6 * (1.0 + origin.length())) {
                        prop_assert_eq!(pi, 0.0, "light {} behind", i);
                    }
                }
            }
            const N: usize = 4096;
            let mut counts = alloc::vec![0usize; specs.len()];
            for k in 0..N {
                let picked = pick_at(&tree, &at, one_sided, (k as f64 + 0.5) / N as f64);
                // The walk always ends on a light (but where all are behind a one-sided
                // receiver).
                prop_assert!(picked.is_some() || one_sided);
                if let Some((i, rest, _, probability)) = picked {
                    prop_assert!((0.0..1.0).contains(&rest));
                    // The walk's own product is the one found from the leaf up.
                    prop_assert_eq!(probability, p[i]);
                    counts[i] += 1;
                }
            }
            // Each light takes one interval of `x`.
            for (i, &count) in counts.iter().enumerate() {
                let expected = p[i] * N as f64;
                prop_assert!((count as f64 - expected).abs() <= 1.0 + 1e-9 * N as f64,
                    "light {}: {} picks, expected {}", i, count, expected);
            }
        }

        /// The density of a sampled direction is the sum, over every light, of its
        /// probability times its own density (found here by a loop over all of them, not
        /// by the tree's walk along the ray), and positive (clause 6). The two sums add the
        /// same terms in other orders, each product within `2 depth` ulps: the tolerance.
        #[test]
        fn the_density_is_the_walk_times_each_lights_density(
            specs in specs(),
            (origin, normal, one_sided) in origin(),
            u in prop::array::uniform2(0.0f64..1.0),
        ) {
            let tree = tree(&specs, 0.0);
            let at = ShadingContext { point: origin, normal };
            let (n, u) = (at.unit_normal(), DVec2::from(u));
            let d = tree.sample(origin, n, one_sided && n.is_some(), u);
            prop_assert!(d.is_finite());
            let one_sided = one_sided && n.is_some();
            let pdf = if one_sided { tree.light_pdf_reflecting(&at, d) } else { tree.light_pdf(&at, d) };
            let loop_sum: f64 = (0..specs.len())
                .map(|i| {
                    let p = if one_sided { tree.probability_reflecting(&at, i) } else { tree.probability(&at, i) };
                    p * tree.lights()[i].pdf_value(origin, d)
                })
                .sum();
            let rounding = (4 * specs.len() + specs.len()) as f64 * f64::EPSILON;
            prop_assert!((pdf - loop_sum).abs() <= rounding * loop_sum, "{} against {}", pdf, loop_sum);
            // A light that can be reached from here gets a density: the sampled direction
            // reaches the light it was drawn toward.
            if let Some((i, ..)) = pick_at(&tree, &at, one_sided, u.x)
                && tree.lights()[i].pdf_value(origin, d) > 0.0
            {
                prop_assert!(pdf > 0.0);
            }
            prop_assert!(!tree.pdf_value(origin, d).is_nan());
        }

        /// As a `Hittable`, the tree answers as the loop over its lights.
        #[test]
        fn hits_are_the_loops(specs in specs(), (origin, _, _) in origin(), d in prop::array::uniform3(-1.0f64..1.0)) {
            let tree = tree(&specs, 0.0);
            let ray = Ray::new(origin, DVec3::from(d));
            let tree_hit = tree.hit(&ray, Interval::FORWARD).map(|h| h.t);
            let loop_hit = tree.lights().hit(&ray, Interval::FORWARD).map(|h| h.t);
            prop_assert_eq!(tree_hit, loop_hit);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1024))]

        /// The importance is a bound: where it is 0 for a cluster of lights (one to three,
        /// merged as the build merges them), no point of any of them sends light toward
        /// `p` from its emitting side onto `p`'s surface (either side, or its front where it receives on one side alone: checked by brute
        /// force on a grid of points of each panel, a margin of 1e-9 in the cosines for
        /// rounding). A light the walk could never pick must be one that cannot light `p`.
        #[test]
        fn a_cluster_of_importance_0_cannot_light_the_point(
            lights in prop::collection::vec((
                0u8..4,
                prop::array::uniform3(-3.0f64..3.0),
                0.1f64..2.0,
                prop::array::uniform3(-1.0f64..1.0),
            ), 1..4),
            p in prop::array::uniform3(-6.0f64..6.0),
            normal in prop::option::of(prop::array::uniform3(-1.0f64..1.0)),
            one_sided in any::<bool>(),
        ) {
            let p = DVec3::from(p);
            let normal = normal.and_then(|n| DVec3::from(n).try_normalize());

            let mut cluster = None;
            let mut panels = Vec::new();
            for &(kind, at, size, turn) in &lights {
                let (u, v) = DVec3::from(turn).normalize_or(DVec3::Y).any_orthonormal_pair();
                let emission = match kind {
                    0 => Emission::OneSide(u.cross(v)),
                    1 => Emission::BothSides(u.cross(v)),
                    2 => Emission::Everywhere,
                    // A cone of 0.1 to 1.5 radians.
                    _ => Emission::Cone { axis: u.cross(v), angle: 0.1 + 0.7 * size },
                };
                let corner = DVec3::from(at);
                let quad = Quad::new(corner, u * size, v * size).unwrap();
                let c = super::Cluster::of(quad.bounding_box(), 1.0, emission).unwrap();
                cluster = Some(cluster.map_or(c, |a: super::Cluster| a.union(&c)));
                panels.push((corner, u * size, v * size, emission));
            }
            let cluster = cluster.unwrap();
            // About one case in six: the others have nothing to check.
            let importance = if one_sided {
                cluster.importance::<true>(p, normal)
            } else {
                cluster.importance::<false>(p, normal)
            };
            if importance > 0.0 {
                return Ok(());
            }
            for (corner, u, v, emission) in panels {
                for i in 0..=4 {
                    for j in 0..=4 {
                        let q = corner + u * (f64::from(i) / 4.0) + v * (f64::from(j) / 4.0);
                        let Some(toward_p) = (p - q).try_normalize() else { continue };
                        let emits = match emission {
                            Emission::Everywhere => true,
                            Emission::OneSide(m) => m.normalize().dot(toward_p) > 1e-9,
                            Emission::BothSides(m) => m.normalize().dot(toward_p).abs() > 1e-9,
                            Emission::Cone { axis, angle } => {
                                axis.normalize().dot(toward_p) > angle.cos() + 1e-9
                            }
                        };
                        // From in front of a one-sided receiver (`-toward_p` from `p` to
                        // the light), or either side.
                        let received = normal.is_none_or(|n| if one_sided {
                            -n.dot(toward_p) > 1e-9
                        } else {
                            n.dot(toward_p).abs() > 1e-9
                        });
                        prop_assert!(!(emits && received), "{q} lights {p} though the importance is 0");
                    }
                }
            }
        }
    }

    /// Where the walk cannot go wrong: one light is picked always; a light of no power
    /// never; an origin on a light, inside a cluster's box or far away, or not finite,
    /// gives no NaN.
    #[test]
    fn edges() {
        let panel = |x: f64| Quad::new(DVec3::new(x, 0.0, 0.0), DVec3::X, DVec3::Z).unwrap();
        let up = Emission::OneSide(DVec3::Y);
        let one = LightTree::new(alloc::vec![panel(0.0)], &[2.0], &[up]).unwrap();
        assert_eq!(
            one.probability(&ShadingContext::at(DVec3::new(0.5, 1.0, 0.5)), 0),
            1.0
        );
        let d = one.sample_direction(DVec3::new(0.5, 1.0, 0.5), DVec2::splat(0.5));
        assert!(one.pdf_value(DVec3::new(0.5, 1.0, 0.5), d) > 0.0);

        let lights = alloc::vec![panel(0.0), panel(2.0), panel(4.0)];
        let tree = LightTree::new(lights, &[1.0, 0.0, 3.0], &[up; 3]).unwrap();
        for origin in [
            DVec3::new(2.5, 0.0, 0.5),   // on the light of no power
            DVec3::new(0.25, 0.0, 0.25), // on a light
            DVec3::new(1.5, 0.0, 0.5),   // inside the boxes of clusters
            DVec3::new(1e300, -1e300, 3.0),
            DVec3::new(2.0, -5.0, 0.5), // below every light
        ] {
            assert_eq!(tree.probability(&ShadingContext::at(origin), 1), 0.0);
            let sum: f64 = (0..3)
                .map(|i| tree.probability(&ShadingContext::at(origin), i))
                .sum();
            assert!((sum - 1.0).abs() < 1e-15, "{origin}: {sum}");
            for u in [DVec2::ZERO, DVec2::splat(0.5), DVec2::splat(1.0 - 1e-16)] {
                let d = tree.sample_direction(origin, u);
                assert!(!tree.pdf_value(origin, d).is_nan(), "{origin}");
            }
        }
        for bad in [DVec3::NAN, DVec3::INFINITY] {
            assert_eq!(tree.sample_direction(bad, DVec2::splat(0.5)), DVec3::ZERO);
            assert_eq!(tree.pdf_value(bad, DVec3::Y), 0.0);
            assert_eq!(tree.probability(&ShadingContext::at(bad), 0), 0.0);
        }
        let empty: LightTree<Quad> = LightTree::new(alloc::vec![], &[], &[]).unwrap();
        assert_eq!(
            empty.sample_direction(DVec3::ZERO, DVec2::splat(0.5)),
            DVec3::ZERO
        );
        assert_eq!(empty.pdf_value(DVec3::ZERO, DVec3::Y), 0.0);
        assert!(
            empty
                .hit(&Ray::new(DVec3::ZERO, DVec3::Y), Interval::FORWARD)
                .is_none()
        );
    }

    /// The deepest kind of tree the build's heuristic makes: balls along a line, each twice
    /// as far out and as large as the last, nearly a chain down to depth 32, then split by
    /// count (leaves 39 deep, of 200). A ray along the line meets every node's box, and the
    /// walks through them (the nearest hit, the density) and up from each leaf (each
    /// light's probability) answer as the loop over the lights does, within their buffers
    /// (see [`MAX_DEPTH`]).
    #[test]
    fn the_deepest_tree_walks_within_its_buffers() {
        let n = 200;
        let lights: Vec<Sphere> = (0..n)
            .map(|i| {
                let r = 2f64.powi(i);
                Sphere::new(DVec3::new(3.0 * r, 0.0, 0.0), r).unwrap()
            })
            .collect();
        let tree =
            LightTree::new(lights.clone(), &[1.0; 200], &[Emission::Everywhere; 200]).unwrap();
        let depth = |mut n: usize| {
            let mut d = 0;
            while tree.parents[n] != super::NONE {
                (n, d) = (tree.parents[n] as usize, d + 1);
            }
            d
        };
        let deepest = (0..tree.nodes.len()).map(depth).max().unwrap();
        assert!(
            (super::MAX_DEPTH / 2..super::MAX_DEPTH).contains(&deepest),
            "{deepest}"
        );
        let at = ShadingContext::at(DVec3::new(-1.0, 0.0, 0.0));
        let sum: f64 = (0..n as usize).map(|i| tree.probability(&at, i)).sum();
        assert!((sum - 1.0).abs() < 1e-12, "{sum}");
        let ray = Ray::new(at.point, DVec3::X);
        let want = crate::Hittable::hit(&lights, &ray, Interval::FORWARD);
        assert_eq!(
            tree.hit(&ray, Interval::FORWARD).map(|h| h.t),
            want.map(|h| h.t)
        );
        assert!(tree.light_pdf(&at, DVec3::X) > 0.0);
    }

    #[test]
    fn bad_lights_are_errors() {
        let panel = Quad::new(DVec3::ZERO, DVec3::X, DVec3::Z).unwrap();
        let up = Emission::OneSide(DVec3::Y);
        let make = |powers: &[f64], emission: &[Emission]| {
            LightTree::new(alloc::vec![panel; powers.len().max(1)], powers, emission).err()
        };
        assert!(matches!(
            make(&[1.0, 1.0], &[up]),
            Some(GeometryError::LengthMismatch { .. })
        ));
        assert!(matches!(
            make(&[-1.0], &[up]),
            Some(GeometryError::InvalidParameter { .. })
        ));
        assert!(matches!(
            make(&[f64::NAN], &[up]),
            Some(GeometryError::NonFinite { .. })
        ));
        assert!(matches!(
            make(&[0.0], &[up]),
            Some(GeometryError::InvalidParameter { .. })
        ));
        let zero = Emission::OneSide(DVec3::ZERO);
        assert!(matches!(
            make(&[1.0], &[zero]),
            Some(GeometryError::ZeroVector { .. })
        ));
        let nan = Emission::BothSides(DVec3::NAN);
        assert!(matches!(
            make(&[1.0], &[nan]),
            Some(GeometryError::NonFinite { .. })
        ));
        // A light of unbounded box is an infinite light, whose power is checked as any
        // other's; an empty box is still refused.
        struct Sky(crate::Aabb);
        impl Hittable for Sky {
            fn hit(&self, _: &Ray, _: Interval) -> Option<crate::HitRecord> {
                None
            }
            fn bounding_box(&self) -> crate::Aabb {
                self.0
            }
        }
        impl PdfHittable for Sky {
            fn pdf_value(&self, _: DVec3, _: DVec3) -> f64 {
                0.0
            }
            fn sample_direction(&self, _: DVec3, _: DVec2) -> DVec3 {
                DVec3::Y
            }
        }
        let sky = || Sky(crate::Aabb::UNIVERSE);
        assert!(LightTree::new(alloc::vec![sky()], &[1.0], &[Emission::Everywhere]).is_ok());
        assert!(matches!(
            LightTree::new(alloc::vec![sky()], &[f64::NAN], &[Emission::Everywhere]).err(),
            Some(GeometryError::NonFinite { .. })
        ));
        assert!(matches!(
            LightTree::new(alloc::vec![sky()], &[0.0], &[Emission::Everywhere]).err(),
            Some(GeometryError::InvalidParameter { .. })
        ));
        let empty = LightTree::new(
            alloc::vec![Sky(crate::Aabb::EMPTY)],
            &[1.0],
            &[Emission::Everywhere],
        );
        assert!(matches!(
            empty.err(),
            Some(GeometryError::InvalidParameter { .. })
        ));
    }
}
