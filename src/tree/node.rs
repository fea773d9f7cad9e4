//! A node of the tree as it is stored: eight children's `f32` boxes relative to the tree's
//! origin, rounded outward, and how a box becomes such offsets (and what that rounding
//! costs the traversal's bounds).

use glam::{DVec3, Vec4};

use super::WIDTH;
use crate::Aabb;
use crate::math::Dd;

/// A node: the boxes of up to eight children, tested together in SIMD lanes (one AVX2
/// instruction a step, or two SSE ones), in four 64-byte cache lines. The boxes are `f32`,
/// relative to the tree's `origin` (rounded outward, so they still hold everything they
/// must, and as precise at 1e9 from the world's origin as at it), bound by bound
/// (`bounds[axis]` the lower bounds along `axis`, `bounds[3 + axis]` the upper), so that a
/// ray picks its near and far bound per axis once. For each child either a node
/// (`count == 0`, `index` the node) or a leaf (`count` objects from `index`); an unused
/// lane holds an empty box, which no ray enters. The root is node 0. (Tried: each bound
/// as 8 bits from a corner of the node, a node in two cache lines: slower on shadow rays,
/// most in rooms, whose flat walls it thickens; `docs/performance.md`.)
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node {
    pub(super) bounds: [[f32; WIDTH]; 6],
    pub(super) index: [u32; WIDTH],
    pub(super) count: [u32; WIDTH],
}

/// A lane's box as a node holds it: lower and upper offsets from the tree's origin.
pub(super) type Bounds = ([f32; 3], [f32; 3]);

impl Node {
    /// Lane `k`'s box.
    #[inline]
    pub(super) fn lane(&self, k: usize) -> Bounds {
        (
            [0, 1, 2].map(|a| self.bounds[a][k]),
            [0, 1, 2].map(|a| self.bounds[3 + a][k]),
        )
    }
}

/// Half the surface area of a box (0 if it is empty), in `f64`.
pub(super) fn half_area((min, max): &Bounds) -> f64 {
    surface(
        DVec3::from_array([0, 1, 2].map(|a| f64::from(max[a]) - f64::from(min[a])))
            .max(DVec3::ZERO),
    )
}

/// Half the surface area of a box of sides `d`: the surface area heuristic's weight (only
/// ratios of areas matter).
#[inline]
fn surface(d: DVec3) -> f64 {
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// A box in `f32`, as SIMD lanes `x, y, z, w` (`w` unused by the box).
#[derive(Clone, Copy)]
pub(super) struct Box3 {
    pub(super) min: Vec4,
    pub(super) max: Vec4,
}

impl Box3 {
    pub(super) const EMPTY: Self = Self {
        min: Vec4::INFINITY,
        max: Vec4::NEG_INFINITY,
    };

    #[inline]
    pub(super) fn grow(&mut self, min: Vec4, max: Vec4) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    /// Half the surface area (only ratios of areas matter); 0 for an empty box.
    #[inline]
    pub(super) fn half_area(&self) -> f64 {
        let d = (self.max - self.min).max(Vec4::ZERO);
        surface(DVec3::new(f64::from(d.x), f64::from(d.y), f64::from(d.z)))
    }
}

/// What the traversal's `f32` lanes need to know of all the bounds a tree holds about its
/// origin, per axis: how far `origin + bound` rounds in `f64` (where the `f64` test puts
/// them), the largest `|bound|`, and whether every bound lies within `2^60` of the origin
/// (see `traverse::Lanes`). Grown by [`Reach::cover`] as bounds are written; never shrunk
/// (a reach larger than the bounds' is still a bound on them).
#[derive(Clone, Copy, Debug)]
pub(super) struct Reach {
    pub(super) rounding: [f64; 3],
    pub(super) extent: [f64; 3],
    pub(super) compact: bool,
}

impl Reach {
    /// Of no bound.
    pub(super) const NONE: Self = Self {
        rounding: [0.0; 3],
        extent: [0.0; 3],
        compact: true,
    };

    /// Grown to cover the finite bounds of a box about `origin`. How far `origin + bound`
    /// rounds is found bound by bound (exactly, by two-sum): mostly not at all, since
    /// [`below`] and [`above`] pick offsets whose sum lands on the box's own coordinates;
    /// but an ulp of the origin where it cannot (about 1e-4 at 1e12), which a bound from
    /// the magnitudes alone would charge every node.
    pub(super) fn cover(&mut self, origin: DVec3, (min, max): &Bounds) {
        for a in 0..3 {
            for f in [min[a], max[a]].into_iter().filter(|f| f.is_finite()) {
                let f = f64::from(f);
                self.compact &= f.abs() <= (1u64 << 60) as f64;
                self.extent[a] = self.extent[a].max(f.abs());
                let error = Dd::diff(origin[a], -f).lo.abs();
                self.rounding[a] = self.rounding[a].max(error);
            }
        }
    }
}

/// `b` as offsets from `origin`, rounded outward by [`below`] and [`above`]; `None` where
/// `b` is not bounded or an offset is past `f32`'s range.
pub(super) fn offsets(b: &Aabb, origin: DVec3) -> Option<Bounds> {
    if !b.is_bounded() {
        return None;
    }
    let min = [0, 1, 2].map(|a| below(b.min()[a], origin[a]));
    let max = [0, 1, 2].map(|a| above(b.max()[a], origin[a]));
    min.iter()
        .chain(&max)
        .all(|f| f.is_finite())
        .then_some((min, max))
}

/// An `f32` offset `f` from `origin` whose world coordinate, as traversal computes it
/// (`origin + f` in `f64`, see `traverse::entries`), is at or below `x`: a node box stored
/// this way still contains the `f64` box it was built from, exactly. Infinite when the
/// offset is past `f32`'s range (the object then stays out of the tree).
///
/// The `f32` at or below `x - origin` (as `f64` rounds it) where its sum with `origin`
/// lands at or below `x`, as it mostly does (often on `x` itself); else its neighbour
/// below, which always does: the rounded difference is within half an `f64` ulp of the
/// exact one, and an `f32` step is wider than that at any magnitude, so the exact sum is
/// below `x`, and rounding it to `f64` cannot pass `x`. Branch-free (which of the two it
/// is, is a coin toss where the origin's bits are not round). Never a subnormal: one is
/// taken down to zero or to the largest negative normal, so that no node holds a bound
/// that traversal would compute with slowly, or read as zero (moved the wrong way) with
/// the CPU's denormals-are-zero mode on.
#[inline]
pub(super) fn below(x: f64, origin: f64) -> f32 {
    let f = round_down(x - origin);
    let f = if origin + f64::from(f) <= x {
        f
    } else {
        step_down(f)
    };
    if f.is_subnormal() {
        if f > 0.0 { 0.0 } else { -f32::MIN_POSITIVE }
    } else {
        f
    }
}

/// As [`below`], at or above `x`.
pub(super) fn above(x: f64, origin: f64) -> f32 {
    -below(-x, -origin)
}

/// The largest `f32` at or below `x` (NaN for NaN), without a branch: rounded to nearest,
/// then, where that went up, its [`step_down`].
#[inline]
pub(super) fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { step_down(f) } else { f }
}

/// The next `f32` toward `-inf` of a non-NaN `f` that is not `-inf`: one step of its bits
/// (toward zero for a positive, away from it for a negative, `-0.0` to the smallest
/// negative subnormal, `+inf` to `f32::MAX`).
#[inline]
pub(super) fn step_down(f: f32) -> f32 {
    let bits = f.to_bits() as i32;
    f32::from_bits(bits.wrapping_sub(2 * (bits >> 31) + 1) as u32)
}

/// The box of no lane.
pub(super) const EMPTY: Bounds = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// The smallest box holding `a` and `b`.
pub(super) fn union(a: &Bounds, b: &Bounds) -> Bounds {
    (
        [0, 1, 2].map(|i| a.0[i].min(b.0[i])),
        [0, 1, 2].map(|i| a.1[i].max(b.1[i])),
    )
}

/// A node of unused lanes.
pub(super) fn empty_node() -> Node {
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
pub(super) fn clear(node: &mut Node, k: usize) {
    node.index[k] = 0;
    node.count[k] = 0;
    for a in 0..3 {
        node.bounds[a][k] = f32::INFINITY;
        node.bounds[3 + a][k] = f32::NEG_INFINITY;
    }
}

/// Whether lane `k` holds a leaf or a node (the root, node 0, is no one's child).
pub(super) fn in_use(node: &Node, k: usize) -> bool {
    node.count[k] > 0 || node.index[k] != 0
}

pub(super) fn set_bounds(node: &mut Node, k: usize, (min, max): Bounds) {
    for a in 0..3 {
        node.bounds[a][k] = min[a];
        node.bounds[3 + a][k] = max[a];
    }
}

/// Grows lane `k`'s box to hold `bounds`.
pub(super) fn grow(node: &mut Node, k: usize, bounds: Bounds) {
    set_bounds(node, k, union(&node.lane(k), &bounds));
}

#[cfg(test)]
mod tests {
    use super::{round_down, step_down};
    use proptest::prelude::*;

    /// The reference: the largest `f32` at or below `x`, by `next_down`.
    fn reference(x: f64) -> f32 {
        let f = x as f32;
        if f64::from(f) > x { f.next_down() } else { f }
    }

    #[test]
    fn round_down_at_the_edges() {
        let tiny = f64::from(f32::from_bits(1));
        for x in [
            0.0,
            -0.0,
            tiny,
            -tiny,
            0.5 * tiny,
            -0.5 * tiny,
            1e-300,
            -1e-300,
            1.0,
            -1.0,
            f64::from(f32::MAX),
            -f64::from(f32::MAX),
            3.5e38,
            -3.5e38,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            assert_eq!(round_down(x).to_bits(), reference(x).to_bits(), "{x:e}");
        }
        assert!(round_down(f64::NAN).is_nan());
    }

    proptest! {
        /// `below` and `above` hold `x` as traversal computes the bound (`origin + f` in
        /// `f64`), for coordinates and origins of every magnitude, and are tight: at most
        /// two `f32` steps from the difference rounded outward.
        #[test]
        fn offsets_hold_the_coordinate_and_are_tight(
            x in prop_oneof![any::<f64>(), -1e13f64..1e13, -1.0f64..1.0, -1e-37f64..1e-37],
            near in prop_oneof![Just(0.0), -1e-3f64..1e-3, -1e6f64..1e6, -1e-38f64..1e-38],
        ) {
            prop_assume!(x.is_finite());
            let origin = x + near;
            prop_assume!(origin.is_finite());
            let (lo, hi) = (super::below(x, origin), super::above(x, origin));
            prop_assert!(!lo.is_subnormal() && !hi.is_subnormal());
            if lo.is_finite() {
                prop_assert!(origin + f64::from(lo) <= x);
                // (Or a subnormal taken down to zero or to the largest negative normal.)
                prop_assert!(
                    lo >= step_down(step_down(round_down(x - origin)))
                        || lo == 0.0
                        || lo == -f32::MIN_POSITIVE
                );
            }
            if hi.is_finite() {
                prop_assert!(origin + f64::from(hi) >= x);
                prop_assert!(
                    -hi >= step_down(step_down(round_down(origin - x)))
                        || hi == 0.0
                        || hi == f32::MIN_POSITIVE
                );
            }
        }

        #[test]
        fn round_down_is_the_largest_f32_at_or_below(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(!x.is_nan());
            prop_assert_eq!(round_down(x).to_bits(), reference(x).to_bits());
        }
    }
}
