//! The linear part of a [`Transformed`](crate::Transformed) instance, and what it does to
//! hits, boxes and densities: [`Rigid`] (a rotation, whose inverse is its transpose and
//! which changes no length or density) and [`Affine`] (any invertible matrix: scales,
//! non-uniform ones too, shears and mirrors).

use glam::{DMat3, DVec3};

use crate::GeometryError;
use crate::HitRecord;
use crate::math::{UNIT_ROUNDOFF, gamma, power_of_two_scale};
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
    /// `B`, bounding (componentwise) the world image of what taking a point `w` back to
    /// object space errs by, as `B (|w| + |c|)`: see [`Affine::hit_to_world`].
    back: DMat3,
    /// `B`'s largest row sum: how much the bound grows per unit that a spawned origin
    /// lies off the hit's point.
    back_growth: f64,
    /// Bounds `|M A - I|_2`, the right residual: the relative error of `A^T n` as a normal
    /// direction, beside the rounding of computing it.
    residual: f64,
    /// `D` for every normal at once (see [`normal_error`]), or more than 1/16 where only
    /// each normal's own says enough.
    normal_bound: f64,
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
        let first = matrix.inverse();
        if !first.is_finite() || !matrix.determinant().is_normal() {
            return Err(GeometryError::OutOfRange);
        }
        // One step of refinement, `A + A (I - M A)`: the cofactor inverse's right residual
        // `M A - I` reached 64 `k` ulps (for a condition number `k`), and it is what the way
        // back's bound pays; after the step it is about the rounding of computing it. The
        // first is kept where the step does not help (a map near the limit).
        let refined = first + first * (DMat3::IDENTITY - matrix * first);
        let right_sum = |a: DMat3| row_sums((matrix * a - DMat3::IDENTITY).abs()).max_element();
        let inverse = if refined.is_finite() && right_sum(refined) < right_sum(first) {
            refined
        } else {
            first
        };
        let (abs, abs_inverse) = (matrix.abs(), inverse.abs());
        // `rho` bounds `|A M - I|_inf`: the computed residual, plus the rounding of
        // computing it (each entry a sum of three products: gamma(3) |A| |M|), plus one
        // more rounding for evaluating the bound.
        let residual = (inverse * matrix - DMat3::IDENTITY).abs();
        let rho =
            (1.0 + gamma(4)) * row_sums(residual + gamma(3) * (abs_inverse * abs)).max_element();
        if rho.is_nan() || rho >= 0.5 {
            return Err(singular);
        }
        // The right residual `|M A - I|`, bounded as `rho` is (the product `|M| |A|`
        // computed is itself within gamma(3) of the exact one, hence gamma(7) for both);
        // see `hit_to_world` for what `B` bounds.
        let slack = abs * abs_inverse;
        let right =
            (1.0 + gamma(2)) * ((matrix * inverse - DMat3::IDENTITY).abs() + gamma(7) * slack);
        let back = (1.0 + gamma(4)) * (right + UNIT_ROUNDOFF * DMat3::IDENTITY + gamma(3) * slack);
        let scale = power_of_two_scale(abs_inverse.to_cols_array().into_iter().fold(0.0, f64::max));
        let unit_inverse = inverse * scale;
        // `|R|_2 <= sqrt(|R|_1 |R|_inf)`, at most the largest of the row and column sums.
        let two_norm = |m: DMat3| {
            (1.0 + gamma(3))
                * row_sums(m)
                    .max_element()
                    .max(row_sums(m.transpose()).max_element())
        };
        let residual = two_norm(right);
        // For every normal: `|v|_1 <= |n|_1 |A|_inf` and `|t*|_2 >= |n|_2 / |M|_2 >=
        // |n|_1 / (sqrt(3) |M|_2)`, so `|v|_1 / |t*|_2 <= a`; and `|t|_2 >= |t*|_2 (1 -
        // rho_r) - gamma(3) |v|_1`, so `|v|_1 / |t|_2 <= a / (1 - rho_r - gamma(3) a)`.
        let a = (1.0 + gamma(4)) * 1.733 * row_sums(abs_inverse).max_element() * two_norm(abs);
        let room = 1.0 - residual - gamma(3) * a;
        let normal_bound = if room > 0.0 {
            normal_error(residual, (1.0 + gamma(2)) * a / room)
        } else {
            f64::INFINITY
        };
        Ok(Self {
            matrix,
            inverse,
            back,
            back_growth: (1.0 + gamma(3)) * row_sums(back).max_element(),
            residual,
            normal_bound,
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
    /// |M| e`, and the rounding of `P = M p + c`, `gamma(5) (|M| |p| + |c|)`: together `F`.
    /// The way back is what differs, and it is bounded in world space through the right
    /// residual `M A - I`, which makes it `k` ulps of the point for a map of condition `k`
    /// (bounded through `|M| |A - M^-1|`, it was `k^2`).
    ///
    /// **The way back.** A ray spawned from the hit starts at `w`, off `P` along the world
    /// normal `n` by `|n| . E` (`E` this bound), and the object sees it from
    /// `o' = fl(A fl(w - c))`. Against the exact preimage `o = M^-1 (w - c)`, with
    /// `x = fl(w - c)`: `M (o' - o) = (M A - I) x + (x - (w - c)) + M r`, where
    /// `|r| <= gamma(3) |A| |x|` is the product's rounding. So the world image of the
    /// object-space error is at most `(|M A - I| + u I + gamma(3) |M| |A|) |x|`, `B (|w| +
    /// |c|)` with `B` as built (the residual computed, plus `gamma(7) |M| |A|` for its own
    /// rounding and that of `|M| |A|`). `|w|` is `|P|` plus the offset, at most
    /// `|n|_1 |E|_inf`: that part, at most `1.8 b |E|_inf` (`b` the largest row sum of
    /// `B`), is paid with the rest below.
    ///
    /// **The object's side.** The object's record `(p, e, n_o)` is one from which a ray
    /// that starts beyond `p` by `|n_o| . e` along `n_o` does not find its surface again
    /// (the contract's clause 5 in object space). Mapped back, `n_o . (o' - p)` is
    /// `|M^-T n_o|` times the world distance of `w + M (o' - o)` from `P`'s tangent plane
    /// less `P`'s own rounding, along the exact normal `n* = M^-T n_o / |M^-T n_o|`, and
    /// `|n_o| . e <= |M^-T n_o| (|n*| . |M| e)`. So it suffices that the world offset,
    /// measured along `n*`, exceeds `|n*| . Q` with `Q = F + B (|P| + |c|) + 1.8 b |E|_inf`.
    /// The offset is along the computed normal `n`, not `n*`: with `D >= |n - n*|_1` (see
    /// [`normal_error`]: the map's bound for every normal, or this normal's own where that
    /// says too little), `E = Q + 4 D |Q|_inf` pays for it (for `D <= 1/16`,
    /// `(|n*| . E - D |E|_inf) (1 - D) >= |n*| . Q`). Both extra parts together are at
    /// most `(4 b + 5 D) |Q_0|_inf` (for `b, D <= 1/16`), `Q_0` the bound without them,
    /// which is what is added; a map or a normal past those limits (a condition number
    /// past about 2^46) gives `f64::MAX`, a bound that holds but says nothing.
    #[inline(always)]
    fn hit_to_world(&self, hit: HitRecord, translation: DVec3) -> HitRecord {
        let abs = self.matrix.abs();
        let carried = (1.0 + gamma(4)) * (abs * hit.point_error);
        let rounding = gamma(5) * (abs * hit.point.abs() + translation.abs());
        let point = self.matrix * hit.point + translation;
        // `|w| <= (1 + 2u) (|P| + offset) + 2^-900` (spawn_ray's step away), and the
        // evaluation's own rounding: gamma(6) on the product, `2^-899` for the step.
        let back = (1.0 + gamma(6)) * (self.back * (point.abs() + translation.abs()))
            + DVec3::splat(self.back_growth * f64::from_bits((1023 - 899) << 52));
        let near = carried + rounding + back;
        let (normal, normal_error) = if self.normal_bound <= 1.0 / 16.0 {
            (self.normal_to_world(hit.normal), self.normal_bound)
        } else {
            self.normal_to_world_with_error(hit.normal)
        };
        let point_error = if self.back_growth <= 1.0 / 16.0 && normal_error <= 1.0 / 16.0 {
            let grow = 4.0 * self.back_growth + 5.0 * normal_error;
            (1.0 + gamma(4)) * (near + DVec3::splat(grow * near.max_element()))
        } else {
            DVec3::splat(f64::MAX)
        };
        HitRecord {
            point,
            point_error: saturated(point_error),
            normal,
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
        direction_of(self.turned(normal)).unwrap_or(normal)
    }

    /// `A^T n`: the columns of `A` dotted with `n`.
    #[inline]
    fn turned(&self, normal: DVec3) -> DVec3 {
        let a = &self.inverse;
        DVec3::new(
            a.x_axis.dot(normal),
            a.y_axis.dot(normal),
            a.z_axis.dot(normal),
        )
    }

    /// [`Affine::normal_to_world`], and `D`, a bound on the sum of its components' errors
    /// against the exact `M^-T n / |M^-T n|`, for this normal: where the map's own bound
    /// for every normal says too little (a map whose `A^T` may lose most digits of some
    /// normal, but seldom does: a scale of 1e-9 to 1e9 along the axes loses none).
    #[cold]
    #[inline(never)]
    fn normal_to_world_with_error(&self, normal: DVec3) -> (DVec3, f64) {
        let (unit, length) = crate::math::unit_and_length(self.turned(normal));
        if length > 0.0 && unit.is_finite() {
            let (a, n) = (self.inverse.abs(), normal.abs());
            let v = a.x_axis.dot(n) + a.y_axis.dot(n) + a.z_axis.dot(n);
            (unit, normal_error(self.residual, v / length))
        } else {
            (normal, f64::INFINITY)
        }
    }
}

/// `D` for a normal `n` turned to `t = fl(A^T n)`, given `r >= |v|_1 / |t|_2` (`v = |A|^T
/// |n|`) and `rho_r >= |M A - I|_2`. Against `t* = M^-T n`: `t - t* = (M A - I)^T t* + e`,
/// `|e| <= gamma(3) v`, so `|t - t*|_2 <= rho_r |t*|_2 + gamma(3) |v|_1`; relative to
/// `|t*|_2 >= (|t|_2 - gamma(3) |v|_1) / (1 + rho_r)`, that is `eps = rho_r + gamma(3) r
/// (1 + rho_r) / (1 - gamma(3) r)`. Unit vectors of two vectors `eps` apart relatively
/// are `2 eps` apart; normalizing rounds by `gamma(4)` more; and `|.|_1 <= sqrt(3) |.|_2`
/// (1.75 covers the rounding of `D`). Infinite where `r` is too large to say anything.
fn normal_error(residual: f64, ratio: f64) -> f64 {
    let rounded = gamma(3) * ratio;
    let eps = residual + rounded * (1.0 + residual) / (1.0 - rounded);
    let d = 1.75 * (2.0 * eps + gamma(4));
    if d >= 0.0 { d } else { f64::INFINITY }
}
