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

    /// Whether the shape accepts points near its edges that [`Interior::contains`]
    /// rejected, within the rounding error of their coordinates (see
    /// [`Interior::contains_within`]). Default: no.
    #[inline]
    fn widens(&self) -> bool {
        false
    }

    /// Whether `(alpha, beta)` lies within `err_alpha` and `err_beta` of the shape: the
    /// exact intersection could be inside it. Called (when [`Interior::widens`]) for
    /// points that `contains` rejected, with the bounds of
    /// [`Plane::coordinate_error`], so that rays through an edge shared by two shapes
    /// hit one of them. Default: `contains(alpha, beta)`.
    #[inline]
    fn contains_within(&self, alpha: f64, beta: f64, err_alpha: f64, err_beta: f64) -> bool {
        let _ = (err_alpha, err_beta);
        self.contains(alpha, beta)
    }
}

/// A shape tested exactly, without the rounding-error widening of its edges: a little
/// faster where rays often hit planes outside their shapes, but a ray through an edge shared
/// by two shapes may then slip between them. See the README's accuracy table.
///
/// ```
/// use hitkit::{glam::DVec3, Exact, Parallelogram, Quad};
/// let fast = Quad::with_interior(DVec3::ZERO, DVec3::X, DVec3::Y, Exact(Parallelogram)).unwrap();
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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

    #[inline]
    fn widens(&self) -> bool {
        true
    }

    #[inline]
    fn contains_within(&self, alpha: f64, beta: f64, err_alpha: f64, err_beta: f64) -> bool {
        (-err_alpha..=1.0 + err_alpha).contains(&alpha)
            && (-err_beta..=1.0 + err_beta).contains(&beta)
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

    #[inline]
    fn widens(&self) -> bool {
        true
    }

    /// The sum's own rounding (`u_r |alpha + beta|`) is added to the slack.
    #[inline]
    fn contains_within(&self, alpha: f64, beta: f64, err_alpha: f64, err_beta: f64) -> bool {
        let slack = err_alpha + err_beta + gamma(2) * (alpha.abs() + beta.abs());
        alpha >= -err_alpha && beta >= -err_beta && alpha + beta <= 1.0 + slack
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
    fn widens(&self) -> bool {
        true
    }

    #[inline]
    fn contains_within(&self, alpha: f64, beta: f64, err_alpha: f64, err_beta: f64) -> bool {
        nearest_r2(alpha, beta, err_alpha, err_beta) <= 1.0 + gamma(3)
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
    fn widens(&self) -> bool {
        true
    }

    #[inline]
    fn contains_within(&self, alpha: f64, beta: f64, err_alpha: f64, err_beta: f64) -> bool {
        let (a, b) = (alpha.abs() + err_alpha, beta.abs() + err_beta);
        let farthest_r2 = a * a + b * b;
        nearest_r2(alpha, beta, err_alpha, err_beta) <= 1.0 + gamma(3)
            && farthest_r2 >= self.inner * self.inner * (1.0 - gamma(3))
    }

    #[inline]
    fn uv(&self, alpha: f64, beta: f64) -> DVec2 {
        disk_uv(alpha, beta)
    }

    fn bounding_box(&self, plane: &Plane) -> Aabb {
        ellipse_box(plane)
    }
}

/// The smallest `alpha^2 + beta^2` within the errors of the point: each coordinate moved
/// toward 0 by its error (and no further). `gamma(3)` of slack covers the squares and sum.
#[inline]
fn nearest_r2(alpha: f64, beta: f64, err_alpha: f64, err_beta: f64) -> f64 {
    let (a, b) = (
        (alpha.abs() - err_alpha).max(0.0),
        (beta.abs() - err_beta).max(0.0),
    );
    a * a + b * b
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
