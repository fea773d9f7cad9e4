//! [`Quad`]: a [`Plane`] and an [`Interior`] predicate, the book's quadrilateral and every
//! other planar shape; a [`PdfHittable`] (a light) where its interior can be sampled.

use glam::{DVec2, DVec3};

use super::{Crossing, Decided, Pending};
use super::{Polygon, Spherical, View};
use crate::math::{direction_scale, gamma, unit_and_length};
use crate::record::{Found, Made};
use crate::sample::{reaching, toward_middle, unit_direction};
use crate::shape::Meets;
use crate::{
    Aabb, GeometryError, HitRecord, Hittable, Interior, Interval, MaterialId, Parallelogram,
    PdfHittable, Plane, PlaneHit, Ray, SampleInterior,
};

/// How a [`Quad`] light chooses directions toward itself ([`Quad::with_sampling`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum Sampling {
    /// Rectangles and triangles uniformly in the solid angle they subtend (Ureña et al.
    /// 2013, Arvo 1995) where it lies between 3e-4 and 6.22 steradians (pbrt-v4's
    /// bounds, where those samplers are accurate); everything else uniformly over its area.
    /// Lower variance near a light, for several times the cost per sample.
    #[default]
    SolidAngle,
    /// Uniformly over the shape's area, for every shape and origin: the cheapest sample, and
    /// as good as solid angle for lights that are small or far.
    Area,
}

/// A planar shape: a [`Plane`] finds `(t, alpha, beta)`, an [`Interior`] predicate decides
/// whether the point belongs to the shape. With the default [`Parallelogram`] it is the
/// book's quad, with corners `q`, `q + u`, `q + v`, `q + u + v`.
///
/// Edges are inclusive and watertight. The built-in shapes decide by the region where the
/// ray's exact crossing with the plane can be ([`Plane::crossing_region`]): narrow across
/// the ray whatever its angle, long only along it. A shape wholly around the region is hit,
/// one clear of it is not, and only a ray that passes within rounding of an edge is decided
/// again, in double-double arithmetic. The shapes also widen by the plane's
/// [tolerance](Plane::tolerance) (a few ulps of the corners' magnitude, in world space), so
/// that a ray through an edge shared by two shapes hits one of them even where their
/// corners were rounded apart; and every hit's `t` lies within the quad's box's span, so a
/// [`Bvh`](crate::Bvh) finds exactly what a loop finds. See the crate's contract. Wrap a
/// shape in [`Exact`](crate::Exact) to decide at the computed crossing alone.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Hittable, Interval, MaterialId, Quad, Ray, Ring, Triangle};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// let wall = Quad::new(DVec3::new(-2.0, -2.0, 0.0), DVec3::new(4.0, 0.0, 0.0), DVec3::new(0.0, 4.0, 0.0))?
///     .with_material(MaterialId(1));
/// let tri = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, Triangle)?;
/// let ring = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, Ring::new(0.5)?)?;
///
/// let ray = Ray::new(DVec3::new(0.1, 0.1, 5.0), DVec3::new(0.0, 0.0, -1.0));
/// let hit = wall.hit(&ray, Interval::FORWARD).unwrap();
/// assert_eq!((hit.t, hit.material), (5.0, MaterialId(1)));
/// assert!(tri.hit(&ray, Interval::FORWARD).is_some());
/// assert!(ring.hit(&ray, Interval::FORWARD).is_none()); // in the hole
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad<S = Parallelogram> {
    plane: Plane,
    shape: S,
    bbox: Aabb,
    sampling: Sampling,
}

impl Quad<Parallelogram> {
    /// The parallelogram with corner `q` and edges `u`, `v`.
    ///
    /// # Errors
    /// As [`Plane::new`].
    pub fn new(q: DVec3, u: DVec3, v: DVec3) -> Result<Self, GeometryError> {
        Self::with_interior(q, u, v, Parallelogram)
    }
}

impl<S: Interior> Quad<S> {
    /// The part of the plane through `q` spanned by `u`, `v` that `shape` accepts.
    ///
    /// # Errors
    /// As [`Plane::new`].
    pub fn with_interior(q: DVec3, u: DVec3, v: DVec3, shape: S) -> Result<Self, GeometryError> {
        let plane = Plane::new(q, u, v)?;
        let shape_box = shape.bounding_box(&plane);
        let bbox = shape_box.grown(DVec3::splat(reach_beyond(&plane)));
        if shape_box.is_bounded() && !bbox.is_bounded() {
            return Err(GeometryError::OutOfRange);
        }
        Ok(Self {
            plane,
            shape,
            bbox,
            sampling: Sampling::default(),
        })
    }

    /// The same shape with material `material`.
    #[inline]
    #[must_use]
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.plane = self.plane.with_material(material);
        self
    }

    /// The same shape, sampled as a light by `sampling` (see [`Sampling`]; the default
    /// samples rectangles and triangles by solid angle where that is accurate).
    #[inline]
    #[must_use]
    pub fn with_sampling(mut self, sampling: Sampling) -> Self {
        self.sampling = sampling;
        self
    }

    /// How the shape is sampled as a light.
    #[inline]
    #[must_use]
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// The plane the shape lies on.
    #[inline]
    #[must_use]
    pub fn plane(&self) -> &Plane {
        &self.plane
    }

    /// The interior predicate.
    #[inline]
    #[must_use]
    pub fn shape(&self) -> &S {
        &self.shape
    }

    /// The decided crossing `hit`, settled: a `t` that rounding put before or past the
    /// box moves onto it, so that a `Bvh` (whose boxes contain this one) finds every hit a
    /// loop over the shapes finds; only then is it compared with `ray_t`.
    ///
    /// The record's point, too, stays in the box ([`Quad::build`]): a crossing decided near an edge may lie beside the
    /// shape by as much as the region's width, which for a grazing ray on a plane of
    /// extreme edges can pass the box's margin. It moves onto the box (toward the shape,
    /// which the box holds), and its error bound grows by the move, so that the point on
    /// the plane it was computed as still lies within it.
    #[inline(always)]
    fn settle(&self, ray: &Ray, ray_t: Interval, mut hit: PlaneHit) -> Option<PlaneHit> {
        hit.t = self.bbox.clamp_hit(ray, hit.t)?;
        ray_t.contains(hit.t).then_some(hit)
    }

    /// The rectangle of `(alpha, beta)` holding the shape, and whether the shape fills it:
    /// what [`Plane::crossing`] decides clear crossings by.
    #[inline(always)]
    fn window(&self) -> Option<([DVec2; 2], bool)> {
        self.shape
            .coordinate_bounds()
            .map(|bounds| (bounds, self.shape.fills_coordinate_bounds()))
    }

    /// [`Quad::decide`] for a ray whose direction's length is extreme, along the same ray
    /// with the direction scaled (exactly) to an ordinary length; `None` for a ray that
    /// cannot be traced.
    #[cold]
    #[inline(never)]
    fn decide_rescaled(&self, ray: &Ray, ray_t: Interval) -> Option<PlaneHit> {
        let (scaled, scale) = ray.rescaled()?;
        let mut hit = self.decide(&scaled, ray_t.scaled(1.0 / scale))?;
        hit.t = Ray::t_from_rescaled(hit.t, scale, ray_t)?;
        Some(hit)
    }

    /// The record of a settled crossing (see [`Quad::settle`]). (Tried: out of line; slower
    /// where a quad's `hit` inlines into its caller, no faster where it does not.)
    #[inline(always)]
    fn build(&self, ray: &Ray, hit: PlaneHit) -> Option<HitRecord> {
        let mut record = self
            .plane
            .hit_record(ray, hit, self.shape.uv(hit.alpha, hit.beta))?;
        let inside = record.point.clamp(self.bbox.min(), self.bbox.max());
        if inside != record.point {
            record.point_error += (inside - record.point).abs();
            record.point = inside;
        }
        // Twice the tolerance by which this shape and its neighbours widen, so that a ray
        // spawned from the hit clears them: leaving a face near its edge, almost along it,
        // a ray would otherwise run within the neighbour's widening and find it at once
        // (the contract's clause 5; pbrt-v4's test of convex shapes finds it on boxes).
        record.point_error += DVec3::splat(2.0 * self.plane.tolerance());
        record.point_error.is_finite().then_some(record)
    }
}

/// How far the box of a quad reaches beyond its shape, per coordinate: the plane's
/// [tolerance](Plane::tolerance) and the frame's own error at the shape (a world-space
/// distance, so per coordinate too), and a few ulps of itself. A ray that passes
/// within the tolerance of the shape (the widening that closes gaps between neighbours
/// whose corners were rounded apart, across the ray or along it) meets that box; what the
/// region's widening in `(alpha, beta)` would accept beyond it (at the acute corners of a
/// sliver, say) the box cuts off, since every hit is kept within the box's span.
fn reach_beyond(plane: &Plane) -> f64 {
    (plane.tolerance() + plane.frame_reach()) * (1.0 + gamma(4))
}

impl<S: Interior> Quad<S> {
    /// The decided and settled crossing, if the ray hits the shape with `t` in `ray_t`.
    /// The reported `t` depends on the ray alone, never on `ray_t.max` (which a `Bvh` or a
    /// list lowers as it finds hits): it is decided, moved into the box's span along the
    /// whole ray, and only then compared with `ray_t`.
    #[inline(always)]
    fn decide(&self, ray: &Ray, ray_t: Interval) -> Option<PlaneHit> {
        match self.plane.crossing(ray, ray_t, self.window())? {
            Crossing::Inside(hit) => self.settle(ray, ray_t, hit),
            Crossing::Pending(pending) => self.decide_pending(ray, ray_t, pending),
            Crossing::Rescale => self.decide_rescaled(ray, ray_t),
        }
    }

    /// [`Quad::decide`] for a crossing the quick test left undecided: by the exact error
    /// terms, then by the region ([`Interior::meets`]), then near an edge in double-double.
    /// Out of line: few crossings come here, and the common path stays small.
    #[inline(never)]
    fn decide_pending(&self, ray: &Ray, ray_t: Interval, pending: Pending) -> Option<PlaneHit> {
        let plane = &self.plane;
        // Whatever the decision below, the reported t is at least t - 3 reach (the refined
        // crossing's own reach is no larger than this one's): `settle_pending` rejects a t
        // past ray_t.max by more (and crossings the shape's rectangle shows clearly outside
        // it). A crossing clearly inside a shape that fills its rectangle is decided there.
        let (mut hit, region) = match plane.settle_pending(ray, ray_t, self.window(), pending)? {
            Decided::Inside(hit) => return self.settle(ray, ray_t, hit),
            Decided::Region(hit, region) => (hit, region),
        };
        // The box's clamp below may move `t` no lower than this. The box holds the shape
        // widened as far as any crossing that truly meets it, and its span along the ray is
        // padded outward, so for such a crossing the clamp stops within the reach of `t`.
        // A region far wider in one coordinate than the shape's scale along it (an ellipse
        // a billion times longer than wide) can meet the shape while the ray passes far
        // outside its box: that crossing is no hit, and refusing it here keeps the answer
        // the same whatever `ray_t.max` is (the early refusals above assume this floor).
        let floor = hit.t - 3.0 * region.reach;
        match self.shape.meets(&region) {
            Meets::Inside => {}
            Meets::Outside => return None,
            // Rounding in f64 cannot tell: ask again of the double-double crossing, whose
            // region is as narrow as the shape's own corners allow.
            Meets::Near(_) => {
                let (precise, region, rounding) = plane.refine(ray)?;
                // Clause 5, where the f64 reach could not tell (see `Plane::crossing`).
                if precise.t - rounding < ray_t.min && ray_t.min > f64::NEG_INFINITY {
                    return None;
                }
                hit = match self.shape.meets(&region) {
                    Meets::Inside => precise,
                    Meets::Near(s) => {
                        let at = region.at(s);
                        PlaneHit {
                            t: precise.t + s,
                            alpha: at.x,
                            beta: at.y,
                        }
                    }
                    Meets::Outside => return None,
                };
            }
        }
        self.settle(ray, ray_t, hit)
            .filter(|settled| settled.t >= floor)
    }
}

impl<S: Interior> Hittable for Quad<S> {
    // Inlined always: in a caller's loop over quads the per-ray work is shared, and the
    // record's registers are not saved around a call (faster through a box's six faces).
    #[inline(always)]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.build(ray, self.decide(ray, ray_t)?)
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    /// The crossing's `(alpha, beta)` in `coords`.
    #[inline(always)]
    fn find(&self, ray: &Ray, ray_t: Interval, _: &mut Made) -> Option<Found> {
        let hit = self.decide(ray, ray_t)?;
        Some(Found::new(hit.t, DVec3::new(hit.alpha, hit.beta, 0.0), 0))
    }

    #[inline]
    fn record(&self, ray: &Ray, _: Interval, found: &Found) -> Option<HitRecord> {
        let (t, alpha, beta) = (found.t, found.coords.x, found.coords.y);
        self.build(ray, PlaneHit { t, alpha, beta })
    }
}

impl<S: SampleInterior> Quad<S> {
    /// The shape's area on the plane: [`SampleInterior::area`] times
    /// [`Plane::uv_area`].
    #[inline]
    #[must_use]
    pub fn area(&self) -> f64 {
        self.plane().uv_area() * self.shape().area()
    }

    /// The polygon this quad is sampled as by solid angle, seen from `origin`: only where
    /// [`Sampling::SolidAngle`] says so.
    #[inline]
    fn spherical(&self, origin: DVec3) -> Option<View> {
        if self.sampling() == Sampling::Area {
            return None;
        }
        let spherical = match self.shape().polygon()? {
            Polygon::Parallelogram => {
                let plane = self.plane();
                (plane.u().dot(plane.v()) == 0.0).then_some(Spherical::Rectangle)?
            }
            Polygon::Triangle => Spherical::Triangle,
        };
        spherical.view(self.plane(), origin)
    }
}

/// Directions toward a quad are drawn uniformly over its area, except for rectangles and
/// triangles that subtend a solid angle between about 3e-4 and 6.22 steradians (pbrt-v4's
/// bounds), which are sampled uniformly in that solid angle (Ureña et al. 2013, Arvo 1995):
/// lower variance near the light, where area sampling's `distance^2 / cos` weights vary
/// most. `pdf_value` follows the same choice, which depends on the origin only.
/// [`Quad::with_sampling`]`(`[`Sampling::Area`]`)` samples every origin by area.
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{PdfHittable, Quad, Sampling, Triangle};
///
/// // A triangular ceiling light 1 above the origin, sampled over its area.
/// let light = Quad::with_interior(DVec3::new(-1.0, 1.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0, Triangle)
///     .unwrap()
///     .with_sampling(Sampling::Area);
/// let up = DVec3::Y;
/// // Straight up, distance 1, cosine 1: the density is 1 / area = 1 / 2.
/// assert_eq!(light.pdf_value(DVec3::ZERO, up), 0.5);
/// assert_eq!(light.pdf_value(DVec3::ZERO, -up), 0.0); // misses
///
/// // A 2 x 2 square there is sampled by solid angle: the same density in every direction
/// // that reaches it, one over its solid angle (about 2.09 sr).
/// let square = Quad::new(DVec3::new(-1.0, 1.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0).unwrap();
/// let d = square.sample_direction(DVec3::ZERO, DVec2::new(0.3, 0.8));
/// assert_eq!(square.pdf_value(DVec3::ZERO, d), square.pdf_value(DVec3::ZERO, up));
/// assert!((square.pdf_value(DVec3::ZERO, up) - 1.0 / 2.0944).abs() < 1e-4);
/// ```
impl<S: SampleInterior> PdfHittable for Quad<S> {
    /// From the side its normal (`u x v`) faces: [`Emission::OneSide`](crate::Emission::OneSide).
    #[inline]
    fn emission(&self) -> crate::Emission {
        crate::Emission::OneSide(self.plane().normal())
    }

    /// `1 / solid angle` where the quad is sampled by solid angle; else
    /// `distance^2 / (|cos| area)`, the area density `1 / area` turned into one over solid
    /// angle at `origin`, where `cos` is between `direction` and the normal. 0 on a miss and
    /// wherever that is not a finite number: an origin in the plane, a grazing direction
    /// whose density overflows, an invalid ray.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.density(origin, direction, || {
            self.spherical(origin).map(|view| view.solid_angle())
        })
    }

    /// The unit direction toward the point `p = q + alpha u + beta v` at
    /// [`SampleInterior::sample`]`(u)` (by [`Sampling::Area`]; by solid angle, toward a
    /// point of the same density); `u` is first clamped into `[0, 1]^2` (NaN to 0).
    ///
    /// A point on the shape's edge (`u.x` or `u.y` exactly 0 for a parallelogram, as the
    /// first point of a Sobol sequence is) may, after rounding, aim just past it; such a
    /// direction is drawn again from `u` moved a little toward the middle of the square, so
    /// that [`pdf_value`](PdfHittable::pdf_value) is positive for every direction returned
    /// (the contract's clause 6) wherever the shape can be aimed at from `origin` at all.
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        if !origin.is_finite() {
            return DVec3::ZERO; // no direction from nowhere; it hits nothing
        }
        let u = u.clamp(DVec2::ZERO, DVec2::ONE);
        let view = self.spherical(origin);
        let plane = self.plane();
        let sample = |k: f64| {
            let u = toward_middle(u, k);
            // A solid-angle sample that is not finite (an origin within rounding of a
            // corner) is drawn by area instead.
            if let Some(view) = &view {
                let d = view.sample(plane, origin, u);
                if d.is_finite() {
                    return unit_direction(d);
                }
            }
            let at = self.shape().sample(u);
            let toward = |k: f64| {
                (k * plane.q() - k * origin) + (k * at.x * plane.u() + k * at.y * plane.v())
            };
            let direction = toward(1.0);
            // Where the difference overflows, a quarter of every term does not (four terms
            // of at most f64::MAX / 4), and points the same way.
            unit_direction(if direction.is_finite() {
                direction
            } else {
                toward(0.25)
            })
        };
        // By the density itself (not only by whether the direction reaches the shape): a
        // grazing direction can reach it with a density past f64's range, which is 0.
        let solid_angle = view.as_ref().map(View::solid_angle);
        reaching(sample, |d| self.density(origin, d, || solid_angle) > 0.0)
    }
}

impl<S: SampleInterior> Quad<S> {
    /// [`PdfHittable::pdf_value`], with the solid angle of the view it is sampled by
    /// (`None`: sampled by area) asked of `solid_angle` only where the direction reaches
    /// the shape.
    #[inline]
    fn density(
        &self,
        origin: DVec3,
        direction: DVec3,
        solid_angle: impl FnOnce() -> Option<f64>,
    ) -> f64 {
        // A density over solid angle: the direction's length is free, and one of ordinary
        // length (an exact scaling) keeps `t` within f64's range.
        let direction = direction * direction_scale(direction);
        let Some(hit) = self.reached(origin, direction) else {
            return 0.0;
        };
        if let Some(solid_angle) = solid_angle() {
            return 1.0 / solid_angle;
        }
        // Through the unit direction and its length: no overflow in |d|^2 for long ones.
        let (unit, length) = unit_and_length(direction);
        let distance = hit.t * length;
        let cosine = self.plane().normal().dot(unit).abs();
        let pdf = distance * distance / (cosine * self.area());
        // Also rejects NaN (0 / 0).
        if pdf < f64::INFINITY { pdf } else { 0.0 }
    }

    /// Where the ray from `origin` along `direction` meets the shape at `t >= 0`, by the
    /// computed crossing: the test [`PdfHittable::pdf_value`] goes by.
    #[inline]
    fn reached(&self, origin: DVec3, direction: DVec3) -> Option<PlaneHit> {
        let ray = Ray::new(origin, direction);
        self.plane()
            .intersect(&ray, Interval::FORWARD)
            .filter(|hit| self.shape().contains(hit.alpha, hit.beta))
    }
}
