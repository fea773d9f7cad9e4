//! What the tree knows of a set of lights ([`Cluster`]): their box, their power and the cone
//! of their normals; the importance, a bound on the light they can send to a point (Conty
//! Estevez and Kulla 2018), and whether they lie wholly below a surface's horizon.

use core::f64::consts::PI;

use glam::DVec3;

use super::Emission;
use crate::math::{atan2, gamma, length, sin_cos, sqrt};
use crate::sample::direction_of;
use crate::{Aabb, GeometryError};

/// What the importance knows of a set of lights.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cluster {
    pub(super) bbox: Aabb,
    pub(super) power: f64,
    /// Every light's normal lies within the angle `spread` of `axis` (`spread = PI`: any
    /// direction).
    pub(super) axis: DVec3,
    pub(super) spread: f64,
    /// `spread`'s cosine and sine.
    pub(super) cos_spread: f64,
    pub(super) sin_spread: f64,
    /// Whether a light emits on both sides of its normal.
    pub(super) two_sided: bool,
}

/// `a / (a + b)`, the share of the first of two non-negative weights, where it is a
/// number: `None` where both are 0; an infinite one against a finite one takes all.
#[inline]
pub(super) fn share(a: f64, b: f64) -> Option<f64> {
    let sum = a + b;
    if sum > 0.0 && sum.is_finite() {
        Some(a / sum)
    } else if a.is_infinite() || b.is_infinite() {
        Some(match (a.is_infinite(), b.is_infinite()) {
            (true, true) => 0.5,
            (true, false) => 1.0,
            _ => 0.0,
        })
    } else if sum.is_infinite() {
        // Two finite weights whose sum overflows: halved, they do not.
        Some(0.5 * a / (0.5 * a + 0.5 * b))
    } else {
        None
    }
}

/// `(cos, sin)` of `max(0, x - y)` for angles `x` and `y` in `[0, PI]` given by their cosines
/// and sines (`x`'s sine found only where it is needed).
#[inline]
pub(super) fn minus_clamped(
    cos_x: f64,
    sin_x: impl FnOnce() -> f64,
    (cos_y, sin_y): (f64, f64),
) -> (f64, f64) {
    if cos_x >= cos_y {
        (1.0, 0.0)
    } else {
        let sin_x = sin_x();
        (cos_x * cos_y + sin_x * sin_y, sin_x * cos_y - cos_x * sin_y)
    }
}

/// The sine of an angle in `[0, PI]` from its cosine.
#[inline]
pub(super) fn sine(cos: f64) -> f64 {
    sqrt((1.0 - cos * cos).max(0.0))
}

impl Cluster {
    /// One light's bounds.
    pub(super) fn of(bbox: Aabb, power: f64, emission: Emission) -> Result<Self, GeometryError> {
        if !power.is_finite() {
            return Err(GeometryError::NonFinite { what: "power" });
        }
        if power < 0.0 {
            return Err(GeometryError::InvalidParameter {
                what: "power",
                value: power,
                domain: "[0, infinity)",
            });
        }
        if !bbox.is_bounded() || bbox.is_empty() {
            return Err(GeometryError::InvalidParameter {
                what: "light's bounding box extent",
                value: f64::INFINITY,
                domain: "a bounded, non-empty box",
            });
        }
        let (axis, spread, two_sided) = match emission {
            Emission::Everywhere => (DVec3::Z, PI, false),
            Emission::OneSide(normal) => (emission_normal(normal)?, 0.0, false),
            Emission::BothSides(normal) => (emission_normal(normal)?, 0.0, true),
        };
        Ok(Self::with_spread(bbox, power, axis, spread, two_sided))
    }

    pub(super) fn with_spread(
        bbox: Aabb,
        power: f64,
        axis: DVec3,
        spread: f64,
        two_sided: bool,
    ) -> Self {
        let (sin_spread, cos_spread) = sin_cos(spread);
        Self {
            bbox,
            power,
            axis,
            spread,
            cos_spread,
            sin_spread: sin_spread.max(0.0),
            two_sided,
        }
    }

    /// The bounds of two clusters' lights together. A cluster of no power adds its box
    /// only: its orientation never matters.
    pub(super) fn union(&self, other: &Self) -> Self {
        let bbox = self.bbox.union(&other.bbox);
        let power = self.power + other.power;
        let (a, b) = match (self.power > 0.0, other.power > 0.0) {
            (true, false) | (false, false) => (self, self),
            (false, true) => (other, other),
            (true, true) if self.spread >= other.spread => (self, other),
            (true, true) => (other, self),
        };
        let two_sided = a.two_sided || b.two_sided;
        // `b`'s cone inside `a`'s (the wider): the angle between their axes at most the
        // difference of their spreads, compared by cosines, without a trigonometric call
        // (the common case: lights of one normal, and a cone grown to every direction).
        let cos_between = a.axis.dot(b.axis);
        let cos_difference = a.cos_spread * b.cos_spread + a.sin_spread * b.sin_spread;
        let keep_a = Self {
            bbox,
            power,
            two_sided,
            ..*a
        };
        if a.spread >= PI || cos_between >= cos_difference {
            return keep_a;
        }
        // The cone around both cones: `a`'s turned toward `b`'s just enough.
        let between = atan2(length(a.axis.cross(b.axis)), cos_between);
        if (between + b.spread).min(PI) <= a.spread {
            return keep_a;
        }
        let spread = 0.5 * (a.spread + between + b.spread);
        let turn_about = a.axis.cross(b.axis).try_normalize();
        match turn_about {
            Some(k) if spread < PI => {
                // Rodrigues' rotation of `a.axis` about `k` (normal to it) by `spread -
                // a.spread`.
                let (sin, cos) = sin_cos(spread - a.spread);
                let axis = (a.axis * cos + k.cross(a.axis) * sin).normalize();
                Self::with_spread(bbox, power, axis, spread, two_sided)
            }
            _ => Self::with_spread(bbox, power, a.axis, PI, two_sided),
        }
    }

    /// A bound on the light the cluster sends to `p` (on a surface facing `normal`, where
    /// given): its power over the squared distance to its centre (no nearer than its
    /// radius), times the cosine of the least angle at which any of its lights can face
    /// `p`, and times the cosine of the least angle between `normal` and any direction
    /// into the cluster's box; 0 where the first passes 90 degrees (every light faces
    /// away) or the second does (the box lies below the horizon).
    pub(super) fn importance(&self, p: DVec3, normal: Option<DVec3>) -> f64 {
        if self.power == 0.0 {
            return 0.0;
        }
        let (min, max) = (self.bbox.min(), self.bbox.max());
        let centre = 0.5 * min + 0.5 * max;
        let radius2 = (0.5 * max - 0.5 * min).length_squared();
        let from_centre = p - centre;
        let d2 = from_centre.length_squared();
        // The cone of directions from `p` into the box's bounding sphere (which holds the
        // box): all of them from inside it.
        let (cos_box, sin_box) = if d2 <= radius2 {
            (-1.0, 0.0)
        } else {
            let sin2 = radius2 / d2;
            (sqrt(1.0 - sin2), sqrt(sin2))
        };
        let toward_p = if d2 > 0.0 {
            from_centre / sqrt(d2)
        } else {
            self.axis
        };
        // The least angle between a light's normal and a direction from the box to `p`.
        let mut cos_normal = self.axis.dot(toward_p);
        if self.two_sided {
            cos_normal = cos_normal.abs();
        }
        let spread = (self.cos_spread, self.sin_spread);
        let (cos_x, sin_x) = minus_clamped(cos_normal, || sine(cos_normal), spread);
        let least = minus_clamped(cos_x, || sin_x, (cos_box, sin_box));
        // Diffuse emitters send nothing at 90 degrees from their normal and beyond.
        if least.0 <= 0.0 {
            return 0.0;
        }
        let mut importance = self.power * least.0 / d2.max(radius2);
        if let Some(n) = normal {
            // Below the horizon by the box itself: its bounding sphere can reach above the
            // horizon where no light does.
            if self.below(p, n) {
                return 0.0;
            }
            // The bound on the cosine by the sphere; where rounding puts even the sphere
            // below while the box is not, no bound.
            let cos_in = (-toward_p).dot(n);
            let (cos_seen, _) = minus_clamped(cos_in, || sine(cos_in), (cos_box, sin_box));
            if cos_seen > 0.0 {
                importance *= cos_seen;
            }
        }
        if importance.is_nan() { 0.0 } else { importance }
    }

    /// Whether the box lies wholly below the horizon of a surface at `p` facing `n` (unit):
    /// its corner farthest along `n` lies below the plane through `p`, by more than the
    /// rounding of the test (the difference, the products and the sums: `gamma(4)` of the
    /// terms' magnitudes) and of `n`'s normalization (a tilt of a few ulps, `gamma(4)` of
    /// the distance again), so that a box touching or crossing the plane never counts.
    #[inline]
    pub(super) fn below(&self, p: DVec3, n: DVec3) -> bool {
        let corner = DVec3::select(n.cmpge(DVec3::ZERO), self.bbox.max(), self.bbox.min());
        let rel = corner - p;
        n.dot(rel) < -gamma(8) * rel.abs().element_sum()
    }
}

/// An emission normal as a unit vector, or the reason it cannot be one: any finite,
/// non-zero vector is a normal, however long or short.
pub(super) fn emission_normal(normal: DVec3) -> Result<DVec3, GeometryError> {
    if !normal.is_finite() {
        return Err(GeometryError::NonFinite {
            what: "emission normal",
        });
    }
    direction_of(normal).ok_or(GeometryError::ZeroVector {
        what: "emission normal",
    })
}
