//! What the tree knows of a set of lights ([`Cluster`]): their box, their power, the cone of
//! their normals and their exitance; the importance, an estimate of the light they can send
//! to a point (Conty Estevez and Kulla 2018).

use core::f64::consts::{FRAC_PI_2, PI};

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
    /// The cosine of the widest angle from its normal at which any light emits: 0 for a
    /// diffuse one, more for a cone ([`Emission::Cone`]).
    pub(super) cos_emit: f64,
    /// The sum of the lights' exitances (each one's power over the area its box allows
    /// it, per side): a bound on the irradiance the lights can send to any point.
    pub(super) exitance: f64,
    /// The least squared distance the importance divides by: `power / (PI exitance)`
    /// (see [`Cluster::importance`]), or the bounding sphere's squared radius where that
    /// is not a number.
    pub(super) near2: f64,
}

/// `a / (a + b)`, the share of the first of two non-negative weights, where it is a
/// number: `None` where both are 0; an infinite one against a finite one takes all.
#[inline]
pub(super) fn share(a: f64, b: f64) -> Option<f64> {
    let sum = a + b;
    if sum > 0.0 && sum < f64::INFINITY {
        Some(a / sum)
    } else {
        share_rare(a, b)
    }
}

/// [`share`] where the sum is 0, infinite or not a number: apart from the common case, which
/// then compiles to two comparisons and a division (the walk built into a small program of
/// its own picked 20% faster so, with 4% fewer instructions; in `hitkit-peers --halls
/// --picks`, within its noise).
#[cold]
#[inline(never)]
fn share_rare(a: f64, b: f64) -> Option<f64> {
    let sum = a + b;
    if a.is_infinite() || b.is_infinite() {
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
/// and sines (`x`'s sine found only where it is needed: tried without the branch, the sine
/// always found, picks 3% to 10% slower on every hall of `hitkit-peers --halls --picks`).
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
        let (axis, spread, two_sided, cos_emit) = checked(power, emission)?;
        if !bbox.is_bounded() || bbox.is_empty() {
            return Err(GeometryError::InvalidParameter {
                what: "light's bounding box extent",
                value: f64::INFINITY,
                domain: "a bounded, non-empty box",
            });
        }
        // A flat light's area is at most `|(e_y e_z, e_z e_x, e_x e_y)|` for its box's
        // extents `e` (its projections on the axes' planes fit in the box's faces), found
        // scaled by the largest extent so that it overflows only past `f64::MAX`.
        let e = bbox.max() - bbox.min();
        let m = e.max_element();
        let f = e / m;
        let area = m * m * sqrt(DVec3::new(f.x * f.y, f.y * f.z, f.z * f.x).length_squared());
        let sides = if two_sided { 2.0 } else { 1.0 };
        // A light of no area (a point light's box of no extent) has no bound on the
        // irradiance it sends near it: `power / d^2` grows without one.
        let exitance = if area > 0.0 {
            power / (sides * area)
        } else if power > 0.0 {
            f64::INFINITY
        } else {
            0.0
        };
        Ok(Self {
            cos_emit,
            ..Self::with_spread(bbox, power, axis, spread, two_sided, exitance)
        })
    }

    pub(super) fn with_spread(
        bbox: Aabb,
        power: f64,
        axis: DVec3,
        spread: f64,
        two_sided: bool,
        exitance: f64,
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
            cos_emit: 0.0,
            exitance,
            near2: near2(bbox, power, exitance),
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
        let cos_emit = a.cos_emit.min(b.cos_emit);
        let exitance = self.exitance + other.exitance;
        // `b`'s cone inside `a`'s (the wider): the angle between their axes at most the
        // difference of their spreads, compared by cosines, without a trigonometric call
        // (the common case: lights of one normal, and a cone grown to every direction).
        let cos_between = a.axis.dot(b.axis);
        let cos_difference = a.cos_spread * b.cos_spread + a.sin_spread * b.sin_spread;
        let keep_a = Self {
            bbox,
            power,
            two_sided,
            cos_emit,
            exitance,
            near2: near2(bbox, power, exitance),
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
                Self {
                    cos_emit,
                    ..Self::with_spread(bbox, power, axis, spread, two_sided, exitance)
                }
            }
            _ => Self {
                cos_emit,
                ..Self::with_spread(bbox, power, a.axis, PI, two_sided, exitance)
            },
        }
    }

    /// An estimate of the light the cluster sends to `p` (on a surface whose normal's line
    /// is `normal`, where given), after Conty Estevez and Kulla 2018 and pbrt-v4's
    /// `LightBounds::Importance`: its power over the squared distance to its centre, times
    /// a bound on the cosine at which any of its lights can face `p` (0 where every light
    /// faces away), and times a bound on the cosine between the normal's line and any
    /// direction into the cluster (light from either side counts).
    ///
    /// The cosines are bounded by the box itself where every light shares one normal (a
    /// component along a unit vector of a direction from `p` into the box is at most the
    /// box's greatest extent along it from `p` over the distance to the box: tight from
    /// far, where the bounding sphere is loose), and by the bounding sphere otherwise (a
    /// tight bound on the surface's cosine beside a loose one on the lights' lets clusters
    /// whose lights face the point least win: tried on the halls of `hitkit-peers --halls`,
    /// the variance of the choice with lamps seen edge on rose from 0.63 to 0.71; the box's
    /// bound on the lights' cosine beside the sphere's there: 0.626 to 0.625, and 12% to
    /// 24% more time).
    ///
    /// The squared distance is clamped below where power over it would pass `PI` times the
    /// sum of the lights' exitances: no diffuse light sends a point more irradiance than its
    /// exitance (its radiance times `PI`), and `power / (PI d^2)` is the irradiance of the
    /// power at a point `d` away, so the clamp is what the cluster can deliver at all. It
    /// scales with the square of the unit of length, as `d^2` does, so that the choices do
    /// not depend on the unit (pbrt-v4 clamps `d^2` at half the box's diagonal, a length).
    /// `ONE_SIDED`: the surface receives on its normal's side alone (its cosine signed).
    pub(super) fn importance<const ONE_SIDED: bool>(&self, p: DVec3, normal: Option<DVec3>) -> f64 {
        if self.power == 0.0 || (ONE_SIDED && !self.in_front(p, normal)) {
            return 0.0;
        }
        let (min, max) = (self.bbox.min(), self.bbox.max());
        let from_centre = p - (0.5 * min + 0.5 * max);
        let d2 = from_centre.length_squared();
        let (least, seen, d2) = if self.spread == 0.0 {
            self.box_cosines::<ONE_SIDED>(p, normal, d2)
        } else {
            self.sphere_cosines::<ONE_SIDED>(from_centre, d2, normal)
        };
        // Diffuse emitters send nothing at 90 degrees from their normal and beyond, a cone
        // nothing past its angle.
        // (Against a field where it was the constant 0: the edge-on hall's picks 3% slower in
        // `hitkit-peers --halls --picks`, the same with the field an `f32` beside
        // `two_sided`, the node kept at 136 bytes.)
        if least <= self.cos_emit {
            return 0.0;
        }
        let importance = self.power * least * seen / d2.max(self.near2);
        if importance.is_nan() { 0.0 } else { importance }
    }

    /// Whether any point of the cluster's box lies in front of a surface at `p` of normal
    /// `normal` (on its side, or on its plane), with no normal always: the cosine bounds
    /// by the bounding sphere reach past a box wholly behind, which this keeps out.
    #[inline]
    fn in_front(&self, p: DVec3, normal: Option<DVec3>) -> bool {
        let Some(normal) = normal else { return true };
        let (min, max) = (self.bbox.min(), self.bbox.max());
        let farthest = DVec3::select(normal.cmpge(DVec3::ZERO), max, min);
        // The box's farthest corner along the normal against the point, with the two dot
        // products' rounding (`gamma(3)` of their absolute sums each) allowed in the box's
        // favour, so that rounding hides no light.
        let slack = gamma(3) * (normal.abs().dot(farthest.abs()) + normal.abs().dot(p.abs()));
        normal.dot(farthest) + slack >= normal.dot(p)
    }

    /// [`Cluster::importance`]'s two cosines by the box, for lights of one normal, and the
    /// squared distance `d2` (to the box's centre) it divides by: from inside the box, both
    /// cosines 1 and the squared distance at least the squared half-diagonal. There the
    /// lights may lie anywhere in the box, and the distance to its centre says nothing of
    /// theirs: the half-diagonal stands for it (the mean of `1 / d^2` over a ball about `p`
    /// is `3 / r^2`, of its order), so that a point amid a cluster (a wall's receiver among
    /// the wall's own lamps, which send it nothing) does not take its sibling's share.
    #[inline]
    fn box_cosines<const ONE_SIDED: bool>(
        &self,
        p: DVec3,
        normal: Option<DVec3>,
        d2: f64,
    ) -> (f64, f64, f64) {
        let (min, max) = (self.bbox.min(), self.bbox.max());
        let outside = (p - p.clamp(min, max)).length_squared();
        if outside <= 0.0 {
            return (1.0, 1.0, d2.max((0.5 * max - 0.5 * min).length_squared()));
        }
        let over_distance = 1.0 / sqrt(outside);
        // How far the box reaches from `p` along `v`, and against it.
        let reach = |v: DVec3| {
            let positive = v.cmpge(DVec3::ZERO);
            let at = v.dot(p);
            (
                v.dot(DVec3::select(positive, max, min)) - at,
                at - v.dot(DVec3::select(positive, min, max)),
            )
        };
        // `behind`: the most that `p - x` reaches along the lights' normal for a point `x`
        // of the box (where `p` lies in front of a light).
        let (ahead, behind) = reach(self.axis);
        let toward = if self.two_sided {
            ahead.max(behind)
        } else {
            behind
        };
        let least = (toward.max(0.0) * over_distance).min(1.0);
        let seen = normal.map_or(1.0, |n| {
            let (ahead, behind) = reach(n);
            // One-sided: how far the box reaches in front of the surface alone.
            let toward = if ONE_SIDED { ahead } else { ahead.max(behind) };
            (toward.max(0.0) * over_distance).min(1.0)
        });
        (least, seen, d2)
    }

    /// [`Cluster::importance`]'s two cosines by the box's bounding sphere (any direction
    /// from inside it), `from_centre` being `p` less the box's centre and `d2` its square,
    /// and the squared distance to divide by: `d2`, or from inside the box at least the
    /// squared half-diagonal, as [`Cluster::box_cosines`] says.
    #[inline]
    fn sphere_cosines<const ONE_SIDED: bool>(
        &self,
        from_centre: DVec3,
        d2: f64,
        normal: Option<DVec3>,
    ) -> (f64, f64, f64) {
        let (min, max) = (self.bbox.min(), self.bbox.max());
        let half = 0.5 * max - 0.5 * min;
        let radius2 = half.length_squared();
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
        let least = minus_clamped(cos_x, || sin_x, (cos_box, sin_box)).0;
        let seen = normal.map_or(1.0, |n| {
            // The cosine between the normal and the direction from `p` to the box's
            // centre: signed for a one-sided surface, either side's otherwise.
            let cos_in = if ONE_SIDED {
                -toward_p.dot(n)
            } else {
                toward_p.dot(n).abs()
            };
            minus_clamped(cos_in, || sine(cos_in), (cos_box, sin_box))
                .0
                .max(0.0)
        });
        // Inside the box, as for the box's bound (see `box_cosines`).
        let inside = from_centre.abs().cmple(half).all();
        (least, seen, if inside { d2.max(radius2) } else { d2 })
    }
}

/// A light's power and emission checked: its cone of normals (axis, spread), whether it
/// emits on both sides, and the cosine of the widest angle from its normal it emits at.
pub(super) fn checked(
    power: f64,
    emission: Emission,
) -> Result<(DVec3, f64, bool, f64), GeometryError> {
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
    Ok(match emission {
        Emission::Everywhere => (DVec3::Z, PI, false, 0.0),
        Emission::OneSide(normal) => (emission_normal(normal)?, 0.0, false, 0.0),
        Emission::BothSides(normal) => (emission_normal(normal)?, 0.0, true, 0.0),
        Emission::Cone { axis, angle } => {
            if !(angle > 0.0 && angle <= FRAC_PI_2) {
                return Err(GeometryError::InvalidParameter {
                    what: "emission cone angle",
                    value: angle,
                    domain: "(0, PI / 2]",
                });
            }
            let cos = sin_cos(angle).1.max(0.0);
            (emission_normal(axis)?, 0.0, false, cos)
        }
    })
}

/// [`Cluster::near2`] of lights in `bbox` of `power` and summed `exitance`.
fn near2(bbox: Aabb, power: f64, exitance: f64) -> f64 {
    let near2 = power / (PI * exitance);
    if near2.is_finite() {
        near2
    } else {
        (0.5 * bbox.max() - 0.5 * bbox.min()).length_squared()
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
