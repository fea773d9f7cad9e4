//! Binned SAH build (Wald 2007, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies"; pbrt-v4 `BVHAggregate::buildRecursive`).

use alloc::vec::Vec;

use glam::DVec3;

use super::{Bvh, MAX_DEPTH, Node, Pair};
use crate::{Aabb, Hittable};

/// Centroid bins per axis.
const BINS: usize = 16;
/// A node with more objects than this is always split.
const MAX_LEAF: usize = 8;
/// Cost of visiting a node, relative to testing one object.
const TRAVERSAL_COST: f64 = 1.0;
/// From this depth on, splits are by count (median), which halves the objects: with at most
/// 2^32 of them, 32 more levels reach single objects, within MAX_DEPTH.
const MEDIAN_FROM_DEPTH: usize = MAX_DEPTH - 33;

/// What the build knows of one bounded object.
#[derive(Clone, Copy)]
struct Prim {
    min: DVec3,
    max: DVec3,
    centroid: DVec3,
    index: u32,
}

pub(super) fn build<T: Hittable>(objects: Vec<T>) -> Bvh<T> {
    assert!(
        u32::try_from(objects.len()).is_ok(),
        "a Bvh holds at most u32::MAX objects"
    );
    let mut bbox = Aabb::EMPTY;
    let mut prims = Vec::with_capacity(objects.len());
    let mut unbounded = Vec::new();
    for (index, object) in (0u32..).zip(&objects) {
        let b = object.bounding_box();
        bbox = bbox.union(&b);
        if b.is_bounded() {
            let centroid = 0.5 * b.min() + 0.5 * b.max();
            prims.push(Prim {
                min: b.min(),
                max: b.max(),
                centroid,
                index,
            });
        } else {
            // Infinite (or empty) boxes stay out of the SAH arithmetic.
            unbounded.push(index);
        }
    }

    let mut pairs = Vec::with_capacity(prims.len() / 2);
    let root = if prims.is_empty() {
        Node::default()
    } else {
        node(&mut prims, 0, 0, &mut pairs)
    };

    let order: Vec<u32> = prims.iter().map(|p| p.index).chain(unbounded).collect();
    let mut slots: Vec<Option<T>> = objects.into_iter().map(Some).collect();
    let objects = order
        .iter()
        .filter_map(|&i| slots[i as usize].take())
        .collect();
    Bvh {
        objects,
        order,
        bounded: prims.len(),
        root,
        pairs,
        bbox,
    }
}

/// Builds the subtree over `prims` (at position `offset` of the final order), returning its
/// root node; inner nodes' children go to `pairs`, parents before children.
fn node(prims: &mut [Prim], offset: usize, depth: usize, pairs: &mut Vec<Pair>) -> Node {
    let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let (mut cmin, mut cmax) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for p in prims.iter() {
        (min, max) = (min.min(p.min), max.max(p.max));
        (cmin, cmax) = (cmin.min(p.centroid), cmax.max(p.centroid));
    }
    let n = prims.len();
    let leaf = Node {
        min: round_down(min),
        max: round_up(max),
        index: offset as u32,
        count: n as u32,
    };
    if n == 1 {
        return leaf;
    }

    let split = if depth < MEDIAN_FROM_DEPTH {
        sah_split(prims, min, max, cmin, cmax)
    } else {
        None
    };
    let mid = match split {
        Some((cost, _, _)) if cost >= n as f64 && n <= MAX_LEAF => return leaf,
        Some((_, axis, bin)) => partition(prims, |p| {
            bin_of(p.centroid[axis], cmin[axis], cmax[axis]) <= bin
        }),
        None if n <= MAX_LEAF => return leaf,
        None => n / 2,
    };
    // A split that leaves one side empty (or a median) becomes a median by centroid along
    // the widest centroid axis: it always halves, so depth stays bounded.
    let mid = if mid == 0 || mid == n {
        let axis = (cmax - cmin).max_position();
        prims.select_nth_unstable_by(n / 2, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
        n / 2
    } else {
        mid
    };

    let pair = pairs.len();
    pairs.push(Pair::default());
    let (left, right) = prims.split_at_mut(mid);
    let a = node(left, offset, depth + 1, pairs);
    let b = node(right, offset + mid, depth + 1, pairs);
    pairs[pair] = Pair([a, b]);
    Node {
        index: pair as u32,
        count: 0,
        ..leaf
    }
}

/// The bin of a centroid coordinate within `[lo, hi]` (`hi > lo`).
#[inline]
fn bin_of(c: f64, lo: f64, hi: f64) -> usize {
    // The float-to-int cast saturates, and NaN becomes 0: always a valid bin.
    (((c - lo) / (hi - lo) * BINS as f64) as usize).min(BINS - 1)
}

/// The cheapest split by the surface area heuristic: `(cost, axis, last bin on the left)`,
/// cost in units of one object test; `None` when all centroids coincide.
fn sah_split(
    prims: &[Prim],
    min: DVec3,
    max: DVec3,
    cmin: DVec3,
    cmax: DVec3,
) -> Option<(f64, usize, usize)> {
    let parent_area = half_area(min, max);
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        let (lo, hi) = (cmin[axis], cmax[axis]);
        if hi <= lo {
            continue;
        }
        let mut count = [0usize; BINS];
        let mut bounds = [(DVec3::INFINITY, DVec3::NEG_INFINITY); BINS];
        for p in prims {
            let b = bin_of(p.centroid[axis], lo, hi);
            count[b] += 1;
            bounds[b] = (bounds[b].0.min(p.min), bounds[b].1.max(p.max));
        }
        // Sweep from the right for the area * count of every suffix, then from the left.
        let mut right_cost = [0.0; BINS];
        let (mut acc, mut k) = ((DVec3::INFINITY, DVec3::NEG_INFINITY), 0);
        for b in (1..BINS).rev() {
            acc = (acc.0.min(bounds[b].0), acc.1.max(bounds[b].1));
            k += count[b];
            right_cost[b] = if k == 0 {
                0.0
            } else {
                half_area(acc.0, acc.1) * k as f64
            };
        }
        let (mut acc, mut k) = ((DVec3::INFINITY, DVec3::NEG_INFINITY), 0);
        for b in 0..BINS - 1 {
            acc = (acc.0.min(bounds[b].0), acc.1.max(bounds[b].1));
            k += count[b];
            if k == 0 || k == prims.len() {
                continue;
            }
            let cost = TRAVERSAL_COST
                + (half_area(acc.0, acc.1) * k as f64 + right_cost[b + 1]) / parent_area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    best
}

/// Half the surface area of a box (only ratios of areas matter).
#[inline]
fn half_area(min: DVec3, max: DVec3) -> f64 {
    let d = (max - min).max(DVec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// Moves the prims satisfying `left` to the front; returns how many.
fn partition(prims: &mut [Prim], left: impl Fn(&Prim) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..prims.len() {
        if left(&prims[i]) {
            prims.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

/// The largest `f32` at or below each coordinate: a box stored in `f32` still contains its
/// `f64` original.
fn round_down(v: DVec3) -> [f32; 3] {
    v.to_array().map(|x| {
        let f = x as f32;
        if f64::from(f) > x { f.next_down() } else { f }
    })
}

/// The smallest `f32` at or above each coordinate.
fn round_up(v: DVec3) -> [f32; 3] {
    v.to_array().map(|x| {
        let f = x as f32;
        if f64::from(f) < x { f.next_up() } else { f }
    })
}
