//! Area-uniform sampling of interiors, which makes a [`Quad`] a [`PdfHittable`]: a light a
//! path tracer can aim at.

use core::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

use crate::math::{sin_cos, sqrt, unit_and_length};
use crate::spherical::{Polygon, View};
use crate::{Disk, Interior, Interval, Parallelogram, PdfHittable, Quad, Ray, Ring, Triangle};

/// An [`Interior`] that knows its area and draws uniform points from it, both in
/// `(alpha, beta)` space: what makes a [`Quad`] of that shape a [`PdfHittable`].
///
/// Implemented for [`Parallelogram`], [`Triangle`], [`Disk`] and [`Ring`]. Your own shape
/// opts in by implementing it beside [`Interior`]:
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{Interior, PdfHittable, Quad, SampleInterior};
///
/// /// The lower half of the parallelogram: `0 <= alpha <= 1, 0 <= beta <= 1/2`.
/// struct Strip;
/// impl Interior for Strip {
///     fn contains(&self, alpha: f64, beta: f64) -> bool {
///         (0.0..=1.0).contains(&alpha) && (0.0..=0.5).contains(&beta)
///     }
/// }
/// impl SampleInterior for Strip {
///     fn area(&self) -> f64 {
///         0.5
///     }
///     fn sample(&self, u: DVec2) -> DVec2 {
///         DVec2::new(u.x, 0.5 * u.y)
///     }
/// }
///
/// let light = Quad::with_interior(DVec3::new(0.0, 0.0, 2.0), DVec3::X, DVec3::Y, Strip).unwrap();
/// let to_light = light.sample_direction(DVec3::ZERO, DVec2::new(0.5, 0.5));
/// assert_eq!(to_light, DVec3::new(0.5, 0.25, 2.0));
/// assert!(light.pdf_value(DVec3::ZERO, to_light) > 0.0);
/// ```
pub trait SampleInterior: Interior {
    /// The shape's area in `(alpha, beta)` units: 1 for the [`Parallelogram`]. The quad's
    /// area is this times [`Plane::uv_area`](crate::Plane::uv_area).
    fn area(&self) -> f64;

    /// A point `(alpha, beta)` of the shape, uniformly distributed over its area when `u` is
    /// uniform in `[0, 1)^2`. [`Quad`] clamps `u` into `[0, 1]^2` before calling it.
    fn sample(&self, u: DVec2) -> DVec2;

    /// Whether the shape is the whole parallelogram, so that a quad of it whose edges are
    /// perpendicular (a rectangle) can be sampled uniformly in solid angle. Default: no.
    #[inline]
    fn is_parallelogram(&self) -> bool {
        false
    }

    /// Whether the shape is the whole [`Triangle`] (`q`, `q + u`, `q + v`), so that a quad
    /// of it can be sampled uniformly in solid angle. Default: no.
    #[inline]
    fn is_triangle(&self) -> bool {
        false
    }
}

/// How a [`Quad`] light chooses directions toward itself ([`Quad::with_sampling`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
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

impl SampleInterior for Parallelogram {
    #[inline]
    fn area(&self) -> f64 {
        1.0
    }

    #[inline]
    fn sample(&self, u: DVec2) -> DVec2 {
        u
    }

    #[inline]
    fn is_parallelogram(&self) -> bool {
        true
    }
}

impl SampleInterior for Triangle {
    #[inline]
    fn area(&self) -> f64 {
        0.5
    }

    #[inline]
    fn is_triangle(&self) -> bool {
        true
    }

    /// The square-root warp: `sqrt(u.x)` is the distance from the corner `q + u` toward the
    /// opposite edge, whose length grows with it, so `u.y` places the point along that edge.
    #[inline]
    fn sample(&self, u: DVec2) -> DVec2 {
        let s = sqrt(u.x);
        DVec2::new(1.0 - s, u.y * s)
    }
}

impl SampleInterior for Disk {
    #[inline]
    fn area(&self) -> f64 {
        PI
    }

    #[inline]
    fn sample(&self, u: DVec2) -> DVec2 {
        annulus_sample(0.0, u)
    }
}

impl SampleInterior for Ring {
    #[inline]
    fn area(&self) -> f64 {
        PI * (1.0 - self.inner() * self.inner())
    }

    #[inline]
    fn sample(&self, u: DVec2) -> DVec2 {
        annulus_sample(self.inner(), u)
    }
}

/// A uniform point of `inner <= r <= 1`: the area inside radius `r` grows as `r^2`, so
/// `r^2` is drawn uniformly between `inner^2` and 1.
#[inline]
fn annulus_sample(inner: f64, u: DVec2) -> DVec2 {
    let inner2 = inner * inner;
    let r = sqrt(inner2 + u.x * (1.0 - inner2));
    let (sin, cos) = sin_cos(TAU * u.y);
    DVec2::new(r * cos, r * sin)
}

impl<S: SampleInterior> Quad<S> {
    /// The shape's area on the plane: [`SampleInterior::area`] times
    /// [`Plane::uv_area`](crate::Plane::uv_area).
    #[inline]
    #[must_use]
    pub fn area(&self) -> f64 {
        self.plane().uv_area() * self.shape().area()
    }
}

impl<S: SampleInterior> Quad<S> {
    /// The polygon this quad is sampled as by solid angle, seen from `origin`: only where
    /// [`Sampling::SolidAngle`] says so.
    #[inline]
    fn spherical(&self, origin: DVec3) -> Option<View> {
        let polygon = match self.sampling() {
            Sampling::Area => return None,
            Sampling::SolidAngle if self.shape().is_parallelogram() => {
                let plane = self.plane();
                (plane.u().dot(plane.v()) == 0.0).then_some(Polygon::Rectangle)?
            }
            Sampling::SolidAngle if self.shape().is_triangle() => Polygon::Triangle,
            Sampling::SolidAngle => return None,
        };
        polygon.view(self.plane(), origin)
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
    /// `1 / solid angle` where the quad is sampled by solid angle; else
    /// `distance^2 / (|cos| area)`, the area density `1 / area` turned into one over solid
    /// angle at `origin`, where `cos` is between `direction` and the normal. 0 on a miss and
    /// wherever that is not a finite number: an origin in the plane, a grazing direction
    /// whose density overflows, an invalid ray.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        let ray = Ray::new(origin, direction);
        let hit = match self
            .plane()
            .intersect(&ray, Interval::new(0.0, f64::INFINITY))
        {
            Some(hit) if self.shape().contains(hit.alpha, hit.beta) => hit,
            _ => return 0.0,
        };
        if let Some(view) = self.spherical(origin) {
            return 1.0 / view.solid_angle();
        }
        // Through the unit direction and its length: no overflow in |d|^2 for long ones.
        let (unit, length) = unit_and_length(direction);
        let distance = hit.t * length;
        let cosine = self.plane().normal().dot(unit).abs();
        let pdf = distance * distance / (cosine * self.area());
        // Also rejects NaN (0 / 0).
        if pdf < f64::INFINITY { pdf } else { 0.0 }
    }

    /// `p - origin` (not normalized) for the point `p = q + alpha u + beta v` at
    /// [`SampleInterior::sample`]`(u)`; `u` is first clamped into `[0, 1]^2` (NaN to 0).
    ///
    /// A point exactly on the shape's edge (`u.x` or `u.y` exactly 0 for a parallelogram,
    /// say, as the first point of a Sobol sequence is) may, after rounding, aim just past
    /// it: [`pdf_value`](PdfHittable::pdf_value) is then 0 for that direction, and a renderer
    /// should count the sample as failed rather than divide by it.
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        if !origin.is_finite() {
            return DVec3::ZERO; // no direction from nowhere; it hits nothing
        }
        let u = u.clamp(DVec2::ZERO, DVec2::ONE);
        if let Some(view) = self.spherical(origin) {
            return view.sample(self.plane(), origin, u);
        }
        let at = self.shape().sample(u);
        let plane = self.plane();
        let toward =
            |k: f64| (k * plane.q() - k * origin) + (k * at.x * plane.u() + k * at.y * plane.v());
        let direction = toward(1.0);
        // Where the difference overflows, a quarter of every term does not (four terms of at
        // most f64::MAX / 4), and points the same way.
        if direction.is_finite() {
            direction
        } else {
            toward(0.25)
        }
    }
}

impl<S: SampleInterior> SampleInterior for crate::Exact<S> {
    #[inline]
    fn area(&self) -> f64 {
        self.0.area()
    }

    #[inline]
    fn sample(&self, u: DVec2) -> DVec2 {
        self.0.sample(u)
    }

    #[inline]
    fn is_parallelogram(&self) -> bool {
        self.0.is_parallelogram()
    }

    #[inline]
    fn is_triangle(&self) -> bool {
        self.0.is_triangle()
    }
}
