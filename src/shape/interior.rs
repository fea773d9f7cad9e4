//! Interior predicates: which points `q + alpha u + beta v` of a plane belong to a shape.

use glam::{DVec2, DVec3};

use crate::math::{gamma, sqrt};
use crate::shape::CrossingRegion;
use crate::{Aabb, GeometryError, Hittable, Plane};

/// The region of a plane that a [`Quad`](crate::Quad) covers, in `(alpha, beta)` space.
///
/// Implemented by [`Parallelogram`], [`Triangle`], [`Disk`], [`Ring`], and by any closure
/// `Fn(f64, f64) -> bool` (write the parameter types, `|a: f64, b: f64|`: they cannot be
/// inferred through the blanket implementation). A closure's extent is unknown, so its quad
/// gets the plane's (unbounded) box; implement the trait on your own type to give a
/// tighter one, for example the box of the [`Parallelogram`] your predicate stays within.
///
/// ```
/// use hitkit::{glam::DVec3, Hittable, Interval, Quad, Ray};
/// // A parallelogram with a square hole in the middle.
/// let frame = |a: f64, b: f64| {
///     (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && !((0.25..0.75).contains(&a) && (0.25..0.75).contains(&b))
/// };
/// let quad = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, frame).unwrap();
/// let through_hole = Ray::new(DVec3::new(0.5, 0.5, 1.0), DVec3::new(0.0, 0.0, -1.0));
/// assert!(quad.hit(&through_hole, Interval::FORWARD).is_none());
/// ```
pub trait Interior: Send + Sync {
    /// Whether the point with plane coordinates `(alpha, beta)` belongs to the shape.
    /// Only called with finite coordinates.
    fn contains(&self, alpha: f64, beta: f64) -> bool;

    /// Surface coordinates of a point of the shape. Default: `(alpha, beta)`.
    #[inline]
    fn uv(&self, alpha: f64, beta: f64) -> DVec2 {
        DVec2::new(alpha, beta)
    }

    /// A box containing every point of the shape laid on `plane`. Default: the plane's
    /// box (unbounded).
    fn bounding_box(&self, plane: &Plane) -> Aabb {
        plane.bounding_box()
    }

    /// How the shape lies against the region where a ray's exact crossing with the plane
    /// can be ([`CrossingRegion`]): wholly inside it, near it (some point of the segment
    /// `region.at(s)`, `|s| <= region.reach`, lies within `region.radius` of the shape), or
    /// clear of it. This is what makes edges watertight without false hits: see
    /// [`Quad`](crate::Quad).
    ///
    /// Default: [`Meets::Inside`] when the region's centre (the computed crossing) is
    /// [contained](Interior::contains), else [`Meets::Outside`]: no widening, so a ray
    /// through an edge shared with another shape may slip between them, but a point is
    /// only accepted where the predicate accepts it.
    #[inline]
    fn meets(&self, region: &CrossingRegion) -> Meets {
        if self.contains(region.center.x, region.center.y) {
            Meets::Inside
        } else {
            Meets::Outside
        }
    }

    /// A rectangle `[min, max]` of `(alpha, beta)` holding the whole shape, if the shape
    /// knows one: a [`Quad`](crate::Quad) then turns away rays whose crossing is clearly
    /// outside it before computing the crossing's error bounds (a division and the region
    /// it spends them on), which is most of what a miss beside a shape costs. It changes
    /// no decision of the built-in shapes (see the crate's contract); a shape that has
    /// points outside the rectangle it names loses the hits there. Default: `None`.
    ///
    /// ```
    /// use hitkit::glam::DVec2;
    /// use hitkit::{Disk, Interior, Parallelogram};
    /// assert_eq!(Parallelogram.coordinate_bounds(), Some([DVec2::ZERO, DVec2::ONE]));
    /// assert_eq!(Disk.coordinate_bounds(), Some([-DVec2::ONE, DVec2::ONE]));
    /// ```
    // Hidden: a speed hook of the built-in interiors (with the next), not what a shape
    // needs; public only because `Quad<S>` asks it of any `S`.
    #[doc(hidden)]
    #[inline]
    fn coordinate_bounds(&self) -> Option<[DVec2; 2]> {
        None
    }

    /// Whether the shape is the whole rectangle its
    /// [`coordinate_bounds`](Interior::coordinate_bounds) names (as the [`Parallelogram`]
    /// is): a [`Quad`](crate::Quad) then takes a crossing clearly inside the rectangle as a
    /// hit without computing its error bounds either. Default: `false`.
    #[doc(hidden)]
    #[inline]
    fn fills_coordinate_bounds(&self) -> bool {
        false
    }
}

/// How a shape lies against a [`CrossingRegion`] ([`Interior::meets`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Meets {
    /// The whole region is in the shape: the ray crosses the plane inside it.
    Inside,
    /// The point `region.at(s)` is within `region.radius` of the shape, but the region is
    /// not wholly inside: rounding cannot tell whether the ray crosses inside or beside.
    Near(f64),
    /// No point of the region is within its radius of the shape.
    Outside,
}

/// A shape tested exactly at the computed crossing, without widening its edges: a little
/// faster where rays often hit planes outside their shapes, but a ray through an edge
/// shared by two shapes may then slip between them. `docs/accuracy.md` measures both.
///
/// ```
/// use hitkit::{glam::DVec3, Exact, Parallelogram, Quad};
/// let fast = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, Exact(Parallelogram)).unwrap();
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct Exact<S>(pub S);

impl<S: Interior> Interior for Exact<S> {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        self.0.contains(alpha, beta)
    }

    #[inline]
    fn uv(&self, alpha: f64, beta: f64) -> DVec2 {
        self.0.uv(alpha, beta)
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        self.0.bounding_box(plane)
    }

    // No `coordinate_bounds`: deciding at the computed crossing alone, `Exact` leaves the
    // region's widths unused (the compiler drops them), and a clear-miss test would only
    // add work.
}

impl<F: Fn(f64, f64) -> bool + Send + Sync> Interior for F {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        self(alpha, beta)
    }
}

/// The values of `s` in `[-reach, reach]` for which the coordinate `c + s w` lies in
/// `[lo, hi]`, intersected with `span`. A constraint that no `s` meets empties the span.
#[inline]
fn narrow(span: &mut (f64, f64), c: f64, w: f64, lo: f64, hi: f64) {
    if w == 0.0 {
        if !(lo <= c && c <= hi) {
            *span = (f64::INFINITY, f64::NEG_INFINITY);
        }
        return;
    }
    let (a, b) = ((lo - c) / w, (hi - c) / w);
    let (a, b) = if w > 0.0 { (a, b) } else { (b, a) };
    span.0 = span.0.max(a);
    span.1 = span.1.min(b);
}

/// The `s` of `span` nearest 0 (the computed crossing), if the span is not empty.
#[inline]
fn nearest(span: (f64, f64)) -> Option<f64> {
    (span.0 <= span.1).then(|| 0.0f64.clamp(span.0, span.1))
}

/// The region's radius grown by the rounding of evaluating `center + s along` anywhere on
/// it (`gamma(3)` of the magnitudes), so that the tests below, which compare such values,
/// stay conservative.
#[inline]
fn evaluated_radius(region: &CrossingRegion) -> DVec2 {
    region.radius + gamma(3) * (region.center.abs() + region.half_length())
}

/// How a region lies against the convex polygon `{ x : lo_i <= k_i . x <= hi_i }` (each
/// `k_i` a row of small integers, so `k_i . radius` is the constraint's widening): the
/// parallelogram and the triangle.
#[inline(always)]
fn meets_polygon(region: &CrossingRegion, rows: &[([f64; 2], f64, f64)]) -> Meets {
    let r = evaluated_radius(region);
    let half = region.half_length();
    // Each row's value at the centre and how far the region reaches from it: the whole
    // region is inside, or clear of a row, without solving for the segment (no division
    // on the common paths).
    let mut inside = true;
    for &([ka, kb], lo, hi) in rows {
        let c = ka * region.center.x + kb * region.center.y;
        let widen = weigh(ka, kb, r);
        let extent = weigh(ka, kb, half) + widen;
        if c + extent < lo || c - extent > hi {
            return Meets::Outside;
        }
        inside &= lo <= c - extent && c + extent <= hi;
    }
    if inside {
        return Meets::Inside;
    }
    let mut span = (-region.reach, region.reach);
    for &([ka, kb], lo, hi) in rows {
        let widen = weigh(ka, kb, r);
        let c = ka * region.center.x + kb * region.center.y;
        let w = ka * region.along.x + kb * region.along.y;
        narrow(&mut span, c, w, lo - widen, hi + widen);
    }
    match nearest(span) {
        None => Meets::Outside,
        Some(s) => Meets::Near(s),
    }
}

/// `|ka| x.x + |kb| x.y`, where a zero `k` weighs nothing even against an infinite width
/// (a region whose reach has no bound): `0 * inf` would make it NaN, and NaN bounds would
/// turn such a region away instead of leaving it undecided.
#[inline(always)]
fn weigh(ka: f64, kb: f64, x: DVec2) -> f64 {
    let term = |k: f64, x: f64| if k == 0.0 { 0.0 } else { k.abs() * x };
    term(ka, x.x) + term(kb, x.y)
}

/// The parallelogram `0 <= alpha <= 1, 0 <= beta <= 1` with corners `q`, `q + u`,
/// `q + v`, `q + u + v`. `uv = (alpha, beta)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Parallelogram;

impl Interior for Parallelogram {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        (0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta)
    }

    #[inline(always)]
    fn meets(&self, region: &CrossingRegion) -> Meets {
        meets_polygon(region, &[([1.0, 0.0], 0.0, 1.0), ([0.0, 1.0], 0.0, 1.0)])
    }

    #[inline]
    fn coordinate_bounds(&self) -> Option<[DVec2; 2]> {
        Some([DVec2::ZERO, DVec2::ONE])
    }

    #[inline]
    fn fills_coordinate_bounds(&self) -> bool {
        true
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        let (q, u, v) = (plane.q(), plane.u(), plane.v());
        Aabb::from_points(&[q, q + u, q + v, q + u + v]).grown(corner_rounding(plane))
    }
}

/// The triangle `alpha >= 0, beta >= 0, alpha + beta <= 1` with corners `q`, `q + u`,
/// `q + v`. `uv = (alpha, beta)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Triangle;

impl Interior for Triangle {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        alpha >= 0.0 && beta >= 0.0 && alpha + beta <= 1.0
    }

    /// The triangle widened by the region's radius: the Minkowski sum of the triangle and
    /// a box is bounded by the triangle's three edges moved out and by `alpha <= 1`,
    /// `beta <= 1` moved out (which cut its corners, so a sliver widens by the radius and
    /// not by the radius over the sine of its angle).
    #[inline(always)]
    fn meets(&self, region: &CrossingRegion) -> Meets {
        meets_polygon(
            region,
            &[
                ([1.0, 0.0], 0.0, 1.0),
                ([0.0, 1.0], 0.0, 1.0),
                ([1.0, 1.0], f64::NEG_INFINITY, 1.0),
            ],
        )
    }

    #[inline]
    fn coordinate_bounds(&self) -> Option<[DVec2; 2]> {
        Some([DVec2::ZERO, DVec2::ONE])
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        let (q, u, v) = (plane.q(), plane.u(), plane.v());
        Aabb::from_points(&[q, q + u, q + v]).grown(corner_rounding(plane))
    }
}

/// The ellipse `alpha^2 + beta^2 <= 1`: `q` is the centre, `u` and `v` the semi-axes (a
/// circle when they are perpendicular and of equal length).
///
/// `uv = ((alpha + 1) / 2, (beta + 1) / 2)`: the disk's bounding parallelogram mapped onto
/// `[0, 1]^2`, so the centre is `(0.5, 0.5)`; no seam, unlike polar coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Disk;

impl Interior for Disk {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        alpha * alpha + beta * beta <= 1.0
    }

    #[inline]
    fn meets(&self, region: &CrossingRegion) -> Meets {
        meets_annulus(region, 0.0)
    }

    #[inline]
    fn coordinate_bounds(&self) -> Option<[DVec2; 2]> {
        Some([-DVec2::ONE, DVec2::ONE])
    }

    #[inline]
    fn uv(&self, alpha: f64, beta: f64) -> DVec2 {
        disk_uv(alpha, beta)
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        ellipse_box(plane)
    }
}

/// The elliptic annulus `inner^2 <= alpha^2 + beta^2 <= 1`: a [`Disk`] with a hole of
/// relative radius `inner`. `uv` as for [`Disk`].
///
/// ```
/// use hitkit::{GeometryError, Ring};
/// assert!(Ring::new(0.5).is_ok());
/// assert!(matches!(Ring::new(1.0), Err(GeometryError::InvalidParameter { .. })));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ring {
    inner: f64,
}

impl Ring {
    /// A ring whose hole has radius `inner` relative to the outer edge.
    ///
    /// # Errors
    /// [`GeometryError::InvalidParameter`] unless `0 <= inner < 1`.
    pub fn new(inner: f64) -> Result<Self, GeometryError> {
        if (0.0..1.0).contains(&inner) {
            Ok(Self { inner })
        } else {
            Err(GeometryError::InvalidParameter {
                what: "ring inner radius",
                value: inner,
                domain: "[0, 1)",
            })
        }
    }

    /// The hole's radius relative to the outer edge.
    #[inline]
    #[must_use]
    pub fn inner(&self) -> f64 {
        self.inner
    }
}

impl Interior for Ring {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        let r2 = alpha * alpha + beta * beta;
        self.inner * self.inner <= r2 && r2 <= 1.0
    }

    #[inline]
    fn meets(&self, region: &CrossingRegion) -> Meets {
        meets_annulus(region, self.inner)
    }

    #[inline]
    fn coordinate_bounds(&self) -> Option<[DVec2; 2]> {
        Some([-DVec2::ONE, DVec2::ONE])
    }

    #[inline]
    fn uv(&self, alpha: f64, beta: f64) -> DVec2 {
        disk_uv(alpha, beta)
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        ellipse_box(plane)
    }
}

/// How a region lies against the annulus `inner <= |(alpha, beta)| <= 1` (a disk for
/// `inner = 0`). The radius is folded into the two circles (the annulus widened by a box of
/// half-widths `r` is within the circles moved by `|r|_1`). Along the segment,
/// `f(s) = |center + s along|^2` is a convex parabola: the segment meets the outer disk
/// where its minimum does, and then leaves the hole somewhere exactly when `f` reaches the
/// inner circle at an end of the segment or the outer circle on the way (where `f` is
/// larger still). Squares and sums round by `gamma(4)` of `f`, which widens both circles.
fn meets_annulus(region: &CrossingRegion, inner: f64) -> Meets {
    let r = evaluated_radius(region);
    let (c, w) = (region.center, region.along);
    let slack = r.x + r.y;
    let hole = (inner - slack).max(0.0);
    let (outer2, inner2) = ((1.0 + slack) * (1.0 + slack), hole * hole);
    let (outer2, inner2) = (outer2 * (1.0 + gamma(4)), inner2 * (1.0 - gamma(4)));
    let f = |s: f64| region.at(s).length_squared();
    let w2 = w.length_squared();
    let vertex = if w2 > 0.0 { -c.dot(w) / w2 } else { 0.0 };
    let s_min = vertex.clamp(-region.reach, region.reach);
    // (NaN, from an overflow, is no hit.)
    let closest = f(s_min);
    if closest.is_nan() || closest > outer2 {
        return Meets::Outside;
    }
    // The segment's ends (its centre for a zero `along`, where an infinite reach would
    // make NaN).
    let ends = if w2 > 0.0 && region.reach < f64::INFINITY {
        [-region.reach, region.reach]
    } else if w2 > 0.0 {
        [f64::NEG_INFINITY, f64::INFINITY]
    } else {
        [0.0, 0.0]
    };
    let f_end = |s: f64| if s.is_infinite() { f64::INFINITY } else { f(s) };
    let (f0, f1) = (f_end(ends[0]), f_end(ends[1]));
    if f0.max(f1).is_nan() || f0.max(f1) < inner2 {
        return Meets::Outside;
    }
    // Wholly inside: the farthest point within the unit circle, the nearest outside the
    // hole, both by the radius (and the rounding), strictly.
    let strict = 1.0 - slack;
    let far_ok = f0.max(f1) * (1.0 + gamma(4)) <= strict * strict;
    let near_ok = inner == 0.0 || f(s_min) * (1.0 - gamma(4)) >= (inner + slack) * (inner + slack);
    if strict > 0.0 && far_ok && near_ok {
        return Meets::Inside;
    }
    // The computed crossing itself, where it is near enough: as for the polygons, the
    // point nearest to it (a grazing ray's segment is long, and its point nearest the
    // centre can be far along the ray from where the ray meets the plane).
    let at_center = f(0.0);
    if inner2 <= at_center && at_center <= outer2 {
        return Meets::Near(0.0);
    }
    if f(s_min) >= inner2 {
        return Meets::Near(s_min);
    }
    // The nearest point of the segment is in the hole (so `along` is not zero, or no end
    // would leave it): from the parabola's vertex, step to where `f` reaches the hole's
    // edge, on the side of an end that leaves the hole.
    let step = sqrt(((inner2 - f(vertex)) / w2).max(0.0));
    let s = if f1 >= inner2 {
        (vertex + step).min(region.reach)
    } else {
        (vertex - step).max(-region.reach)
    };
    Meets::Near(s)
}

#[inline]
fn disk_uv(alpha: f64, beta: f64) -> DVec2 {
    DVec2::new(0.5 * (alpha + 1.0), 0.5 * (beta + 1.0))
}

/// How far a corner `q + u + v` computed in floats can be from the exact one: two sums,
/// `gamma(2)` of the summed magnitudes. Shapes grow their boxes by it, so that the box holds
/// the exact shape and not only its rounded corners.
fn corner_rounding(plane: &Plane) -> DVec3 {
    gamma(2) * (plane.q().abs() + plane.u().abs() + plane.v().abs())
}

/// The box of the ellipse `q + cos(s) u + sin(s) v`: along each axis its coordinate ranges
/// over `q_i ± sqrt(u_i^2 + v_i^2)`, the amplitude of `u_i cos(s) + v_i sin(s)`. The
/// half-width carries four roundings (two squares, a sum, a square root) and the sum with
/// `q` one more: `gamma(5)` of the magnitudes.
fn ellipse_box(plane: &Plane) -> Aabb {
    let (q, u, v) = (plane.q(), plane.u(), plane.v());
    let s = u * u + v * v;
    let half = DVec3::new(sqrt(s.x), sqrt(s.y), sqrt(s.z));
    Aabb::new(q - half, q + half).grown(gamma(5) * (q.abs() + half))
}
