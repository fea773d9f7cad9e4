//! pbrt-v4's BVH light sampler, written from its description (Pharr, Jakob and Humphreys,
//! "Physically Based Rendering", 4th edition, section 12.6.3, `BVHLightSampler`) as the
//! anchor the light tree is measured against: a binary tree over the lights built by the
//! surface area orientation heuristic, one light a leaf, each inner choice in proportion to
//! `LightBounds::Importance`, whose distance clamp is `max(d^2, |diagonal| / 2)` (a length
//! against a squared length: it depends on the unit). Lights are the halls' one-sided
//! lamps: a normal each and no spread of it.

use core::f64::consts::{FRAC_PI_2, PI};

use hitkit::ShadingContext;
use hitkit::glam::DVec3;

/// What a node knows of its lights (pbrt-v4's `LightBounds`): a box, the power, a cone of
/// normals (axis and the cosine of its half-angle `theta_o`), and the cosine of the angle
/// past the normal at which emission stops (`theta_e`, 90 degrees for a diffuse lamp).
#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: DVec3,
    max: DVec3,
    phi: f64,
    w: DVec3,
    cos_o: f64,
    cos_e: f64,
}

/// `cos(max(0, a - b))` from the cosines and sines of `a` and `b` (the book's
/// `cosSubClamped`), and its sine.
fn sub_clamped((sin_a, cos_a): (f64, f64), (sin_b, cos_b): (f64, f64)) -> (f64, f64) {
    if cos_a > cos_b {
        (0.0, 1.0)
    } else {
        (sin_a * cos_b - cos_a * sin_b, cos_a * cos_b + sin_a * sin_b)
    }
}

fn safe_sqrt(x: f64) -> f64 {
    x.max(0.0).sqrt()
}

impl Bounds {
    fn union(&self, o: &Bounds) -> Bounds {
        if self.phi == 0.0 {
            return *o;
        }
        if o.phi == 0.0 {
            return *self;
        }
        let (w, cos_o) = cone_union((self.w, self.cos_o), (o.w, o.cos_o));
        Bounds {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
            phi: self.phi + o.phi,
            w,
            cos_o,
            cos_e: self.cos_e.min(o.cos_e),
        }
    }

    /// The book's `LightBounds::Importance` at `p`, with the receiver's normal `n` taken
    /// on either side.
    fn importance(&self, p: DVec3, n: Option<DVec3>) -> f64 {
        let centre = 0.5 * (self.min + self.max);
        let diagonal = self.max - self.min;
        let d2 = p.distance_squared(centre).max(0.5 * diagonal.length());
        let wi = (p - centre).normalize_or_zero();
        let cos_w = self.w.dot(wi);
        let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
        // The cone of directions into the box's bounding sphere.
        let r2 = (0.5 * diagonal).length_squared();
        let dist2 = p.distance_squared(centre);
        let cos_b = if dist2 < r2 {
            -1.0
        } else {
            safe_sqrt(1.0 - r2 / dist2)
        };
        let sin_b = safe_sqrt(1.0 - cos_b * cos_b);
        let sin_o = safe_sqrt(1.0 - self.cos_o * self.cos_o);
        let (sin_x, cos_x) = sub_clamped((sin_w, cos_w), (sin_o, self.cos_o));
        let (_, cos_p) = sub_clamped((sin_x, cos_x), (sin_b, cos_b));
        if cos_p <= self.cos_e {
            return 0.0;
        }
        let mut importance = self.phi * cos_p / d2;
        if let Some(n) = n {
            let cos_i = wi.dot(n).abs();
            let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
            importance *= sub_clamped((sin_i, cos_i), (sin_b, cos_b)).1;
        }
        importance.max(0.0)
    }

    /// The build's cost of a side (`EvaluateCost`), against the whole node's box `whole`
    /// along `axis`.
    fn cost(&self, whole: (DVec3, DVec3), axis: usize) -> f64 {
        let theta_o = self.cos_o.clamp(-1.0, 1.0).acos();
        let theta_e = self.cos_e.clamp(-1.0, 1.0).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let sin_o = safe_sqrt(1.0 - self.cos_o * self.cos_o);
        let m_omega = 2.0 * PI * (1.0 - self.cos_o)
            + FRAC_PI_2
                * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                    + self.cos_o);
        let d = whole.1 - whole.0;
        let kr = d.max_element() / d[axis];
        let e = self.max - self.min;
        let area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
        self.phi * m_omega * kr * area
    }
}

/// The smallest cone the book's `DirectionCone::Union` finds around two.
fn cone_union(a: (DVec3, f64), b: (DVec3, f64)) -> (DVec3, f64) {
    let theta_a = a.1.clamp(-1.0, 1.0).acos();
    let theta_b = b.1.clamp(-1.0, 1.0).acos();
    let theta_d = a.0.angle_between(b.0);
    if (theta_d + theta_b).min(PI) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return b;
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= PI {
        return (a.0, -1.0);
    }
    let Some(axis) = a.0.cross(b.0).try_normalize() else {
        return (a.0, -1.0);
    };
    let turn = hitkit::glam::DQuat::from_axis_angle(axis, theta_o - theta_a);
    (turn * a.0, theta_o.cos())
}

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Bounds,
    /// The second child of an inner node, or the light of a leaf.
    index: usize,
    leaf: bool,
}

/// The sampler: a tree whose first child follows its parent.
pub struct PbrtLightBvh {
    nodes: Vec<Node>,
    parents: Vec<usize>,
    leaves: Vec<usize>,
}

impl PbrtLightBvh {
    /// The tree over lights given by their boxes, powers and unit normals.
    pub fn new(boxes: &[(DVec3, DVec3)], powers: &[f64], normals: &[DVec3]) -> Self {
        let mut prims: Vec<(Bounds, usize)> = (0..boxes.len())
            .map(|i| {
                let b = Bounds {
                    min: boxes[i].0,
                    max: boxes[i].1,
                    phi: powers[i],
                    w: normals[i],
                    cos_o: 1.0,
                    cos_e: 0.0,
                };
                (b, i)
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * prims.len());
        if !prims.is_empty() {
            build(&mut prims, &mut nodes);
        }
        let mut parents = vec![usize::MAX; nodes.len()];
        let mut leaves = vec![0; boxes.len()];
        for (n, node) in nodes.iter().enumerate() {
            if node.leaf {
                leaves[node.index] = n;
            } else {
                parents[n + 1] = n;
                parents[node.index] = n;
            }
        }
        Self {
            nodes,
            parents,
            leaves,
        }
    }

    /// The probability of the first child at inner node `n`; `None` where both children's
    /// importance is 0.
    fn left(&self, n: usize, at: &ShadingContext) -> Option<f64> {
        let a = self.nodes[n + 1].bounds.importance(at.point, at.normal);
        let b = self.nodes[self.nodes[n].index]
            .bounds
            .importance(at.point, at.normal);
        (a + b > 0.0).then(|| a / (a + b))
    }

    /// The light `u` picks from `at`, its probability, and what is left of `u`.
    pub fn pick(&self, at: &ShadingContext, mut u: f64) -> Option<(usize, f64, f64)> {
        let mut n = 0;
        let mut p = 1.0;
        self.nodes.first()?;
        while !self.nodes[n].leaf {
            let left = self.left(n, at)?;
            if u < left {
                u = (u / left).min(1.0 - f64::EPSILON / 2.0);
                p *= left;
                n += 1;
            } else {
                u = ((u - left) / (1.0 - left)).min(1.0 - f64::EPSILON / 2.0);
                p *= 1.0 - left;
                n = self.nodes[n].index;
            }
        }
        Some((self.nodes[n].index, p, u))
    }

    /// The probability that [`PbrtLightBvh::pick`] picks light `i` from `at`.
    pub fn probability(&self, at: &ShadingContext, i: usize) -> f64 {
        let mut n = self.leaves[i];
        let mut p = 1.0;
        while self.parents[n] != usize::MAX {
            let parent = self.parents[n];
            let Some(left) = self.left(parent, at) else {
                return 0.0;
            };
            p *= if n == parent + 1 { left } else { 1.0 - left };
            n = parent;
        }
        p
    }
}

/// Buckets per axis, as the book's build.
const BUCKETS: usize = 12;

/// The book's `buildBVH`: a leaf for one light; else the cheapest of the bucket splits on
/// every axis of the centroids' box, or the middle of the range where none splits them.
fn build(prims: &mut [(Bounds, usize)], nodes: &mut Vec<Node>) -> Bounds {
    let n = nodes.len();
    if let [(b, i)] = prims {
        nodes.push(Node {
            bounds: *b,
            index: *i,
            leaf: true,
        });
        return *b;
    }
    nodes.push(Node {
        bounds: prims[0].0,
        index: 0,
        leaf: false,
    });
    let centroid = |b: &Bounds| 0.5 * (b.min + b.max);
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let (mut wlo, mut whi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for (b, _) in prims.iter() {
        lo = lo.min(centroid(b));
        hi = hi.max(centroid(b));
        wlo = wlo.min(b.min);
        whi = whi.max(b.max);
    }
    let bucket = |c: f64, axis: usize| {
        (((c - lo[axis]) / (hi[axis] - lo[axis]) * BUCKETS as f64) as usize).min(BUCKETS - 1)
    };
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        if hi[axis] == lo[axis] {
            continue;
        }
        let mut buckets: [Option<Bounds>; BUCKETS] = [None; BUCKETS];
        for (b, _) in prims.iter() {
            let k = bucket(centroid(b)[axis], axis);
            buckets[k] = Some(buckets[k].map_or(*b, |x| x.union(b)));
        }
        for cut in 0..BUCKETS - 1 {
            let join = |range: &[Option<Bounds>]| {
                range.iter().flatten().fold(None, |acc: Option<Bounds>, b| {
                    Some(acc.map_or(*b, |a| a.union(b)))
                })
            };
            let (Some(below), Some(above)) = (join(&buckets[..=cut]), join(&buckets[cut + 1..]))
            else {
                continue;
            };
            let cost = below.cost((wlo, whi), axis) + above.cost((wlo, whi), axis);
            if best.is_none_or(|(c, ..)| cost < c) {
                best = Some((cost, axis, cut));
            }
        }
    }
    let mut mid = prims.len() / 2;
    if let Some((_, axis, cut)) = best {
        let mut first = 0;
        for i in 0..prims.len() {
            if bucket(centroid(&prims[i].0)[axis], axis) <= cut {
                prims.swap(i, first);
                first += 1;
            }
        }
        if first > 0 && first < prims.len() {
            mid = first;
        }
    }
    let (left, right) = prims.split_at_mut(mid);
    let a = build(left, nodes);
    let second = nodes.len();
    let b = build(right, nodes);
    let bounds = a.union(&b);
    nodes[n] = Node {
        bounds,
        index: second,
        leaf: false,
    };
    bounds
}
