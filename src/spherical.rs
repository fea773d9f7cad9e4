//! Sampling a rectangle uniformly in the solid angle it subtends: Ureña, Fajardo and King
//! 2013, "An Area-Preserving Parametrization for Spherical Rectangles" (the formulation of
//! pbrt-v4's `SampleSphericalRectangle`). Area sampling weights directions by
//! `distance^2 / cos`, which is large where a near light is seen at a slant; sampling the
//! solid angle itself has density `1 / solid angle` everywhere on the light.

use core::f64::consts::TAU;

use glam::{DVec2, DVec3};

use crate::Plane;
use crate::math::{acos, sin_cos, sqrt, unit_and_length};

/// Solid angles (steradians) between which spherical sampling is used, as in pbrt-v4:
/// below, `g0 + g1 + g2 + g3 - 2 pi` cancels too much for an accurate density (and area
/// sampling is as good for a small, far light); above, the rectangle fills nearly the
/// hemisphere and the parametrization loses accuracy.
const MIN_SOLID_ANGLE: f64 = 3e-4;
const MAX_SOLID_ANGLE: f64 = 6.22;

/// The spherical rectangle of a rectangular quad as seen from a point: its local frame,
/// extents and internal angles.
pub(crate) struct SphericalRectangle {
    frame: [DVec3; 3],
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    /// `z` components of the first and third edges' normals, and `2 pi - g2 - g3`.
    b0: f64,
    b1: f64,
    k: f64,
    solid_angle: f64,
}

impl SphericalRectangle {
    /// The rectangle `plane` (with `u` exactly perpendicular to `v`) seen from `origin`, if
    /// its solid angle lies where spherical sampling is accurate.
    pub(crate) fn new(plane: &Plane, origin: DVec3) -> Option<Self> {
        let (u, v) = (plane.u(), plane.v());
        if u.dot(v) != 0.0 {
            return None;
        }
        let ((ex, exl), (ey, eyl)) = (unit_and_length(u), unit_and_length(v));
        let mut ez = ex.cross(ey);
        let d = plane.q() - origin;
        let (x0, y0, mut z0) = (d.dot(ex), d.dot(ey), d.dot(ez));
        if z0 > 0.0 {
            z0 = -z0;
            ez = -ez;
        }
        let (x1, y1) = (x0 + exl, y0 + eyl);
        let corner = |x: f64, y: f64| DVec3::new(x, y, z0);
        let (v00, v01, v10, v11) = (
            corner(x0, y0),
            corner(x0, y1),
            corner(x1, y0),
            corner(x1, y1),
        );
        let normal = |a: DVec3, b: DVec3| unit_and_length(a.cross(b)).0;
        let (n0, n1, n2, n3) = (
            normal(v00, v10),
            normal(v10, v11),
            normal(v11, v01),
            normal(v01, v00),
        );
        let angle = |a: DVec3, b: DVec3| acos((-a).dot(b).clamp(-1.0, 1.0));
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let solid_angle = g0 + g1 + g2 + g3 - TAU;
        (MIN_SOLID_ANGLE..=MAX_SOLID_ANGLE)
            .contains(&solid_angle)
            .then_some(Self {
                frame: [ex, ey, ez],
                x0,
                x1,
                y0,
                y1,
                z0,
                b0: n0.z,
                b1: n2.z,
                k: TAU - g2 - g3,
                solid_angle,
            })
    }

    pub(crate) fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// The direction (from the origin, not normalized) to the point of the rectangle at
    /// `u`, uniform in solid angle.
    pub(crate) fn sample(&self, u: DVec2) -> DVec3 {
        let Self {
            x0,
            x1,
            y0,
            y1,
            z0,
            b0,
            b1,
            k,
            ..
        } = *self;
        // The x coordinate: the area up to it is u.x of the whole.
        let au = u.x * self.solid_angle + k;
        let (sin_au, cos_au) = sin_cos(au);
        let fu = (cos_au * b0 - b1) / sin_au;
        let cu = (1.0 / sqrt(fu * fu + b0 * b0))
            .copysign(fu)
            .clamp(-1.0, 1.0);
        let xu = (-(cu * z0) / sqrt((1.0 - cu * cu).max(0.0))).clamp(x0, x1);
        // The y coordinate: uniform in the projected height along that column.
        let dd = sqrt(xu * xu + z0 * z0);
        let (h0, h1) = (y0 / sqrt(dd * dd + y0 * y0), y1 / sqrt(dd * dd + y1 * y1));
        let hv = h0 + u.y * (h1 - h0);
        let yv = if hv * hv < 1.0 {
            (hv * dd / sqrt(1.0 - hv * hv)).clamp(y0, y1)
        } else {
            y1
        };
        let [ex, ey, ez] = self.frame;
        xu * ex + yv * ey + z0 * ez
    }
}
