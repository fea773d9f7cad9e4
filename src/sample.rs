//! Next-event estimation: where light is gathered ([`ShadingContext`]) and a point sampled
//! on a light as seen from there ([`LightSample`]), which
//! [`HitRecord::spawn_ray_to`](crate::HitRecord::spawn_ray_to) turns into a shadow ray;
//! and what every light's sampler shares (`reaching`: the retreat toward the middle of the
//! square that keeps the contract's clause 6; unit directions).

use glam::{DVec2, DVec3};

use crate::HitRecord;
#[cfg(doc)]
use crate::PdfHittable;

/// Where a renderer gathers light: a point and, on a surface, its normal (pbrt-v4's
/// `LightSampleContext`). Every light sampler takes one; a [`LightTree`](crate::LightTree)
/// weighs its choices by the cosine at the surface, on either side of it.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::ShadingContext;
///
/// let in_fog = ShadingContext::at(DVec3::new(0.0, 1.0, 0.0));
/// let on_floor = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
/// assert_eq!((in_fog.normal, on_floor.normal), (None, Some(DVec3::Y)));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingContext {
    /// The point being shaded.
    pub point: DVec3,
    /// The geometric normal of the surface there, facing either side (its sign never
    /// changes an answer), or `None` in a medium, where no cosine at a surface weighs the
    /// lights. A normal of length 0 or not finite counts as `None`.
    pub normal: Option<DVec3>,
}

impl ShadingContext {
    /// A point in space (in a medium, say): lights are sampled from every side.
    #[inline]
    #[must_use]
    pub fn at(point: DVec3) -> Self {
        Self {
            point,
            normal: None,
        }
    }

    /// A point on a surface whose normal's line is `normal`, pointing to either side: a
    /// floor's normal may point down and still gather the light above it.
    #[inline]
    #[must_use]
    pub fn on_surface(point: DVec3, normal: DVec3) -> Self {
        Self {
            point,
            normal: Some(normal),
        }
    }

    /// The normal as a unit vector, where it is one.
    #[inline]
    pub(crate) fn unit_normal(&self) -> Option<DVec3> {
        self.normal.and_then(direction_of)
    }
}

/// The hit's point on its geometric normal: a renderer's context for an opaque surface.
impl From<&HitRecord> for ShadingContext {
    #[inline]
    fn from(hit: &HitRecord) -> Self {
        Self::on_surface(hit.point, hit.normal)
    }
}

/// A point sampled on a light from a [`ShadingContext`]
/// ([`PdfHittable::sample_light`]), as pbrt-v4's `ShapeSample` and `LightLiSample`
/// carry it: the direction toward it, its distance, the light's surface there and the
/// density the direction was drawn with.
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{Hittable, PdfHittable, Quad, ShadingContext};
///
/// let lamp = Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0).unwrap();
/// let floor = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
/// let sample = lamp.sample_light(&floor, DVec2::new(0.5, 0.5)).unwrap();
/// assert!((sample.record.point - DVec3::new(0.0, 2.0, 0.0)).length() < 1e-15);
/// assert!((sample.distance - 2.0).abs() < 1e-15 && sample.direction.y > 0.999);
/// assert_eq!(sample.record.normal, DVec3::NEG_Y); // faces the shading point
/// assert_eq!(sample.pdf, lamp.light_pdf(&floor, sample.direction));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// The unit direction from the context's point toward the sampled point.
    pub direction: DVec3,
    /// The distance from the context's point to the sampled point.
    pub distance: f64,
    /// The light's surface at the sampled point, as a ray from the context's point along
    /// `direction` finds it: its point and error bound, its normal (facing the context's
    /// point; `front_face` says whether that is the side the light's outward normal points
    /// to), its material and `uv`. [`HitRecord::spawn_ray_to`] aims a shadow ray at it.
    pub record: HitRecord,
    /// The density over solid angle with which `direction` was drawn
    /// ([`PdfHittable::light_pdf`] from the same context): positive and finite. For a
    /// `delta` sample, which no density draws, what the light's emitted value is divided
    /// by instead: `distance^2 / falloff` times the probability of the pick (see
    /// [`PunctualLight`](crate::PunctualLight)), so that `emitted * cos / pdf` is the
    /// estimate for every kind of light.
    pub pdf: f64,
    /// Which light the sampled point is on: its index in the lights of the
    /// [`LightTree`](crate::LightTree), [`Mixture`](crate::Mixture), slice or `Vec` that
    /// sampled it (through instances and masks around it), 0 for a single light. With
    /// `record` (its `uv`, `primitive` and point), where on it: what a textured emitter's
    /// lookup needs ([`PdfHittable::light_hit`]).
    pub light: usize,
    /// Whether the light is a point, spot or sun ([`PunctualLight`](crate::PunctualLight)),
    /// which no ray finds and no density draws: multiple importance sampling weighs the
    /// sample 1 (no other strategy can find the light), and `pdf` is not a density (see
    /// there). For a sun, `distance` and `record.t` are infinite and `record.point` is the
    /// unit direction toward it; [`HitRecord::spawn_ray_to`] aims a shadow ray to infinity.
    pub delta: bool,
}

/// How far a light's sampler retreats toward the middle of its shape, in turn, when a
/// direction it drew does not reach the shape by the test its density goes by: the first
/// (1, no retreat) is the sample itself, and for every `u` inside `[0, 1)^2` by more than
/// rounding it is the one returned, so the distribution is unchanged but for the few
/// directions that rounding aims just past an edge (a sampler's first point `(0, 0)`, a
/// triangle's corner, a sphere's silhouette), which would have density 0 (the contract's
/// clause 6). Each later factor moves the sample a larger share of the way in; the last
/// (0) aims at the middle itself.
const RETREAT: [f64; 6] = [
    1.0,
    1.0 - 1.0 / (1u64 << 40) as f64,
    1.0 - 1.0 / (1u64 << 24) as f64,
    1.0 - 1.0 / (1u64 << 12) as f64,
    0.5,
    0.0,
];

/// The first of `sample(k)`, for the factors `k` of [`RETREAT`], that `reaches`; the first
/// sample if none does (a shape too small or far to aim at from `origin`, which has
/// density 0 there in every direction), or the zero vector where that is not finite (a
/// sampler's arithmetic past its range: no direction, rather than NaN).
#[inline]
pub(crate) fn reaching(
    mut sample: impl FnMut(f64) -> DVec3,
    reaches: impl Fn(DVec3) -> bool,
) -> DVec3 {
    let first = sample(RETREAT[0]);
    if reaches(first) {
        return first;
    }
    RETREAT[1..]
        .iter()
        .map(|&k| sample(k))
        .find(|&d| reaches(d))
        .unwrap_or(if first.is_finite() {
            first
        } else {
            DVec3::ZERO
        })
}

/// `v` as a unit vector, for any finite, non-zero `v` (scaled first, so that its square
/// neither over- nor underflows); `None` for a zero or non-finite one.
pub(crate) fn direction_of(v: DVec3) -> Option<DVec3> {
    let (unit, length) = crate::math::unit_and_length(v);
    (length > 0.0 && unit.is_finite()).then_some(unit)
}

/// `d` as a unit vector (the zero vector as itself): what every light's
/// `sample_direction` returns, tested for reaching the light after this rounding.
#[inline]
pub(crate) fn unit_direction(d: DVec3) -> DVec3 {
    let squared = d.length_squared();
    if squared.is_normal() && squared < f64::INFINITY {
        // One division for the three components: within an ulp or two of `d / |d|`.
        d * (1.0 / crate::math::sqrt(squared))
    } else if d == DVec3::ZERO || !d.is_finite() {
        d
    } else {
        // A length whose square over- or underflows: scaled first.
        crate::math::unit_and_length(d).0
    }
}

/// `u` moved toward the middle of the unit square by the factor `k` of [`RETREAT`]; `u`
/// itself, bit for bit, for `k = 1`.
#[inline]
pub(crate) fn toward_middle(u: DVec2, k: f64) -> DVec2 {
    if k == 1.0 {
        u
    } else {
        DVec2::splat(0.5) + (u - DVec2::splat(0.5)) * k
    }
}

/// `sample`, a light's own (a [`PunctualLight`](crate::PunctualLight)'s: its
/// `sample_direction` is the zero vector), picked with `probability` as light `index` of
/// a mixture, tree or list: its `pdf` times the pick's; `None` for no sample or one that
/// is not delta (a light that drew the zero vector has no other sample there).
pub(crate) fn delta_pick(
    sample: Option<LightSample>,
    probability: f64,
    index: usize,
) -> Option<LightSample> {
    let sample = sample.filter(|s| s.delta)?;
    let pdf = sample.pdf * probability;
    (pdf > 0.0 && pdf.is_finite()).then_some(LightSample {
        pdf,
        light: index,
        ..sample
    })
}

/// The directions a light emits in, for a [`LightTree`](crate::LightTree)'s importance: a light that faces
/// away from a point is not picked there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Emission {
    /// From every point in every direction (a sphere, or a light whose orientation is not
    /// known): never ruled out by its orientation.
    Everywhere,
    /// From the side of a surface that the given normal points to (a one-sided diffuse
    /// panel): no light behind it.
    OneSide(DVec3),
    /// From both sides of a surface normal to the given vector.
    BothSides(DVec3),
    /// From one side, within `angle` radians of `axis` and nothing beyond (a spot light's
    /// cone, as pbrt-v4 bounds it): at most a right angle wide.
    Cone {
        /// The direction at the cone's middle.
        axis: DVec3,
        /// Its half-angle, in `(0, PI / 2]`.
        angle: f64,
    },
}
