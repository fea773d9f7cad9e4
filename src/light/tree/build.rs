//! Building a [`LightTree`]: lights split by the surface area and orientation heuristic
//! (Conty Estevez and Kulla 2018), depth first.

use alloc::vec::Vec;
use core::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use super::cluster::Cluster;
use super::{MAX_DEPTH, Node};
use crate::Aabb;

/// Buckets per axis of the build's split search.
pub(super) const BUCKETS: usize = 12;

/// A light as the build sorts it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Prim {
    pub(super) cluster: Cluster,
    pub(super) centroid: DVec3,
    pub(super) light: u32,
}

/// Builds the subtree over `prims` into `nodes`, depth first, and returns its cluster: a
/// leaf for one light; otherwise split where the cost of the two halves is least, each
/// half's cost being its power times the solid angle its cone of emission can reach times
/// its box's surface area, times the box's aspect along the split axis (the surface area
/// orientation heuristic of Conty Estevez and Kulla 2018), over [`BUCKETS`] buckets of
/// centroids per axis; by count where no bucket boundary splits them, and from half
/// [`MAX_DEPTH`] on.
pub(super) fn build(prims: &mut [Prim], nodes: &mut Vec<Node>, depth: usize) -> Cluster {
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
pub(super) fn split(prims: &mut [Prim]) -> Option<usize> {
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
pub(super) fn centroid_bounds(prims: &[Prim]) -> (DVec3, DVec3) {
    prims
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.centroid), hi.max(p.centroid))
        })
}

/// The bucket of a centroid at `c` along an axis whose centroids span `width` from `lo`:
/// always below [`BUCKETS`], the arrays' size (the cast saturates, NaN to 0).
#[inline]
pub(super) fn bucket(c: f64, lo: f64, width: f64) -> usize {
    (((c - lo) / width * BUCKETS as f64) as usize).min(BUCKETS - 1)
}

impl Cluster {
    /// The cost of the heuristic of [`build`] for one side of a split.
    pub(super) fn cost(&self) -> f64 {
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
    pub(super) fn orientation_measure(&self) -> f64 {
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
