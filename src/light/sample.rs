//! Next-event estimation: where light is gathered ([`ShadingContext`]) and a point sampled
//! on a light as seen from there ([`LightSample`]), which
//! [`HitRecord::spawn_ray_to`](crate::HitRecord::spawn_ray_to) turns into a shadow ray.

use glam::DVec3;

use crate::{HitRecord, Interval, PdfHittable, Ray};

/// Where a renderer gathers light: a point and, on a surface, its normal (pbrt-v4's
/// `LightSampleContext`). Every light sampler takes one; a [`LightTree`](crate::LightTree)
/// picks no light wholly below the surface's horizon.
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
    /// The geometric normal of the surface there (either side), or `None` in a medium or
    /// on a surface that transmits light (where lights below the horizon still count). A
    /// normal of length 0 or not finite counts as `None`.
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

    /// A point on an opaque surface facing `normal` (either side of it).
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
        self.normal.and_then(crate::light::direction_of)
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
    /// ([`PdfHittable::light_pdf`] from the same context): positive and finite.
    pub pdf: f64,
}

impl LightSample {
    /// The sample along `direction` from `at`: the first surface of `light` there, and the
    /// light's density of the direction. `None` where the direction finds no surface of
    /// the light (a zero direction, a sample rounding aimed past an edge) or has density 0.
    ///
    /// What [`PdfHittable::sample_light`] returns for a direction its sampler drew; a light
    /// that draws directions its own way (as [`LightTree`](crate::LightTree) does, by the
    /// context's normal) ends with it.
    #[must_use]
    pub fn along<L: PdfHittable + ?Sized>(
        light: &L,
        at: &ShadingContext,
        direction: DVec3,
    ) -> Option<Self> {
        Self::along_with(light, at, direction, |d| light.light_pdf(at, d))
    }

    /// [`LightSample::along`] with the density of the direction (as it is kept) from `pdf`.
    pub(crate) fn along_with<L: PdfHittable + ?Sized>(
        light: &L,
        at: &ShadingContext,
        direction: DVec3,
        pdf: impl FnOnce(DVec3) -> f64,
    ) -> Option<Self> {
        // Unit directions (what hitkit's lights return) are kept bit for bit, so that the
        // density is the one of the very direction the sampler tested to reach the light.
        let length = crate::math::length(direction);
        let direction = if (length - 1.0).abs() <= 4.0 * f64::EPSILON {
            direction
        } else {
            direction / length
        };
        let ray = Ray::new(at.point, direction);
        if !ray.is_valid() {
            return None;
        }
        let record = light.hit(&ray, Interval::FORWARD)?;
        let pdf = pdf(direction);
        let distance = record.t;
        (pdf > 0.0 && pdf.is_finite() && distance.is_finite()).then_some(Self {
            direction,
            distance,
            record,
            pdf,
        })
    }
}
