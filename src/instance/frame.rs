//! The linear part of a [`Transformed`](crate::Transformed) instance, and what it does to
//! hits, boxes and densities: [`Rigid`] (a rotation, whose inverse is its transpose and
//! which changes no length or density) and [`Affine`] (any invertible matrix: scales,
//! non-uniform ones too, shears and mirrors).

use glam::{DMat3, DVec3};

use crate::GeometryError;
use crate::HitRecord;
use crate::math::{gamma, power_of_two_scale};
use crate::sample::direction_of;

/// What a [`Transformed`](crate::Transformed) instance's linear part does to the object's
/// rays, hits and densities: [`Rigid`] or [`Affine`]. Sealed: hitkit implements it, a
/// renderer names it only as `Transformed`'s second parameter.
pub trait Frame: Copy + core::fmt::Debug + PartialEq + Send + Sync + sealed::Sealed {
    /// A world-space vector (a direction, or a point less the translation) in object space.
    #[doc(hidden)]
    fn to_object(&self, v: DVec3) -> DVec3;

    /// An object-space vector in world space.
    #[doc(hidden)]
    fn to_world(&self, v: DVec3) -> DVec3;

    /// `|M|`, the absolute values of the object-to-world matrix's entries.
    #[doc(hidden)]
    fn abs(&self) -> DMat3;

    /// An object-space hit's point, its error bound and normals in world space, for the
    /// instance moved by `translation` (`t` is the same in both spaces). An error bound
    /// past `f64`'s range is `f64::MAX` ([`saturated`]): the same hit, whichever query
    /// asks, and nothing infinite.
    #[doc(hidden)]
    fn hit_to_world(&self, hit: HitRecord, translation: DVec3) -> HitRecord;

    /// The object's `density` over solid angle for the direction that is `direction` in
    /// world space, as a density over world-space solid angle: finite, and positive where
    /// `density` is.
    #[doc(hidden)]
    fn density_to_world(&self, density: f64, direction: DVec3) -> f64;

    /// An object-space direction in world space, of unit length where the object's is, and
    /// without overflow; the zero vector for a zero direction.
    #[doc(hidden)]
    fn direction_to_world(&self, local: DVec3) -> DVec3;
}

/// An error bound within `f64`'s range: `f64::MAX` where it overflowed (a map of extreme
/// condition, a hit far along the ray), still a bound on a finite point's error.
#[inline]
fn saturated(error: DVec3) -> DVec3 {
    error.min(DVec3::splat(f64::MAX))
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Rigid {}
    impl Sealed for super::Affine {}
}

/// A rotation: the linear part of a rigid [`Transformed`](crate::Transformed) (its
/// default), built by [`Transformed::new`](crate::Transformed::new),
/// [`rotate_y`](crate::Transformed::rotate_y) and
/// [`translate`](crate::Transformed::translate). Lengths, `t` and densities over solid
/// angle are unchanged by it, and quarter turns are exact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rigid {
    /// Object to world.
    pub(crate) rotation: DMat3,
    /// World to object: the transpose, the inverse of a rotation.
    inverse: DMat3,
}

impl Rigid {
    pub(crate) fn new(rotation: DMat3) -> Self {
        Self {
            rotation,
            inverse: rotation.transpose(),
        }
    }
}

impl Frame for Rigid {
    #[inline]
    fn to_object(&self, v: DVec3) -> DVec3 {
        self.inverse * v
    }

    #[inline]
    fn to_world(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    #[inline]
    fn abs(&self) -> DMat3 {
        self.rotation.abs()
    }

    /// The point's error bound: the object's bound `e` is carried through the rotation as
    /// `|R| e`, and computing `R p + t` adds its own rounding. Each coordinate of `R p + t`
    /// is a sum of three products and `t`: every term is rounded at most 4 times (one
    /// product, three sums), so the error is at most `gamma(4) (|R| |p| + |t|)`
    /// componentwise (Higham 3.1). One more rounding each, `(1 + gamma(4))` on the carried
    /// part and `gamma(5)` on the new one, covers the evaluation of the bound itself.
    ///
    /// And the way back: a ray spawned from the hit is moved into the object's space
    /// again, `R^T (p - t)`, which rounds its origin by `gamma(4) |R^T| (|p| + |t|)` there,
    /// `|R| |R^T| <= 1` (every entry, by Cauchy-Schwarz) times that in world space, so at
    /// most `gamma(5)` of `|p| + |t|` summed over the axes on each. Without it the origin
    /// could land back on the surface's inner side, and the object find the surface the
    /// ray leaves (the contract's clause 5).
    #[inline]
    fn hit_to_world(&self, hit: HitRecord, translation: DVec3) -> HitRecord {
        let abs = self.rotation.abs();
        let carried = (1.0 + gamma(4)) * (abs * hit.point_error);
        let rounding = gamma(5) * (abs * hit.point.abs() + translation.abs());
        let point = self.rotation * hit.point + translation;
        let back = gamma(5) * (point.abs() + translation.abs()).element_sum();
        HitRecord {
            point,
            point_error: saturated(carried + rounding + DVec3::splat(back)),
            // Unit length to within a few ulps: the rotation is orthonormal to rounding.
            normal: self.rotation * hit.normal,
            shading_normal: self.rotation * hit.shading_normal,
            ..hit
        }
    }

    #[inline]
    fn density_to_world(&self, density: f64, _direction: DVec3) -> f64 {
        density
    }

    #[inline]
    fn direction_to_world(&self, local: DVec3) -> DVec3 {
        let direction = self.rotation * local;
        if direction.is_finite() {
            direction
        } else {
            // A rotation can lengthen a component by up to sqrt(3): a quarter of a finite
            // direction turns without overflow, and points the same way.
            let quarter = self.rotation * (0.25 * local);
            if quarter.is_finite() {
                quarter
            } else {
                DVec3::ZERO
            }
        }
    }
}

/// Any invertible linear map: the linear part of a [`Transformed`](crate::Transformed)
/// built by [`Transformed::affine`](crate::Transformed::affine) or
/// [`scale`](crate::Transformed::scale), with scales (uniform or not), shears and mirrors.
///
/// `t` is the same in both spaces (a ray `o + t d` maps to `A (o - c) + t A d`, the
/// object's direction not normalized), normals go by the inverse transpose (facing
/// against the ray still, and outward still under a mirror), and a density over solid
/// angle is the object's times `|det A| / |A w|^3` for the world direction `w` (the
/// Jacobian of the map between the two spheres of directions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    /// `M`, object to world.
    matrix: DMat3,
    /// `A`, world to object: `M`'s inverse as computed, which is not exact.
    inverse: DMat3,
    /// `|M| |A|`, rounded up: what carries the rounding of a point taken back to object
    /// space into world space.
    back: DMat3,
    /// `|M|` times the bound on `|(A - M^-1) v|` for `|v|_inf = 1`: the part of taking a
    /// point back that comes from `A` not being `M^-1` exactly, in world space.
    inexact: DVec3,
    /// `A` scaled by a power of two to entries near 1, and its determinant's magnitude,
    /// for densities: the scale cancels in `|det A| / |A w|^3`, and neither over- nor
    /// underflows.
    unit_inverse: DMat3,
    unit_det: f64,
}

impl Affine {
    /// The frame of `matrix` (object to world).
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite entry;
    /// [`GeometryError::InvalidParameter`] for a matrix that is singular or so nearly so
    /// that its computed inverse times it is not within 1/2 of the identity (a condition
    /// number past about 2^50), where no error bound through it would mean anything;
    /// [`GeometryError::OutOfRange`] where its determinant or inverse over- or underflows.
    pub(crate) fn new(matrix: DMat3) -> Result<Self, GeometryError> {
        if !matrix.is_finite() {
            return Err(GeometryError::NonFinite { what: "transform" });
        }
        let largest = matrix.abs().to_cols_array().into_iter().fold(0.0, f64::max);
        // The determinant of the matrix scaled (exactly) to entries near 1 says whether it
        // is singular; the matrix's own can over- or underflow where it is not.
        let det = (matrix * power_of_two_scale(largest)).determinant();
        let singular = GeometryError::InvalidParameter {
            what: "transform's determinant (scaled to entries near 1)",
            value: det,
            domain: "an invertible matrix, its inverse computable to within 1/2",
        };
        if det == 0.0 {
            return Err(singular);
        }
        let inverse = matrix.inverse();
        if !inverse.is_finite() || !matrix.determinant().is_normal() {
            return Err(GeometryError::OutOfRange);
        }
        let (abs, abs_inverse) = (matrix.abs(), inverse.abs());
        // `rho` bounds `|A M - I|_inf`: the computed residual, plus the rounding of
        // computing it (each entry a sum of three products: gamma(3) |A| |M|), plus one
        // more rounding for evaluating the bound.
        let residual = (inverse * matrix - DMat3::IDENTITY).abs();
        let slack = abs_inverse * abs;
        let rho = (1.0 + gamma(4)) * row_sums(residual + gamma(3) * slack).max_element();
        if rho.is_nan() || rho >= 0.5 {
            return Err(singular);
        }
        // `M^-1 = (A M)^-1 A`, and `|(A M)^-1|_inf <= 1 / (1 - rho)`; so
        // `|(A - M^-1) v|_inf <= |A M - I|_inf |M^-1|_inf |v|_inf <= k |v|_inf`, doubled
        // for the rounding of `k` itself.
        let k = 2.0 * rho / (1.0 - rho) * row_sums(abs_inverse).max_element();
        let scale = power_of_two_scale(abs_inverse.to_cols_array().into_iter().fold(0.0, f64::max));
        let unit_inverse = inverse * scale;
        Ok(Self {
            matrix,
            inverse,
            back: (1.0 + gamma(4)) * (abs * abs_inverse),
            inexact: k * row_sums(abs),
            unit_inverse,
            unit_det: unit_inverse.determinant().abs(),
        })
    }

    /// The matrix, object to world.
    #[must_use]
    pub(crate) fn matrix(&self) -> DMat3 {
        self.matrix
    }
}

/// Each row's sum.
fn row_sums(m: DMat3) -> DVec3 {
    m * DVec3::ONE
}

impl Frame for Affine {
    #[inline]
    fn to_object(&self, v: DVec3) -> DVec3 {
        self.inverse * v
    }

    #[inline]
    fn to_world(&self, v: DVec3) -> DVec3 {
        self.matrix * v
    }

    #[inline]
    fn abs(&self) -> DMat3 {
        self.matrix.abs()
    }

    /// The point's error bound, as [`Rigid`]'s: the object's bound carried, `(1 + gamma(4))
    /// |M| e`, and the rounding of `M p + c`, `gamma(5) (|M| |p| + |c|)`. The way back
    /// differs: a spawned ray's origin `w` goes to `A (w - c)`, rounded by
    /// `gamma(4) |A| (|w| + |c|)` and off by `(A - M^-1) (w - c)` besides (`A` is not the
    /// exact inverse); both are object-space errors, `|M|` times them in world space.
    ///
    /// That a world-space bound is enough on the object's side too: the hit point lies
    /// within the box `E` of the world surface, so the spawned origin, offset by
    /// `|N| . E` along the normal `N`, lies beyond the surface's tangent plane; the map to
    /// object space keeps it beyond the object's (an affine map keeps a plane's sides),
    /// and taking it there moves it by an error whose world image `|M|` bounds.
    #[inline]
    fn hit_to_world(&self, hit: HitRecord, translation: DVec3) -> HitRecord {
        let abs = self.matrix.abs();
        let carried = (1.0 + gamma(4)) * (abs * hit.point_error);
        let rounding = gamma(5) * (abs * hit.point.abs() + translation.abs());
        let point = self.matrix * hit.point + translation;
        let magnitude = point.abs() + translation.abs();
        let back = gamma(5) * (self.back * magnitude)
            + (1.0 + gamma(2)) * self.inexact * magnitude.max_element();
        HitRecord {
            point,
            point_error: saturated(carried + rounding + back),
            normal: self.normal_to_world(hit.normal),
            shading_normal: self.normal_to_world(hit.shading_normal),
            ..hit
        }
    }

    /// Times `|det A| / |A w|^3` for the unit direction `w`, with `A` scaled to entries
    /// near 1 (the scale cancels): the ratio lies between `|det| / sigma_max^3` and
    /// `|det| / sigma_min^3` of that `A`, which the bound on its condition keeps normal.
    #[inline]
    fn density_to_world(&self, density: f64, direction: DVec3) -> f64 {
        if density == 0.0 {
            return 0.0;
        }
        let Some(unit) = direction_of(direction) else {
            return 0.0;
        };
        let length = crate::math::length(self.unit_inverse * unit);
        let density = density * (self.unit_det / (length * length * length));
        // A density near f64's end can overflow here; the largest finite one stands in.
        if density.is_nan() {
            0.0
        } else {
            density.min(f64::MAX)
        }
    }

    #[inline]
    fn direction_to_world(&self, local: DVec3) -> DVec3 {
        // Scaled to a unit first, so that `M` cannot overflow it.
        direction_of(local)
            .and_then(|unit| direction_of(self.matrix * unit))
            .unwrap_or(DVec3::ZERO)
    }
}

impl Affine {
    /// A unit normal of the object's in world space: by the inverse transpose, which keeps
    /// it square to the surface, against the ray, and outward under a mirror too.
    #[inline]
    fn normal_to_world(&self, normal: DVec3) -> DVec3 {
        // `A^T n`: the columns of `A` dotted with `n`.
        let a = &self.inverse;
        let turned = DVec3::new(
            a.x_axis.dot(normal),
            a.y_axis.dot(normal),
            a.z_axis.dot(normal),
        );
        direction_of(turned).unwrap_or(normal)
    }
}
