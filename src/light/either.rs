//! A light of either kind, a surface or a [`PunctualLight`], for a tree or mixture that
//! holds both without a trait object.

use glam::{DVec2, DVec3};

use crate::record::{Found, Made};
use crate::{
    Aabb, Emission, HitRecord, Hittable, Interval, LightSample, PdfHittable, PunctualLight, Ray,
    ShadingContext,
};

/// A light that is a surface (`T`) or a point, spot or sun ([`PunctualLight`]): what a
/// [`LightTree`](crate::LightTree) or [`Mixture`](crate::Mixture) of both kinds holds when
/// its surfaces are all one type, without a `Box<dyn PdfHittable>`'s indirection.
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{Light, LightTree, PdfHittable, PunctualLight, Quad, ShadingContext};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// let panel = Quad::new(DVec3::new(-1.0, 3.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0)?;
/// let bulb = PunctualLight::point(DVec3::new(5.0, 2.0, 0.0))?;
/// let powers = [std::f64::consts::PI * 4.0 * 10.0, bulb.power(20.0)];
/// let lights = LightTree::from_lights(vec![Light::Surface(panel), Light::Punctual(bulb)], &powers)?;
/// let floor = ShadingContext::on_surface(DVec3::new(5.0, 0.0, 0.0), DVec3::Y);
/// // Right under the bulb, the tree picks it more often than the panel.
/// assert!(lights.probability(&floor, 1) > 0.5);
/// let sample = lights.sample_light(&floor, DVec2::new(0.9, 0.5)).unwrap();
/// assert!(sample.delta && sample.light == 1);
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light<T> {
    /// A light with a surface: a shape, a mesh, an instance.
    Surface(T),
    /// A point, spot or sun.
    Punctual(PunctualLight),
}

impl<T: Hittable> Hittable for Light<T> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        match self {
            Light::Surface(s) => s.hit(ray, ray_t),
            Light::Punctual(_) => None,
        }
    }
    #[inline]
    fn bounding_box(&self) -> Aabb {
        match self {
            Light::Surface(s) => s.bounding_box(),
            Light::Punctual(p) => p.bounding_box(),
        }
    }
    #[inline]
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        match self {
            Light::Surface(s) => s.occluded(ray, ray_t),
            Light::Punctual(_) => false,
        }
    }
    #[inline]
    fn find(&self, ray: &Ray, ray_t: Interval, made: &mut Made) -> Option<Found> {
        match self {
            Light::Surface(s) => s.find(ray, ray_t, made),
            Light::Punctual(_) => None,
        }
    }
    #[inline]
    fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
        match self {
            Light::Surface(s) => s.record(ray, ray_t, found),
            Light::Punctual(_) => None,
        }
    }
    #[inline]
    fn mask(&self) -> u32 {
        match self {
            Light::Surface(s) => s.mask(),
            Light::Punctual(p) => p.mask(),
        }
    }
}

impl<T: PdfHittable> PdfHittable for Light<T> {
    #[inline]
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        match self {
            Light::Surface(s) => s.pdf_value(origin, direction),
            Light::Punctual(_) => 0.0,
        }
    }
    #[inline]
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        match self {
            Light::Surface(s) => s.sample_direction(origin, u),
            Light::Punctual(_) => DVec3::ZERO,
        }
    }
    #[inline]
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        match self {
            Light::Surface(s) => s.sample_light(at, u),
            Light::Punctual(p) => p.sample_light(at, u),
        }
    }
    #[inline]
    fn light_pdf(&self, at: &ShadingContext, direction: DVec3) -> f64 {
        match self {
            Light::Surface(s) => s.light_pdf(at, direction),
            Light::Punctual(_) => 0.0,
        }
    }
    #[inline]
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        match self {
            Light::Surface(s) => s.light_hit(ray, ray_t),
            Light::Punctual(_) => None,
        }
    }
    #[inline]
    fn emission(&self) -> Emission {
        match self {
            Light::Surface(s) => s.emission(),
            Light::Punctual(p) => p.emission(),
        }
    }
}
