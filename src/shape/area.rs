//! Interiors that can be sampled: [`SampleInterior`] (an area and area-uniform points in
//! `(alpha, beta)` space), which makes a [`Quad`] of the shape a [`PdfHittable`], and the
//! [`Polygon`]s that also have a solid-angle sampler.

use core::f64::consts::{PI, TAU};

use glam::DVec2;

use crate::math::{sin_cos, sqrt};
use crate::{Disk, Exact, Interior, Parallelogram, Ring, Triangle};
#[cfg(doc)]
use crate::{PdfHittable, Quad, Sampling};

/// A whole polygon with a solid-angle sampler: what [`SampleInterior::polygon`] returns
/// for a shape that is one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum Polygon {
    /// The whole parallelogram (`0 <= alpha, beta <= 1`); sampled by solid angle where
    /// its edges are perpendicular (a rectangle: Ureña et al. 2013).
    Parallelogram,
    /// The whole triangle `q`, `q + u`, `q + v` (Arvo 1995).
    Triangle,
}

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
/// let toward = DVec3::new(0.5, 0.25, 2.0); // the point (alpha, beta) = (0.5, 0.25)
/// assert!((to_light - toward.normalize()).length() < 1e-15);
/// assert!(light.pdf_value(DVec3::ZERO, to_light) > 0.0);
/// ```
pub trait SampleInterior: Interior {
    /// The shape's area in `(alpha, beta)` units: 1 for the [`Parallelogram`]. The quad's
    /// area is this times [`Plane::uv_area`](crate::Plane::uv_area).
    fn area(&self) -> f64;

    /// A point `(alpha, beta)` of the shape, uniformly distributed over its area when `u` is
    /// uniform in `[0, 1)^2`. [`Quad`] clamps `u` into `[0, 1]^2` before calling it.
    fn sample(&self, u: DVec2) -> DVec2;

    /// The whole polygon the shape is, if it is one with a solid-angle sampler: then a
    /// [`Quad`] of it can be sampled uniformly in the solid angle it subtends (see
    /// [`Sampling::SolidAngle`]). Default: `None`, sampled by area. A wrapper forwards it.
    #[inline]
    fn polygon(&self) -> Option<Polygon> {
        None
    }
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
    fn polygon(&self) -> Option<Polygon> {
        Some(Polygon::Parallelogram)
    }
}

impl SampleInterior for Triangle {
    #[inline]
    fn area(&self) -> f64 {
        0.5
    }

    #[inline]
    fn polygon(&self) -> Option<Polygon> {
        Some(Polygon::Triangle)
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

impl<S: SampleInterior> SampleInterior for Exact<S> {
    #[inline]
    fn area(&self) -> f64 {
        self.0.area()
    }

    #[inline]
    fn sample(&self, u: DVec2) -> DVec2 {
        self.0.sample(u)
    }

    #[inline]
    fn polygon(&self) -> Option<Polygon> {
        self.0.polygon()
    }
}
