//! Sampling rectangles and triangles uniformly in the solid angle they subtend. Area
//! sampling weights directions by `distance^2 / cos`, which is large where a near light is
//! seen at a slant; sampling the solid angle itself has density `1 / solid angle`
//! everywhere on the light.
//!
//! - Rectangles: Ureña, Fajardo and King 2013, "An Area-Preserving Parametrization for
//!   Spherical Rectangles" (in the formulation of pbrt-v4's `SampleSphericalRectangle`).
//! - Triangles: Arvo 1995, "Stratified Sampling of Spherical Triangles".
//! - Solid angles: Van Oosterom and Strackee 1983, "The Solid Angle of a Plane Triangle",
//!   one `atan2` per triangle and no cancellation for small ones.

use core::f64::consts::TAU;

use glam::{DVec2, DVec3};

use crate::math::{acos, atan2, power_of_two_scale, sin_cos, sqrt};
use crate::{Interval, Plane, Ray};

/// Solid angles (steradians) between which spherical sampling is used, as in pbrt-v4:
/// below, a light is small and far, its `distance^2 / cos` nearly constant, and area
/// sampling as good and cheaper; above, the shape fills nearly the hemisphere and the
/// parametrizations lose accuracy.
const MIN_SOLID_ANGLE: f64 = 3e-4;
const MAX_SOLID_ANGLE: f64 = 6.22;

/// The shapes with a solid-angle sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Spherical {
    /// `q`, `q + u`, `q + u + v`, `q + v` with `u` perpendicular to `v`.
    Rectangle,
    /// `q`, `q + u`, `q + v`.
    Triangle,
}

/// A polygon as seen from an origin where it is sampled by solid angle: its scaled frame,
/// the unit directions to its first three corners, and its solid angle.
pub(crate) struct View {
    polygon: Spherical,
    /// `q - origin`, `u`, `v`, times `scale` (see [`scaled_frame`]).
    frame: [DVec3; 3],
    scale: f64,
    /// Unit directions to `q`, `q + u`, `q + v`.
    corners: [DVec3; 3],
    solid_angle: f64,
}

impl Spherical {
    /// The polygon on `plane` as seen from `origin`, if its solid angle lies where
    /// spherical sampling is used; `None` elsewhere, also for an origin in the plane or at a
    /// corner (solid angle 0 or NaN).
    pub(crate) fn view(self, plane: &Plane, origin: DVec3) -> Option<View> {
        let (frame, scale) = scaled_frame(plane, origin)?;
        let [d, u, v] = frame;
        let (a, b, c) = (d.normalize(), (d + u).normalize(), (d + v).normalize());
        let half = match self {
            Spherical::Triangle => half_solid_angle(a, b, c),
            Spherical::Rectangle => {
                // The two triangles' half angles added as the arguments of complex numbers
                // multiply: one atan2 instead of two. Their sum is below pi (the rectangle's
                // solid angle below 2 pi), where atan2 returns it unchanged.
                let corner = (d + u + v).normalize();
                let (p, q) = (
                    half_solid_angle(a, b, corner),
                    half_solid_angle(a, corner, c),
                );
                DVec2::new(p.x * q.x - p.y * q.y, p.x * q.y + p.y * q.x)
            }
        };
        let solid_angle = 2.0 * atan2(half.y, half.x);
        (MIN_SOLID_ANGLE..=MAX_SOLID_ANGLE)
            .contains(&solid_angle)
            .then_some(View {
                polygon: self,
                frame,
                scale,
                corners: [a, b, c],
                solid_angle,
            })
    }
}

impl View {
    pub(crate) fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// A direction from the origin (not normalized) to a point of the polygon on `plane`,
    /// uniform in solid angle when `u` is uniform in `[0, 1]^2`.
    pub(crate) fn sample(&self, plane: &Plane, origin: DVec3, u: DVec2) -> DVec3 {
        match self.polygon {
            Spherical::Rectangle => self.sample_rectangle(u),
            Spherical::Triangle => onto_triangle(plane, origin, self.sample_triangle(u)),
        }
    }
}

/// `q - origin`, `u` and `v`, scaled exactly (by a power of two) so that the largest
/// coordinate is near 1, or `None` where the samplers would lose their digits. They
/// normalize cross products of these coordinates (and of unit vectors built from them):
/// squares of products of two, which stay normal numbers when the distance to the plane and
/// the edges are at least 2^-240 of the largest coordinate. Shapes past that (an edge 1e-80
/// of the distance, say) are area-sampled. Every vector built from the three can then be
/// normalized directly.
fn scaled_frame(plane: &Plane, origin: DVec3) -> Option<([DVec3; 3], f64)> {
    let d = plane.q() - origin;
    let scale = power_of_two_scale((d.abs() + plane.u().abs() + plane.v().abs()).max_element());
    let [d, u, v] = [d * scale, plane.u() * scale, plane.v() * scale];
    let tiny = f64::from_bits((1023 - 240) << 52); // 2^-240
    let height = d.dot(plane.normal()).abs();
    (height >= tiny && u.length_squared() >= tiny * tiny && v.length_squared() >= tiny * tiny)
        .then_some(([d, u, v], scale))
}

/// Half the solid angle of the triangle with unit corner directions `a`, `b`, `c`, as the
/// argument of `(x, y)`: `tan(omega / 2) = |a.(b x c)| / (1 + a.b + b.c + c.a)` (Van Oosterom
/// and Strackee). The triple product is taken of `b - a` and `c - a`, which are accurate
/// however small the triangle; `atan2(y, x)` keeps angles past a quarter sphere, where the
/// denominator is negative.
fn half_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> DVec2 {
    let volume = a.dot((b - a).cross(c - a)).abs();
    DVec2::new(1.0 + a.dot(b) + b.dot(c) + c.dot(a), volume)
}

impl View {
    /// Ureña et al.: the x coordinate splits the solid angle in the ratio `u.x`, then y is
    /// uniform in the projected height of that column. In a frame with x along `u`, y along
    /// `v` and z toward the rectangle's plane (`z0 < 0`), corners `(x0 or x1, y0 or y1, z0)`.
    fn sample_rectangle(&self, u: DVec2) -> DVec3 {
        let ([d, edge_u, edge_v], scale, solid_angle) = (self.frame, self.scale, self.solid_angle);
        let (exl, eyl) = (edge_u.length(), edge_v.length());
        let (ex, ey) = (edge_u / exl, edge_v / eyl);
        let mut ez = ex.cross(ey);
        let (x0, y0, mut z0) = (d.dot(ex), d.dot(ey), d.dot(ez));
        if z0 > 0.0 {
            z0 = -z0;
            ez = -ez;
        }
        let (x1, y1) = (x0 + exl, y0 + eyl);
        let corner = |x: f64, y: f64| DVec3::new(x, y, z0);
        let normal = |a: DVec3, b: DVec3| a.cross(b).normalize();
        // The normals of the planes through the origin and each edge; the rectangle's internal
        // angles at its third and fourth corners, g2 and g3, are angles between them.
        let (n0, n2) = (
            normal(corner(x0, y0), corner(x1, y0)),
            normal(corner(x1, y1), corner(x0, y1)),
        );
        let n3 = normal(corner(x0, y1), corner(x0, y0));
        let angle = |a: DVec3, b: DVec3| acos((-a).dot(b).clamp(-1.0, 1.0));
        let (b0, b1) = (n0.z, n2.z);
        let k = TAU - angle(n2, n3) - angle(n3, n0);

        let au = u.x * solid_angle + k;
        let (sin_au, cos_au) = sin_cos(au);
        let fu = (cos_au * b0 - b1) / sin_au;
        let cu = (1.0 / sqrt(fu * fu + b0 * b0))
            .copysign(fu)
            .clamp(-1.0, 1.0);
        let xu = (-(cu * z0) / sqrt((1.0 - cu * cu).max(0.0))).clamp(x0, x1);
        let dd = sqrt(xu * xu + z0 * z0);
        let (h0, h1) = (y0 / sqrt(dd * dd + y0 * y0), y1 / sqrt(dd * dd + y1 * y1));
        let hv = h0 + u.y * (h1 - h0);
        let yv = if hv * hv < 1.0 {
            (hv * dd / sqrt(1.0 - hv * hv)).clamp(y0, y1)
        } else {
            y1
        };
        // Back from the scaled frame (exactly): the point's offset from `origin`.
        (xu * ex + yv * ey + z0 * ez) / scale
    }

    /// Arvo: `u.x` picks the sub-triangle `a b c'` with `c'` on the arc from `a` to `c` whose
    /// solid angle is `u.x` of the whole, then `u.y` picks a point on the arc from `b` to `c'`,
    /// uniform in `1 - cos` of its distance from `b`. The direction found is then moved onto the
    /// triangle (clamped into it in `(alpha, beta)`, by [`View::sample`]), so rounding never
    /// aims it past an edge.
    fn sample_triangle(&self, u: DVec2) -> DVec3 {
        let ([a, b, c], solid_angle) = (self.corners, self.solid_angle);
        let unit = DVec3::normalize;
        // The internal angle at a, between the great circles a-b and a-c.
        let (n_ab, n_ac) = (unit(a.cross(b)), unit(a.cross(c)));
        let (cos_alpha, sin_alpha) = (n_ab.dot(n_ac), n_ab.cross(n_ac).length());
        // The sub-triangle's solid angle, less alpha, gives the angle at c' (Arvo's s, t).
        let (sin_area, cos_area) = sin_cos(u.x * solid_angle);
        let s = sin_area * cos_alpha - cos_area * sin_alpha;
        let t = cos_area * cos_alpha + sin_area * sin_alpha;
        let (p, q) = (t - cos_alpha, s + sin_alpha * a.dot(b));
        // cos of the arc from a to c'.
        let cos_ac = ((q * t - p * s) * cos_alpha - q) / ((q * s + p * t) * sin_alpha);
        let cos_ac = if cos_ac.is_nan() {
            1.0
        } else {
            cos_ac.clamp(-1.0, 1.0)
        };
        let c_arc = unit(c - c.dot(a) * a);
        let c_end = cos_ac * a + sqrt(1.0 - cos_ac * cos_ac) * c_arc;
        // 1 - cos of the arc from b to c', as |c' - b|^2 / 2: no cancellation for short arcs;
        // the sampled point's 1 - cos from b is h = u.y of it, and its sine sqrt(h (2 - h)).
        let h = u.y * 0.5 * (c_end - b).length_squared();
        let toward = unit(c_end - c_end.dot(b) * b);
        (1.0 - h) * b + sqrt((h * (2.0 - h)).max(0.0)) * toward
    }
}

/// `direction` from `origin` moved to the nearest point of the triangle in `(alpha, beta)`
/// (a point past the long edge is scaled back onto it), as a vector from `origin`.
fn onto_triangle(plane: &Plane, origin: DVec3, direction: DVec3) -> DVec3 {
    let Some(hit) = plane.intersect(&Ray::new(origin, direction), Interval::FORWARD) else {
        return direction;
    };
    let (alpha, beta) = (hit.alpha.max(0.0), hit.beta.max(0.0));
    let sum = alpha + beta;
    let (alpha, beta) = if sum > 1.0 {
        (alpha / sum, beta / sum)
    } else {
        (alpha, beta)
    };
    (plane.q() - origin) + (alpha * plane.u() + beta * plane.v())
}
