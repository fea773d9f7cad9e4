//! Interior predicates: which points `q + alpha u + beta v` of a plane belong to a shape.

use glam::{DVec2, DVec3};

use crate::math::{gamma, sqrt};
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
/// assert!(quad.hit(&through_hole, Interval::new(0.0, f64::INFINITY)).is_none());
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
}

impl<F: Fn(f64, f64) -> bool + Send + Sync> Interior for F {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        self(alpha, beta)
    }
}

/// The parallelogram `0 <= alpha <= 1, 0 <= beta <= 1` with corners `q`, `q + u`,
/// `q + v`, `q + u + v`. `uv = (alpha, beta)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Parallelogram;

impl Interior for Parallelogram {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        (0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta)
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        let (q, u, v) = (plane.q(), plane.u(), plane.v());
        Aabb::from_points(&[q, q + u, q + v, q + u + v]).grown(corner_rounding(plane))
    }
}

/// The triangle `alpha >= 0, beta >= 0, alpha + beta <= 1` with corners `q`, `q + u`,
/// `q + v`. `uv = (alpha, beta)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Triangle;

impl Interior for Triangle {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        alpha >= 0.0 && beta >= 0.0 && alpha + beta <= 1.0
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
pub struct Disk;

impl Interior for Disk {
    #[inline]
    fn contains(&self, alpha: f64, beta: f64) -> bool {
        alpha * alpha + beta * beta <= 1.0
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
    fn uv(&self, alpha: f64, beta: f64) -> DVec2 {
        disk_uv(alpha, beta)
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        ellipse_box(plane)
    }
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
