//! [`Aabb`]: the padded axis-aligned box, and the slab test a shape and a [`Bvh`](crate::Bvh)
//! share, which keeps rays lying in a slab plane and never loses a hit to rounding.

use glam::DVec3;

use crate::math::{direction_scale, gamma, ordinary, scaled_outward};
use crate::{Interval, Ray};

/// Below this fraction of its longest side, a side of a box is padded: flat shapes get
/// boxes of positive volume, and a micrometre object grows by a micrometre times 2^-20
/// rather than by the book's fixed 0.0001.
const MIN_WIDTH_REL_EXTENT: f64 = 1.0 / (1u64 << 20) as f64;
/// Nor is a side thinner than this fraction of the largest coordinate: 2^-50 |x| is at least
/// four ulps of |x|, so the padding survives rounding at 1e12 and beyond, where a fixed
/// 0.0001 (less than one ulp past about 5e11) rounds away.
const MIN_WIDTH_REL_MAGNITUDE: f64 = 1.0 / (1u64 << 50) as f64;
/// The far slab distance is enlarged by this fraction of itself: each slab distance
/// `(bound - o) * (1 / d)` carries three roundings, so `gamma(3)` bounds its relative error,
/// and twice that covers the near and the far one together (pbrt-v4 `Bounds3::IntersectP`,
/// after Ize 2013, "Robust BVH Ray Traversal").
const FAR_PAD: f64 = 2.0 * gamma(3);

/// An axis-aligned bounding box, padded so that no side is thinner than a width relative to
/// the box's size and position (flat shapes still get a box with volume).
///
/// ```
/// use hitkit::{glam::DVec3, Aabb, Interval, Ray};
/// // Corners in any order; the flat z side is padded to a sliver.
/// let b = Aabb::new(DVec3::new(1.0, 1.0, 0.0), DVec3::new(-1.0, -1.0, 0.0));
/// assert!(b.min().z < 0.0 && b.max().z > 0.0 && b.max().z < 1e-5);
/// let ray = Ray::new(DVec3::new(0.0, 0.0, 5.0), DVec3::new(0.0, 0.0, -1.0));
/// assert!(b.hit(&ray, Interval::FORWARD));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub(crate) min: DVec3,
    pub(crate) max: DVec3,
}

impl Aabb {
    /// Contains nothing; the identity of [`Aabb::union`].
    pub const EMPTY: Self = Self {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };
    /// Contains everything; the box of an unbounded shape.
    pub const UNIVERSE: Self = Self {
        min: DVec3::NEG_INFINITY,
        max: DVec3::INFINITY,
    };

    /// The box with corners `a` and `b` (in any order), padded to minimum widths.
    ///
    /// Infinite coordinates give an unbounded box; a NaN coordinate makes that axis
    /// unbounded (a box must never lose what it should contain).
    #[must_use]
    pub fn new(a: DVec3, b: DVec3) -> Self {
        let nan = a.is_nan_mask() | b.is_nan_mask();
        let mut min = DVec3::select(nan, DVec3::NEG_INFINITY, a.min(b));
        let mut max = DVec3::select(nan, DVec3::INFINITY, a.max(b));

        let size = max - min;
        let finite = |v: DVec3| DVec3::select(v.is_finite_mask(), v, DVec3::ZERO);
        let longest = finite(size).max_element();
        let magnitude = finite(min).abs().max(finite(max).abs()).max_element();
        let min_width = (longest * MIN_WIDTH_REL_EXTENT).max(magnitude * MIN_WIDTH_REL_MAGNITUDE);
        for axis in 0..3 {
            if size[axis] < min_width {
                let grow = 0.5 * (min_width - size[axis]);
                min[axis] -= grow;
                max[axis] += grow;
            }
        }
        Self { min, max }
    }

    /// The smallest box (padded) containing every point; [`Aabb::EMPTY`] for none. As for
    /// [`Aabb::new`], a NaN coordinate makes its axis unbounded.
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Aabb};
    /// let b = Aabb::from_points(&[DVec3::Z, DVec3::new(0.0, 0.0, f64::NAN), DVec3::ZERO]);
    /// assert!(b.contains(DVec3::Z) && b.max().z == f64::INFINITY);
    /// ```
    #[must_use]
    pub fn from_points(points: &[DVec3]) -> Self {
        match points.split_first() {
            None => Self::EMPTY,
            Some((first, rest)) => {
                let (lo, hi, nan) = rest
                    .iter()
                    .fold((*first, *first, first.is_nan_mask()), |(lo, hi, nan), p| {
                        (lo.min(*p), hi.max(*p), nan | p.is_nan_mask())
                    });
                Self::new(
                    DVec3::select(nan, DVec3::NAN, lo),
                    DVec3::select(nan, DVec3::NAN, hi),
                )
            }
        }
    }

    /// The box grown by `margin` (non-negative) on every side: how shapes make room for
    /// the rounding of the corners they compute.
    #[inline]
    #[must_use]
    pub(crate) fn grown(&self, margin: DVec3) -> Self {
        Self {
            min: self.min - margin,
            max: self.max + margin,
        }
    }

    /// The corner with the smallest coordinates.
    #[inline]
    #[must_use]
    pub fn min(&self) -> DVec3 {
        self.min
    }

    /// The corner with the largest coordinates.
    #[inline]
    #[must_use]
    pub fn max(&self) -> DVec3 {
        self.max
    }

    /// The smallest box containing both. See also [`Aabb::EMPTY`].
    #[inline]
    #[must_use]
    pub fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Whether it contains no point.
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// Whether it is non-empty and all its coordinates are finite.
    #[inline]
    #[must_use]
    pub fn is_bounded(&self) -> bool {
        !self.is_empty() && self.min.is_finite() && self.max.is_finite()
    }

    /// Whether `p` lies in the closed box.
    #[inline]
    #[must_use]
    pub fn contains(&self, p: DVec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }

    /// Whether the ray meets the closed box at some `t` in `ray_t`.
    ///
    /// Conservative by design: a ray lying in a slab plane (a zero or `-0.0` direction
    /// component with the origin on a face) and a zero-thickness box are hits, and the far
    /// distance is padded for rounding, so no box is rejected whose contents a shape's own
    /// test would accept. An invalid ray (see [`Ray::is_valid`]) hits nothing.
    #[inline]
    #[must_use]
    pub fn hit(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.ray_span(ray, ray_t).is_some()
    }

    /// The part of `ray_t` during which the ray can be in the box, by the same conservative
    /// test as [`Aabb::hit`]; `None` where that test misses.
    ///
    /// Shapes report every hit at a `t` inside their own box's span (moving a `t` that
    /// rounding put outside onto its end): so a [`Bvh`](crate::Bvh), which tests boxes
    /// that contain the shapes' boxes, reaches every hit that a loop over the shapes finds.
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Aabb, Interval, Ray};
    /// let cube = Aabb::new(DVec3::ZERO, DVec3::ONE);
    /// let ray = Ray::new(DVec3::new(0.5, 0.5, -1.0), DVec3::Z);
    /// let span = cube.ray_span(&ray, Interval::FORWARD).unwrap();
    /// assert!(span.min <= 1.0 && span.min > 0.99 && span.max >= 2.0 && span.max < 2.01);
    /// ```
    #[inline]
    #[must_use]
    pub fn ray_span(&self, ray: &Ray, ray_t: Interval) -> Option<Interval> {
        // (One test of `|d|_1` says both that the ray is valid and that it needs no scaling.
        // Tried: a check of each on every call; slower on the Cornell box.)
        if !(ray.origin.is_finite() && ordinary(ray.direction)) {
            return self.ray_span_rescaled(ray, ray_t);
        }
        let ([t0], [t1]) = slab_spans(
            lanes(self.min),
            lanes(self.max),
            &BoxRay::with_scale(ray, 1.0),
            ray_t,
        );
        (t0 < f64::INFINITY).then_some(Interval::new(t0, t1))
    }

    /// [`Aabb::ray_span`] for a ray whose direction's length is extreme, along the
    /// direction scaled to an ordinary length (see [`BoxRay`]); `None` for an invalid ray.
    #[cold]
    #[inline(never)]
    fn ray_span_rescaled(&self, ray: &Ray, ray_t: Interval) -> Option<Interval> {
        if !ray.is_valid() {
            return None;
        }
        let box_ray = BoxRay::new(ray);
        let scaled = box_ray.scaled_range(ray_t);
        let ([t0], [t1]) = slab_spans(lanes(self.min), lanes(self.max), &box_ray, scaled);
        (t0 < f64::INFINITY).then(|| box_ray.unscaled_span(Interval::new(t0, t1)))
    }

    /// Whether a coordinate of the box reaches a sixteenth of f64's largest (about
    /// `2^1020`), or is unbounded: past it, a point of the box and a few ulps of error on
    /// it could overflow, so shapes there make sure a hit's record can be made before
    /// `occluded` counts it.
    #[inline]
    pub(crate) fn near_overflow(&self) -> bool {
        let largest = self.min.abs().max(self.max.abs()).max_element();
        largest.is_nan() || largest >= f64::MAX / 16.0
    }

    /// `t` moved into the box's [span](Aabb::ray_span) along the whole ray, or `None` when
    /// the ray misses the box: how shapes keep their hits consistent with their boxes.
    #[inline(always)]
    pub(crate) fn clamp_hit(&self, ray: &Ray, t: f64) -> Option<f64> {
        if self.clearly_holds(ray, t) {
            return Some(t);
        }
        self.clamp_by_span(ray, t)
    }

    /// Whether `t` is within the box's span for certain, without the slab test (three
    /// divisions), as it is for most hits: where `t d` lies between `min - o` and `max - o`
    /// by more than `gamma(6)` of `|t d| + |bound - o|` per axis, `t` is within every
    /// slab's computed span. (Each distance `(bound - o) (1 / d)` is within `gamma(3)` of
    /// its own; the test's three roundings, and the span's floor for underflow, fit in the
    /// rest.) Distances from the origin, not the point's coordinates: a flat box (an
    /// axis-aligned quad's) is thinner than the rounding of a coordinate far from the
    /// origin, not than that of its distance.
    #[inline(always)]
    fn clearly_holds(&self, ray: &Ray, t: f64) -> bool {
        let step = t * ray.direction;
        let (lo, hi) = (self.min - ray.origin, self.max - ray.origin);
        let margin = gamma(6) * (step.abs() + lo.abs().max(hi.abs())) + f64::MIN_POSITIVE;
        // (A NaN `t` fails the comparisons.)
        (lo + margin).cmple(step).all() && step.cmple(hi - margin).all()
    }

    /// [`Aabb::clamp_hit`], for a caller that tests many boxes on one ray: where the fast
    /// path leaves `t` in doubt (always, on an axis along which the box is flat, as an
    /// axis-aligned face's is), the slab test runs on `box_ray`, made once for the ray
    /// (`BoxRay::new`, which the caller keeps in `box_ray` from its first use), rather than
    /// on a new one: the same arithmetic as [`Aabb::ray_span`], without its three divisions.
    #[inline(always)]
    pub(crate) fn clamp_hit_on(
        &self,
        ray: &Ray,
        box_ray: &mut Option<BoxRay>,
        t: f64,
    ) -> Option<f64> {
        if self.clearly_holds(ray, t) {
            return Some(t);
        }
        // `ray_span` takes this ray's own direction (scale 1) for a finite origin and an
        // ordinary direction, and otherwise its own path.
        if !(ray.origin.is_finite() && ordinary(ray.direction)) {
            return self.clamp_by_span(ray, t);
        }
        let box_ray = box_ray.get_or_insert_with(|| BoxRay::with_scale(ray, 1.0));
        let ([t0], [t1]) = slab_spans(
            lanes(self.min),
            lanes(self.max),
            box_ray,
            Interval::UNIVERSE,
        );
        (t0 < f64::INFINITY).then(|| t.clamp(t0, t1.max(t0)))
    }

    /// [`Aabb::clamp_hit`] by the slab test.
    #[cold]
    #[inline(never)]
    fn clamp_by_span(&self, ray: &Ray, t: f64) -> Option<f64> {
        let span = self.ray_span(ray, Interval::UNIVERSE)?;
        Some(t.clamp(span.min, span.max.max(span.min)))
    }
}

/// The slab test (pbrt-v4 `Bounds3::IntersectP`) of `N` boxes at once, given per axis as
/// `min[axis][box]`, `max[axis][box]`, against a ray whose reciprocal direction and signs
/// were computed once: for each box, the distances at which the ray enters it within
/// `ray_t` (clamped to `ray_t.min`; `+inf` if it does not) and leaves it (the far distance
/// padded for rounding, clamped to `ray_t.max`). The one box test of the crate: `Aabb::hit`
/// runs it on one box, the BVH on two siblings (the lanes vectorize).
///
/// `0 * inf` (origin in a slab plane, direction 0) gives NaN, and the comparisons are written
/// so that a NaN distance constrains nothing: the ray lies in the face, which belongs to the
/// closed box. Testing the near bound by the direction's sign (not by `min`/`max` of the two
/// distances) makes an empty box (`min > max`) a miss.
#[inline(always)]
pub(crate) fn slab_spans<const N: usize>(
    min: [[f64; N]; 3],
    max: [[f64; N]; 3],
    ray: &BoxRay,
    ray_t: Interval,
) -> ([f64; N], [f64; N]) {
    // A box met only "at infinity" (a ray parallel to a slab and outside it gives an
    // infinite near distance) is not hit: clamping the range to finite numbers makes such
    // a box fail `t0 <= t1` (NaN ends stay NaN, and hit nothing).
    let lo = if ray_t.min < -f64::MAX {
        -f64::MAX
    } else {
        ray_t.min
    };
    let hi = if ray_t.max > f64::MAX {
        f64::MAX
    } else {
        ray_t.max
    };
    let (mut t0, mut t1) = ([lo; N], [hi; N]);
    for axis in 0..3 {
        let (near, far) = if ray.negative[axis] {
            (max[axis], min[axis])
        } else {
            (min[axis], max[axis])
        };
        let (origin, inv) = (ray.origin[axis], ray.inv_direction[axis]);
        for k in 0..N {
            let t_near = (near[k] - origin) * inv;
            let t_far = (far[k] - origin) * inv;
            // Enlarge outward (a multiple, not `+ |t_far| * pad`, which is NaN at infinity).
            let t_far = t_far
                * if t_far > 0.0 {
                    1.0 + FAR_PAD
                } else {
                    1.0 - FAR_PAD
                };
            if t_near > t0[k] {
                t0[k] = t_near;
            }
            if t_far < t1[k] {
                t1[k] = t_far;
            }
        }
    }
    let entries = core::array::from_fn(|k| if t0[k] <= t1[k] { t0[k] } else { f64::INFINITY });
    (entries, t1)
}

/// A box's corner as the one-box lanes of [`slab_spans`].
#[inline(always)]
fn lanes(v: DVec3) -> [[f64; 1]; 3] {
    [[v.x], [v.y], [v.z]]
}

impl Default for Aabb {
    /// [`Aabb::EMPTY`].
    fn default() -> Self {
        Self::EMPTY
    }
}

/// A ray prepared for many box tests: its reciprocal direction and the direction's signs.
///
/// The direction is first scaled by a power of two ([`direction_scale`]), exactly, so that
/// its reciprocal neither overflows (a direction of `1e-310`) nor underflows: the slab
/// test's distances are along the scaled direction, and [`BoxRay::scaled_range`] and
/// [`BoxRay::unscaled_span`] convert to and from the ray's own `t`. For every ordinary ray
/// the scale is 1 and both are the identity.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxRay {
    origin: DVec3,
    /// The reciprocal of the scaled direction.
    pub(crate) inv_direction: DVec3,
    /// Sign bits, so that `-0.0` counts as negative: its reciprocal is `-inf`.
    pub(crate) negative: [bool; 3],
    /// The direction's scale: a distance `t'` of the slab test is `t' * scale` along the
    /// ray's own direction.
    scale: f64,
}

impl BoxRay {
    #[inline]
    pub(crate) fn new(ray: &Ray) -> Self {
        Self::with_scale(ray, direction_scale(ray.direction))
    }

    /// The ray with its direction scaled by the power of two `scale` (exactly).
    #[inline(always)]
    fn with_scale(ray: &Ray, scale: f64) -> Self {
        let inv_direction = (ray.direction * scale).recip();
        let negative = [
            inv_direction.x.is_sign_negative(),
            inv_direction.y.is_sign_negative(),
            inv_direction.z.is_sign_negative(),
        ];
        Self {
            origin: ray.origin,
            inv_direction,
            negative,
            scale,
        }
    }

    /// `ray_t` in the slab test's units, rounded outward where the conversion rounds.
    #[inline]
    pub(crate) fn scaled_range(&self, ray_t: Interval) -> Interval {
        ray_t.scaled(1.0 / self.scale)
    }

    /// The upper end of a range of the ray's `t` in the slab test's units, rounded up.
    #[inline]
    pub(crate) fn scaled_max(&self, t: f64) -> f64 {
        if self.scale == 1.0 {
            t
        } else {
            scaled_outward(t, 1.0 / self.scale, false)
        }
    }

    /// A span of the slab test's distances as the ray's `t`, rounded outward.
    #[inline]
    pub(crate) fn unscaled_span(&self, span: Interval) -> Interval {
        span.scaled(self.scale)
    }
}
