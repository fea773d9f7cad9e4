//! Many lights: a tree over them that picks one by its importance from the shading point
//! (after Conty Estevez and Kulla 2018, "Importance Sampling of Many Lights with Adaptive
//! Tree Splitting", the method of pbrt-v4's `BVHLightSampler`).

use alloc::vec::Vec;
use core::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use crate::math::{atan2, gamma, length, sin_cos, sqrt, unit_and_length};
use crate::{
    Aabb, GeometryError, HitRecord, Hittable, Interval, PdfHittable, Quad, Ray, Triangle,
    TriangleMesh,
};

/// The directions a light emits in, for [`LightTree`]'s importance: a light that faces
/// away from a point is not picked there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Emission {
    /// From every point in every direction (a sphere, or a light whose orientation is not
    /// known): never ruled out by its orientation.
    Everywhere,
    /// From the side of a surface that the given normal points to (a one-sided diffuse
    /// panel): no light behind it.
    OneSide(DVec3),
    /// From both sides of a surface normal to the given vector.
    BothSides(DVec3),
}

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
/// [`LightTree::with_normal`] adds the shading normal: lights whose boxes lie wholly below
/// the surface's horizon are then never picked. As a [`Hittable`], the tree is the list of its lights
/// (the closest hit; ties go to the earlier light).
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{Emission, LightTree, PdfHittable, Quad};
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
/// assert!(lights.probability(under, None, 42) > 0.4);
/// assert!(lights.with_normal(DVec3::Y).probability(under, 42) > 0.55);
/// let d = lights.sample_direction(under, DVec2::new(0.3, 0.7));
/// assert!(lights.pdf_value(under, d) > 0.0);
/// // Seen from high above the panels, every one faces away: their importance there is 0,
/// // and the walk falls back on power alone.
/// let above = DVec3::new(420.5, 1000.0, 0.5);
/// assert!((lights.probability(above, None, 42) - 0.01).abs() < 1e-15);
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
    /// For each light, its leaf.
    leaves: Vec<u32>,
}

/// A node of the tree: the bounds of its lights, and its second child or its light.
#[derive(Clone, Copy, Debug)]
struct Node {
    cluster: Cluster,
    /// The second child of an inner node, or the light of a leaf.
    index: u32,
    leaf: bool,
}

/// What the importance knows of a set of lights.
#[derive(Clone, Copy, Debug)]
struct Cluster {
    bbox: Aabb,
    power: f64,
    /// Every light's normal lies within the angle `spread` of `axis` (`spread = PI`: any
    /// direction).
    axis: DVec3,
    spread: f64,
    /// `spread`'s cosine and sine.
    cos_spread: f64,
    sin_spread: f64,
    /// Whether a light emits on both sides of its normal.
    two_sided: bool,
}

/// How deep the tree may grow: splits by count from half this depth on keep it within,
/// for as many lights as `u32` counts.
const MAX_DEPTH: usize = 64;

/// Buckets per axis of the build's split search.
const BUCKETS: usize = 12;

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
    /// # Errors
    /// [`GeometryError::LengthMismatch`] if `powers` or `emission` differ in length from
    /// `lights`; [`GeometryError::NonFinite`] for a NaN or infinite power, or an emission
    /// normal that is not finite; [`GeometryError::InvalidParameter`] for a negative power,
    /// for powers all 0, or for a light whose bounding box is empty or unbounded;
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
        for (i, light) in lights.iter().enumerate() {
            let cluster = Cluster::of(light.bounding_box(), powers[i], emission[i])?;
            let centroid = 0.5 * (cluster.bbox.min() + cluster.bbox.max());
            prims.push(Prim {
                cluster,
                centroid,
                light: i as u32,
            });
        }
        if !lights.is_empty() && prims.iter().all(|p| p.cluster.power == 0.0) {
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
        let mut leaves = alloc::vec![0; lights.len()];
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
        })
    }

    /// The lights, in the order given.
    #[inline]
    #[must_use]
    pub fn lights(&self) -> &[T] {
        &self.lights
    }

    /// The tree seen from surfaces of the given normal: as a [`PdfHittable`], it picks no
    /// light whose box lies wholly below the horizon of a surface at the origin facing
    /// `normal` (no light there can reach the side the normal faces). Where every light
    /// the walk can still reach lies below it, the walk picks none: the sample is the zero
    /// vector (as for an empty tree), and the probabilities of the lights sum to less than
    /// 1 by that chance, which the density accounts for (a renderer that mixes the tree
    /// with other strategies stays unbiased). Cheap: a renderer makes one at every shading
    /// point. A normal of any finite, non-zero length is a direction; one of length 0 or
    /// not finite is ignored.
    ///
    /// Only for surfaces that do not transmit light: a light below a translucent surface's
    /// horizon still lights it.
    #[inline]
    #[must_use]
    pub fn with_normal(&self, normal: DVec3) -> WithNormal<'_, T> {
        WithNormal {
            tree: self,
            normal: direction_of(normal),
        }
    }

    /// The probability that a sample from `origin` (seen from a surface facing `normal`,
    /// where given) picks light `i`: the product of the choices on the walk down to it.
    ///
    /// # Panics
    /// If `i >= self.lights().len()`.
    #[must_use]
    pub fn probability(&self, origin: DVec3, normal: Option<DVec3>, i: usize) -> f64 {
        let normal = normal.and_then(direction_of);
        if !origin.is_finite() || self.hidden(origin, normal) {
            return 0.0;
        }
        self.reaching(self.leaves[i] as usize, origin, normal)
    }

    /// Whether every light lies wholly below the horizon of a surface at `origin` facing
    /// `normal` (the root's box does): then nothing is picked.
    #[inline]
    fn hidden(&self, origin: DVec3, normal: Option<DVec3>) -> bool {
        normal.is_some_and(|n| {
            self.nodes
                .first()
                .is_some_and(|root| root.cluster.below(origin, n))
        })
    }

    /// The probability that the walk reaches node `n` (given that the tree is not
    /// [`hidden`](LightTree::hidden)): the product of the choices on the way down to it,
    /// found on the way up.
    fn reaching(&self, mut n: usize, origin: DVec3, normal: Option<DVec3>) -> f64 {
        let mut p = 1.0;
        while let Some(&parent) = self.parents.get(n).filter(|&&p| p != NONE) {
            let parent = parent as usize;
            let Some(left) = self.left_probability(parent, origin, normal) else {
                return 0.0;
            };
            p *= if n == parent + 1 { left } else { 1.0 - left };
            n = parent;
        }
        p
    }

    /// The probability that the walk at inner node `n` goes to its first child; `None`
    /// where it can go to neither (see [`LightTree::with_normal`]).
    ///
    /// By importance; where both children's is 0 (every light faces away from the point,
    /// or is too dim to count), by power, among the children not wholly below the
    /// horizon. Where both are (the parent's box reached above the horizon, its children's
    /// do not), the walk ends without a light, as pbrt-v4's `BVHLightSampler` does: so a
    /// light below the horizon is never picked.
    #[inline]
    fn left_probability(&self, n: usize, origin: DVec3, normal: Option<DVec3>) -> Option<f64> {
        let (a, b) = (
            &self.nodes[n + 1].cluster,
            &self.nodes[self.nodes[n].index as usize].cluster,
        );
        share(a.importance(origin, normal), b.importance(origin, normal)).or_else(|| {
            let seen = |c: &Cluster| {
                if normal.is_some_and(|m| c.below(origin, m)) {
                    0.0
                } else {
                    c.power
                }
            };
            share(seen(a), seen(b))
        })
    }

    /// The walk from the root: the light `x` in `[0, 1)` picks, and what is left of `x`,
    /// rescaled to `[0, 1)`; `None` for an empty tree.
    /// `None` for an empty tree, and where the walk picks no light (see
    /// [`LightTree::left_probability`]).
    fn pick(&self, origin: DVec3, normal: Option<DVec3>, x: f64) -> Option<(usize, f64)> {
        if self.nodes.is_empty() || self.hidden(origin, normal) {
            return None;
        }
        // Into [0, 1) (NaN to 0); each choice rescales what is left of it to [0, 1).
        let below_one = 1.0 - f64::EPSILON / 2.0;
        let mut x = if x > 0.0 { x.min(below_one) } else { 0.0 };
        let mut n = 0;
        while !self.nodes[n].leaf {
            let left = self.left_probability(n, origin, normal)?;
            if x < left {
                x /= left;
                n += 1;
            } else {
                x = (x - left) / (1.0 - left);
                n = self.nodes[n].index as usize;
            }
            x = x.clamp(0.0, below_one);
        }
        Some((self.nodes[n].index as usize, x))
    }

    fn sample(&self, origin: DVec3, normal: Option<DVec3>, u: DVec2) -> DVec3 {
        if !origin.is_finite() {
            return DVec3::ZERO;
        }
        self.pick(origin, normal, u.x)
            .map_or(DVec3::ZERO, |(i, x)| {
                self.lights[i].sample_direction(origin, DVec2::new(x, u.y))
            })
    }

    fn density(&self, origin: DVec3, normal: Option<DVec3>, direction: DVec3) -> f64 {
        let ray = Ray::new(origin, direction);
        if self.nodes.is_empty() || !ray.is_valid() || self.hidden(origin, normal) {
            return 0.0;
        }
        if let [only] = self.lights.as_slice() {
            // Picked always: its own density, and no box test before it.
            return only.pdf_value(origin, direction);
        }
        // The lights the direction reaches, found by the boxes the ray meets (a light it
        // reaches lies in the box of every node above it); the walk's probability only for
        // those (most directions reach none, or one), from its leaf up.
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
                    sum += self.reaching(n, origin, normal) * pdf;
                }
                continue;
            }
            stack[top] = node.index;
            stack[top + 1] = n as u32 + 1;
            top += 2;
        }
        sum
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
        let mut faces = Vec::with_capacity(mesh.face_count());
        let (mut powers, mut emission) = (Vec::new(), Vec::new());
        let sides = if two_sided { 2.0 } else { 1.0 };
        for face in mesh.faces() {
            let [a, b, c] = face.corners();
            let Ok(quad) = Quad::with_interior(a, b - a, c - a, Triangle) else {
                continue;
            };
            let normal = quad.plane().normal();
            powers.push(sides * PI * radiance * quad.area());
            emission.push(if two_sided {
                Emission::BothSides(normal)
            } else {
                Emission::OneSide(normal)
            });
            faces.push(quad.with_material(mesh.material()));
        }
        Self::new(faces, &powers, &emission)
    }
}

/// `a / (a + b)`, the share of the first of two non-negative weights, where it is a
/// number: `None` where both are 0; an infinite one against a finite one takes all.
#[inline]
fn share(a: f64, b: f64) -> Option<f64> {
    let sum = a + b;
    if sum > 0.0 && sum.is_finite() {
        Some(a / sum)
    } else if a.is_infinite() || b.is_infinite() {
        Some(match (a.is_infinite(), b.is_infinite()) {
            (true, true) => 0.5,
            (true, false) => 1.0,
            _ => 0.0,
        })
    } else if sum.is_infinite() {
        // Two finite weights whose sum overflows: halved, they do not.
        Some(0.5 * a / (0.5 * a + 0.5 * b))
    } else {
        None
    }
}

/// `(cos, sin)` of `max(0, x - y)` for angles `x` and `y` in `[0, PI]` given by their cosines
/// and sines (`x`'s sine found only where it is needed).
#[inline]
fn minus_clamped(
    cos_x: f64,
    sin_x: impl FnOnce() -> f64,
    (cos_y, sin_y): (f64, f64),
) -> (f64, f64) {
    if cos_x >= cos_y {
        (1.0, 0.0)
    } else {
        let sin_x = sin_x();
        (cos_x * cos_y + sin_x * sin_y, sin_x * cos_y - cos_x * sin_y)
    }
}

/// The sine of an angle in `[0, PI]` from its cosine.
#[inline]
fn sine(cos: f64) -> f64 {
    sqrt((1.0 - cos * cos).max(0.0))
}

impl Cluster {
    /// One light's bounds.
    fn of(bbox: Aabb, power: f64, emission: Emission) -> Result<Self, GeometryError> {
        if !power.is_finite() {
            return Err(GeometryError::NonFinite { what: "power" });
        }
        if power < 0.0 {
            return Err(GeometryError::InvalidParameter {
                what: "power",
                value: power,
                domain: "[0, infinity)",
            });
        }
        if !bbox.is_bounded() || bbox.is_empty() {
            return Err(GeometryError::InvalidParameter {
                what: "light's bounding box extent",
                value: f64::INFINITY,
                domain: "a bounded, non-empty box",
            });
        }
        let (axis, spread, two_sided) = match emission {
            Emission::Everywhere => (DVec3::Z, PI, false),
            Emission::OneSide(normal) => (unit(normal)?, 0.0, false),
            Emission::BothSides(normal) => (unit(normal)?, 0.0, true),
        };
        Ok(Self::with_spread(bbox, power, axis, spread, two_sided))
    }

    fn with_spread(bbox: Aabb, power: f64, axis: DVec3, spread: f64, two_sided: bool) -> Self {
        let (sin_spread, cos_spread) = sin_cos(spread);
        Self {
            bbox,
            power,
            axis,
            spread,
            cos_spread,
            sin_spread: sin_spread.max(0.0),
            two_sided,
        }
    }

    /// The bounds of two clusters' lights together. A cluster of no power adds its box
    /// only: its orientation never matters.
    fn union(&self, other: &Self) -> Self {
        let bbox = self.bbox.union(&other.bbox);
        let power = self.power + other.power;
        let (a, b) = match (self.power > 0.0, other.power > 0.0) {
            (true, false) | (false, false) => (self, self),
            (false, true) => (other, other),
            (true, true) if self.spread >= other.spread => (self, other),
            (true, true) => (other, self),
        };
        let two_sided = a.two_sided || b.two_sided;
        // `b`'s cone inside `a`'s (the wider): the angle between their axes at most the
        // difference of their spreads, compared by cosines, without a trigonometric call
        // (the common case: lights of one normal, and a cone grown to every direction).
        let cos_between = a.axis.dot(b.axis);
        let cos_difference = a.cos_spread * b.cos_spread + a.sin_spread * b.sin_spread;
        let keep_a = Self {
            bbox,
            power,
            two_sided,
            ..*a
        };
        if a.spread >= PI || cos_between >= cos_difference {
            return keep_a;
        }
        // The cone around both cones: `a`'s turned toward `b`'s just enough.
        let between = atan2(length(a.axis.cross(b.axis)), cos_between);
        if (between + b.spread).min(PI) <= a.spread {
            return keep_a;
        }
        let spread = 0.5 * (a.spread + between + b.spread);
        let turn_about = a.axis.cross(b.axis).try_normalize();
        match turn_about {
            Some(k) if spread < PI => {
                // Rodrigues' rotation of `a.axis` about `k` (normal to it) by `spread -
                // a.spread`.
                let (sin, cos) = sin_cos(spread - a.spread);
                let axis = (a.axis * cos + k.cross(a.axis) * sin).normalize();
                Self::with_spread(bbox, power, axis, spread, two_sided)
            }
            _ => Self::with_spread(bbox, power, a.axis, PI, two_sided),
        }
    }

    /// A bound on the light the cluster sends to `p` (on a surface facing `normal`, where
    /// given): its power over the squared distance to its centre (no nearer than its
    /// radius), times the cosine of the least angle at which any of its lights can face
    /// `p`, and times the cosine of the least angle between `normal` and any direction
    /// into the cluster's box; 0 where the first passes 90 degrees (every light faces
    /// away) or the second does (the box lies below the horizon).
    fn importance(&self, p: DVec3, normal: Option<DVec3>) -> f64 {
        if self.power == 0.0 {
            return 0.0;
        }
        let (min, max) = (self.bbox.min(), self.bbox.max());
        let centre = 0.5 * min + 0.5 * max;
        let radius2 = (0.5 * max - 0.5 * min).length_squared();
        let from_centre = p - centre;
        let d2 = from_centre.length_squared();
        // The cone of directions from `p` into the box's bounding sphere (which holds the
        // box): all of them from inside it.
        let (cos_box, sin_box) = if d2 <= radius2 {
            (-1.0, 0.0)
        } else {
            let sin2 = radius2 / d2;
            (sqrt(1.0 - sin2), sqrt(sin2))
        };
        let toward_p = if d2 > 0.0 {
            from_centre / sqrt(d2)
        } else {
            self.axis
        };
        // The least angle between a light's normal and a direction from the box to `p`.
        let mut cos_normal = self.axis.dot(toward_p);
        if self.two_sided {
            cos_normal = cos_normal.abs();
        }
        let spread = (self.cos_spread, self.sin_spread);
        let (cos_x, sin_x) = minus_clamped(cos_normal, || sine(cos_normal), spread);
        let least = minus_clamped(cos_x, || sin_x, (cos_box, sin_box));
        // Diffuse emitters send nothing at 90 degrees from their normal and beyond.
        if least.0 <= 0.0 {
            return 0.0;
        }
        let mut importance = self.power * least.0 / d2.max(radius2);
        if let Some(n) = normal {
            // Below the horizon by the box itself: its bounding sphere can reach above the
            // horizon where no light does.
            if self.below(p, n) {
                return 0.0;
            }
            // The bound on the cosine by the sphere; where rounding puts even the sphere
            // below while the box is not, no bound.
            let cos_in = (-toward_p).dot(n);
            let (cos_seen, _) = minus_clamped(cos_in, || sine(cos_in), (cos_box, sin_box));
            if cos_seen > 0.0 {
                importance *= cos_seen;
            }
        }
        if importance.is_nan() { 0.0 } else { importance }
    }

    /// Whether the box lies wholly below the horizon of a surface at `p` facing `n` (unit):
    /// its corner farthest along `n` lies below the plane through `p`, by more than the
    /// rounding of the test (the difference, the products and the sums: `gamma(4)` of the
    /// terms' magnitudes) and of `n`'s normalization (a tilt of a few ulps, `gamma(4)` of
    /// the distance again), so that a box touching or crossing the plane never counts.
    #[inline]
    fn below(&self, p: DVec3, n: DVec3) -> bool {
        let corner = DVec3::select(n.cmpge(DVec3::ZERO), self.bbox.max(), self.bbox.min());
        let rel = corner - p;
        n.dot(rel) < -gamma(8) * rel.abs().element_sum()
    }
}

/// An emission normal as a unit vector, or the reason it cannot be one: any finite,
/// non-zero vector is a normal, however long or short.
fn unit(normal: DVec3) -> Result<DVec3, GeometryError> {
    if !normal.is_finite() {
        return Err(GeometryError::NonFinite {
            what: "emission normal",
        });
    }
    direction_of(normal).ok_or(GeometryError::ZeroVector {
        what: "emission normal",
    })
}

/// `v` as a unit vector, for any finite, non-zero `v` (scaled first, so that its square
/// neither over- nor underflows); `None` for a zero or non-finite one.
fn direction_of(v: DVec3) -> Option<DVec3> {
    let (unit, length) = unit_and_length(v);
    (length > 0.0 && unit.is_finite()).then_some(unit)
}

/// A light as the build sorts it.
#[derive(Clone, Copy, Debug)]
struct Prim {
    cluster: Cluster,
    centroid: DVec3,
    light: u32,
}

/// Builds the subtree over `prims` into `nodes`, depth first, and returns its cluster: a
/// leaf for one light; otherwise split where the cost of the two halves is least, each
/// half's cost being its power times the solid angle its cone of emission can reach times
/// its box's surface area, times the box's aspect along the split axis (the surface area
/// orientation heuristic of Conty Estevez and Kulla 2018), over [`BUCKETS`] buckets of
/// centroids per axis; by count where no bucket boundary splits them, and from half
/// [`MAX_DEPTH`] on.
fn build(prims: &mut [Prim], nodes: &mut Vec<Node>, depth: usize) -> Cluster {
    let n = nodes.len();
    if let [prim] = prims {
        nodes.push(Node {
            cluster: prim.cluster,
            index: prim.light,
            leaf: true,
        });
        return prim.cluster;
    }
    // A placeholder, filled once the children are built.
    nodes.push(Node {
        cluster: prims[0].cluster,
        index: 0,
        leaf: false,
    });
    let heuristic = if prims.len() == 2 {
        // Two lights: nothing to choose.
        Some(1)
    } else if depth < MAX_DEPTH / 2 {
        split(prims)
    } else {
        None
    };
    let mid = heuristic.unwrap_or_else(|| {
        // By count: the median along the longest axis of the centroids.
        let (lo, hi) = centroid_bounds(prims);
        let axis = (hi - lo).max_position();
        let mid = prims.len() / 2;
        prims.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
        mid
    });
    let (left, right) = prims.split_at_mut(mid);
    let a = build(left, nodes, depth + 1);
    let second = nodes.len() as u32;
    let b = build(right, nodes, depth + 1);
    let cluster = a.union(&b);
    nodes[n] = Node {
        cluster,
        index: second,
        leaf: false,
    };
    cluster
}

/// The cheapest split of `prims` by the heuristic of [`build`]: `prims` partitioned and
/// the size of the first part; `None` where every centroid falls in one bucket on every
/// axis.
fn split(prims: &mut [Prim]) -> Option<usize> {
    let (lo, hi) = centroid_bounds(prims);
    let whole = prims
        .iter()
        .fold(Aabb::EMPTY, |b, p| b.union(&p.cluster.bbox));
    let extent = whole.max() - whole.min();
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        let width = hi[axis] - lo[axis];
        if width <= 0.0 || !width.is_finite() {
            continue;
        }
        let bucket = |p: &Prim| bucket(p.centroid[axis], lo[axis], width);
        let mut buckets: [Option<Cluster>; BUCKETS] = [None; BUCKETS];
        for p in prims.iter() {
            let b = &mut buckets[bucket(p)];
            *b = Some(b.map_or(p.cluster, |c| c.union(&p.cluster)));
        }
        // The aspect along this axis: thin slabs cut across are dear.
        let aspect = extent.max_element() / extent[axis].max(f64::MIN_POSITIVE);
        // The clusters below and above each cut, by a sweep from each end.
        let sweep = |order: &mut dyn Iterator<Item = usize>| {
            let mut running: Option<Cluster> = None;
            let mut out = [None; BUCKETS];
            for b in order {
                if let Some(c) = &buckets[b] {
                    running = Some(running.map_or(*c, |r| r.union(c)));
                }
                out[b] = running;
            }
            out
        };
        let below = sweep(&mut (0..BUCKETS));
        let above = sweep(&mut (0..BUCKETS).rev());
        for cut in 1..BUCKETS {
            let (Some(a), Some(b)) = (below[cut - 1], above[cut]) else {
                continue;
            };
            let cost = aspect * (a.cost() + b.cost());
            if best.is_none_or(|(c, ..)| cost < c) {
                best = Some((cost, axis, cut));
            }
        }
    }
    let (_, axis, cut) = best?;
    // Partitioned by the same bucket test the costs were found with.
    let width = hi[axis] - lo[axis];
    let mut first = 0;
    for i in 0..prims.len() {
        if bucket(prims[i].centroid[axis], lo[axis], width) < cut {
            prims.swap(i, first);
            first += 1;
        }
    }
    (first > 0 && first < prims.len()).then_some(first)
}

/// The corners of the box of the lights' centroids.
fn centroid_bounds(prims: &[Prim]) -> (DVec3, DVec3) {
    prims
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.centroid), hi.max(p.centroid))
        })
}

/// The bucket of a centroid at `c` along an axis whose centroids span `width` from `lo`.
#[inline]
fn bucket(c: f64, lo: f64, width: f64) -> usize {
    (((c - lo) / width * BUCKETS as f64) as usize).min(BUCKETS - 1)
}

impl Cluster {
    /// The cost of the heuristic of [`build`] for one side of a split.
    fn cost(&self) -> f64 {
        let e = self.bbox.max() - self.bbox.min();
        let area = e.x * e.y + e.y * e.z + e.z * e.x;
        self.power * self.orientation_measure() * area
    }

    /// The measure of the directions the cluster's lights emit in, each falling off to 0 at
    /// 90 degrees from its normal: the `M_Omega` of Conty Estevez and Kulla 2018's
    /// orientation heuristic, `2 PI (1 - cos s) + PI / 2 (2 r sin s - cos(s - 2 r) - 2 s
    /// sin s + cos s)` for the spread `s` and `r = min(s + PI / 2, PI)`, where
    /// `cos(s - 2 r)` is `-cos s` for `s <= PI / 2` and `cos s` beyond: no trigonometric
    /// call but the cached cosine and sine.
    fn orientation_measure(&self) -> f64 {
        let (s, cos_s, sin_s) = (self.spread, self.cos_spread, self.sin_spread);
        let (reach, cos_s_minus_2_reach) = if s <= FRAC_PI_2 {
            (s + FRAC_PI_2, -cos_s)
        } else {
            (PI, cos_s)
        };
        2.0 * PI * (1.0 - cos_s)
            + 0.5 * PI * (2.0 * reach * sin_s - cos_s_minus_2_reach - 2.0 * s * sin_s + cos_s)
    }
}

/// [`LightTree::with_normal`]: the tree, seen from surfaces facing `normal`.
#[derive(Clone, Copy, Debug)]
pub struct WithNormal<'a, T> {
    tree: &'a LightTree<T>,
    normal: Option<DVec3>,
}

impl<T: PdfHittable> Hittable for LightTree<T> {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        // The lights under every node whose box the ray meets, nearest kept (ties to the
        // earlier light, as the list's loop keeps them).
        let mut best: Option<(usize, HitRecord)> = None;
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
                if let Some(hit) = self.lights[i].hit(ray, reach) {
                    let better = best
                        .as_ref()
                        .is_none_or(|(j, b)| hit.t < b.t || (hit.t == b.t && i < *j));
                    if better {
                        best = Some((i, hit));
                    }
                }
                continue;
            }
            stack[top] = node.index;
            stack[top + 1] = n + 1;
            top += 2;
        }
        best.map(|(_, hit)| hit)
    }

    fn bounding_box(&self) -> Aabb {
        self.nodes
            .first()
            .map_or(Aabb::EMPTY, |root| root.cluster.bbox)
    }
}

impl<T: PdfHittable> PdfHittable for LightTree<T> {
    /// The sum, over the lights the direction reaches, of the probability that the walk
    /// picks each (from `origin`, with no normal) times its density; 0 for an empty tree
    /// or an invalid direction.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.density(origin, None, direction)
    }

    /// `u.x` makes the walk's choices (each rescaled to `[0, 1)` within the choice made)
    /// and, what is left of it, the chosen light's own `u.x`. The zero vector for an empty
    /// tree or an origin that is not finite (and, [`with_normal`](LightTree::with_normal),
    /// where the walk picks no light).
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.sample(origin, None, u)
    }
}

impl<T: PdfHittable> WithNormal<'_, T> {
    /// [`LightTree::probability`] with this normal.
    ///
    /// # Panics
    /// If `i >= self.lights().len()` of the tree.
    #[must_use]
    pub fn probability(&self, origin: DVec3, i: usize) -> f64 {
        self.tree.probability(origin, self.normal, i)
    }
}

impl<T: PdfHittable> Hittable for WithNormal<'_, T> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.tree.hit(ray, ray_t)
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.tree.bounding_box()
    }
}

impl<T: PdfHittable> PdfHittable for WithNormal<'_, T> {
    #[inline]
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.tree.density(origin, self.normal, direction)
    }

    #[inline]
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.tree.sample(origin, self.normal, u)
    }
}

#[cfg(test)]
mod tests {
    use super::{Emission, LightTree};
    use crate::{GeometryError, Hittable, Interval, PdfHittable, Quad, Ray, Sphere};
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

    fn origin() -> impl Strategy<Value = (DVec3, Option<DVec3>)> {
        (
            prop_oneof![
                prop::array::uniform3(-12.0f64..12.0).prop_map(DVec3::from),
                prop::array::uniform3(-1e6f64..1e6).prop_map(DVec3::from),
            ],
            prop::option::of(prop::array::uniform3(-1.0f64..1.0).prop_map(DVec3::from)),
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The walk's probabilities, found light by light from the leaf up, are a
        /// distribution over the lights of power (each in `[0, 1]`, summing to 1 within
        /// the rounding of the sum: each probability is a product of at most `depth`
        /// shares, each within an ulp, and the sum of `n` terms adds `n` more; with a
        /// normal, to at most 1, the rest being the chance of no light), and a stratified
        /// walk from the root lands on each light as often as that says: each light takes
        /// one interval of `x`, so `N` evenly spaced `x` land on it its probability times
        /// `N`, within one (and the rounding).
        #[test]
        fn the_walk_picks_each_light_with_its_probability(
            specs in specs(),
            offset in prop_oneof![Just(0.0), Just(1e9)],
            (o, normal) in origin(),
        ) {
            let tree = tree(&specs, offset);
            let origin = o + offset;
            let p: Vec<f64> = (0..specs.len()).map(|i| tree.probability(origin, normal, i)).collect();
            let sum: f64 = p.iter().sum();
            let depth = 2 * specs.len();
            let rounding = (depth + specs.len()) as f64 * f64::EPSILON;
            // With a normal, the walk may end without a light (where every light it can
            // still reach lies below the horizon): then the sum is less than 1.
            prop_assert!(sum <= 1.0 + rounding, "sum {}", sum);
            if normal.is_none() {
                prop_assert!((sum - 1.0).abs() <= rounding, "sum {}", sum);
            }
            for (i, &pi) in p.iter().enumerate() {
                prop_assert!((0.0..=1.0).contains(&pi));
                if specs[i].4 == 0.0 {
                    prop_assert_eq!(pi, 0.0);
                }
            }
            let normal = normal.and_then(DVec3::try_normalize);
            const N: usize = 4096;
            let (mut counts, mut none) = (alloc::vec![0usize; specs.len()], 0usize);
            for k in 0..N {
                match tree.pick(origin, normal, (k as f64 + 0.5) / N as f64) {
                    Some((i, rest)) => {
                        prop_assert!((0.0..1.0).contains(&rest));
                        counts[i] += 1;
                    }
                    None => none += 1,
                }
            }
            // Each light, and no light, takes intervals of `x`: one per dead end of the
            // walk for no light, so its count may be off by one for each.
            for (i, &count) in counts.iter().enumerate() {
                let expected = p[i] * N as f64;
                prop_assert!((count as f64 - expected).abs() <= 1.0 + 1e-9 * N as f64,
                    "light {}: {} picks, expected {}", i, count, expected);
            }
            let expected = (1.0 - sum) * N as f64;
            prop_assert!((none as f64 - expected).abs() <= specs.len() as f64 + 1e-9 * N as f64,
                "no light: {} picks, expected {}", none, expected);
        }

        /// The density of a sampled direction is the sum, over every light, of its
        /// probability times its own density (found here by a loop over all of them, not
        /// by the tree's walk along the ray), and positive (clause 6). The two sums add the
        /// same terms in other orders, each product within `2 depth` ulps: the tolerance.
        #[test]
        fn the_density_is_the_walk_times_each_lights_density(
            specs in specs(),
            (origin, normal) in origin(),
            u in prop::array::uniform2(0.0f64..1.0),
        ) {
            let tree = tree(&specs, 0.0);
            let lights = tree.with_normal(normal.unwrap_or(DVec3::ZERO));
            let d = lights.sample_direction(origin, DVec2::from(u));
            prop_assert!(d.is_finite());
            let pdf = lights.pdf_value(origin, d);
            let loop_sum: f64 = (0..specs.len())
                .map(|i| lights.probability(origin, i) * tree.lights()[i].pdf_value(origin, d))
                .sum();
            let rounding = (4 * specs.len() + specs.len()) as f64 * f64::EPSILON;
            prop_assert!((pdf - loop_sum).abs() <= rounding * loop_sum, "{} against {}", pdf, loop_sum);
            // A light that can be reached from here gets a density: the sampled direction
            // reaches the light it was drawn toward.
            if let Some((i, _)) = tree.pick(origin, normal.and_then(DVec3::try_normalize), u[0])
                && tree.lights()[i].pdf_value(origin, d) > 0.0
            {
                prop_assert!(pdf > 0.0);
            }
            prop_assert!(!tree.pdf_value(origin, d).is_nan());
        }

        /// As a `Hittable`, the tree answers as the loop over its lights.
        #[test]
        fn hits_are_the_loops(specs in specs(), (origin, _) in origin(), d in prop::array::uniform3(-1.0f64..1.0)) {
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
        /// `p` from its emitting side onto the side `p`'s normal faces (checked by brute
        /// force on a grid of points of each panel, a margin of 1e-9 in the cosines for
        /// rounding). A light the walk could never pick must be one that cannot light `p`.
        #[test]
        fn a_cluster_of_importance_0_cannot_light_the_point(
            lights in prop::collection::vec((
                0u8..3,
                prop::array::uniform3(-3.0f64..3.0),
                0.1f64..2.0,
                prop::array::uniform3(-1.0f64..1.0),
            ), 1..4),
            p in prop::array::uniform3(-6.0f64..6.0),
            normal in prop::option::of(prop::array::uniform3(-1.0f64..1.0)),
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
                    _ => Emission::Everywhere,
                };
                let corner = DVec3::from(at);
                let quad = Quad::new(corner, u * size, v * size).unwrap();
                let c = super::Cluster::of(quad.bounding_box(), 1.0, emission).unwrap();
                cluster = Some(cluster.map_or(c, |a: super::Cluster| a.union(&c)));
                panels.push((corner, u * size, v * size, emission));
            }
            let cluster = cluster.unwrap();
            // About one case in six: the others have nothing to check.
            if cluster.importance(p, normal) > 0.0 {
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
                        };
                        let received = normal.is_none_or(|n| n.dot(-toward_p) > 1e-9);
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
        assert_eq!(one.probability(DVec3::new(0.5, 1.0, 0.5), None, 0), 1.0);
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
            assert_eq!(tree.probability(origin, None, 1), 0.0);
            let sum: f64 = (0..3).map(|i| tree.probability(origin, None, i)).sum();
            assert!((sum - 1.0).abs() < 1e-15, "{origin}: {sum}");
            for u in [DVec2::ZERO, DVec2::splat(0.5), DVec2::splat(1.0 - 1e-16)] {
                let d = tree.sample_direction(origin, u);
                assert!(!tree.pdf_value(origin, d).is_nan(), "{origin}");
            }
        }
        for bad in [DVec3::NAN, DVec3::INFINITY] {
            assert_eq!(tree.sample_direction(bad, DVec2::splat(0.5)), DVec3::ZERO);
            assert_eq!(tree.pdf_value(bad, DVec3::Y), 0.0);
            assert_eq!(tree.probability(bad, None, 0), 0.0);
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
        // A light with no bounds to cluster by.
        struct Everywhere;
        impl Hittable for Everywhere {
            fn hit(&self, _: &Ray, _: Interval) -> Option<crate::HitRecord> {
                None
            }
            fn bounding_box(&self) -> crate::Aabb {
                crate::Aabb::UNIVERSE
            }
        }
        impl PdfHittable for Everywhere {
            fn pdf_value(&self, _: DVec3, _: DVec3) -> f64 {
                0.0
            }
            fn sample_direction(&self, _: DVec3, _: DVec2) -> DVec3 {
                DVec3::Y
            }
        }
        let unbounded = LightTree::new(alloc::vec![Everywhere], &[1.0], &[Emission::Everywhere]);
        assert!(matches!(
            unbounded.err(),
            Some(GeometryError::InvalidParameter { .. })
        ));
    }
}
