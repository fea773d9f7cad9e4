//! The book's materials, as one enum: a match is cheaper than a virtual call per bounce.

use std::sync::Arc;

use hitkit::HitRecord;
use hitkit::glam::DVec3;
use rand::RngExt;
use rand::rngs::SmallRng;

use crate::Color;
use crate::texture::Textures;

#[derive(Clone, Debug)]
pub enum Material {
    /// Ideal diffuse reflector with this albedo.
    Lambertian(Color),
    /// Mirror with this albedo, blurred by `fuzz` (0 = perfect).
    Metal(Color, f64),
    /// Clear glass (or water...) with this index of refraction.
    Dielectric(f64),
    /// Emits this radiance from its front face; reflects nothing.
    Light(Color),
    /// Diffuse with the albedo its lookup gives at the hit, emitting what it gives there
    /// (a glTF material: base colour and emission, each a factor times a texture).
    Textured(Arc<dyn Textures>),
}

/// What happens to a ray at a surface.
pub enum Scatter {
    /// Absorbed.
    None,
    /// Continues along one direction, scaled by the attenuation.
    Specular(DVec3, Color),
    /// Diffuse with this albedo: the integrator picks the direction (cosine-weighted, or
    /// by light sampling).
    Diffuse(Color),
}

impl Material {
    /// Light leaving the surface toward the ray.
    #[inline]
    pub fn emitted(&self, hit: &HitRecord) -> Color {
        match self {
            Material::Light(radiance) if hit.front_face => *radiance,
            Material::Textured(textures) => textures.emission(hit),
            _ => Color::ZERO,
        }
    }

    #[inline]
    pub fn scatter(&self, direction: DVec3, hit: &HitRecord, rng: &mut SmallRng) -> Scatter {
        match *self {
            Material::Lambertian(albedo) => Scatter::Diffuse(albedo),
            Material::Textured(ref textures) => Scatter::Diffuse(textures.albedo(hit)),
            Material::Metal(albedo, fuzz) => {
                let reflected =
                    reflect(direction.normalize(), hit.normal) + fuzz * random_unit_vector(rng);
                if reflected.dot(hit.normal) > 0.0 {
                    Scatter::Specular(reflected, albedo)
                } else {
                    Scatter::None
                }
            }
            Material::Dielectric(ior) => {
                let ratio = if hit.front_face { 1.0 / ior } else { ior };
                let unit = direction.normalize();
                let cos = (-unit).dot(hit.normal).min(1.0);
                let sin = (1.0 - cos * cos).sqrt();
                let out = if ratio * sin > 1.0 || reflectance(cos, ratio) > rng.random::<f64>() {
                    reflect(unit, hit.normal)
                } else {
                    refract(unit, hit.normal, ratio, cos)
                };
                Scatter::Specular(out, Color::ONE)
            }
            Material::Light(_) => Scatter::None,
        }
    }
}

#[inline]
fn reflect(v: DVec3, n: DVec3) -> DVec3 {
    v - 2.0 * v.dot(n) * n
}

#[inline]
fn refract(unit: DVec3, n: DVec3, ratio: f64, cos: f64) -> DVec3 {
    let perp = ratio * (unit + cos * n);
    let parallel = -(1.0 - perp.length_squared()).abs().sqrt() * n;
    perp + parallel
}

/// Schlick's approximation.
#[inline]
fn reflectance(cos: f64, ratio: f64) -> f64 {
    let r0 = ((1.0 - ratio) / (1.0 + ratio)).powi(2);
    r0 + (1.0 - r0) * (1.0 - cos).powi(5)
}

/// Uniform on the unit sphere.
#[inline]
pub fn random_unit_vector(rng: &mut SmallRng) -> DVec3 {
    let z = 2.0 * rng.random::<f64>() - 1.0;
    let phi = std::f64::consts::TAU * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = phi.sin_cos();
    DVec3::new(r * c, r * s, z)
}

/// A direction around the unit `normal` with density `cos / pi`, not normalized: `normal`
/// plus a uniform point of the unit sphere (whose sum is cosine-distributed about it), the
/// sphere's point by Marsaglia's method (1972: a uniform point of the unit disk, found by
/// rejection, lifted), so that neither trigonometry nor a frame around the normal (a
/// division) is needed. The sum is never zero: a sphere point at exactly `-normal` (a
/// measure-zero draw) gives `normal` instead.
#[inline]
pub fn cosine_direction(normal: DVec3, rng: &mut SmallRng) -> DVec3 {
    let (x, y, s) = loop {
        let (x, y) = (
            2.0 * rng.random::<f64>() - 1.0,
            2.0 * rng.random::<f64>() - 1.0,
        );
        let s = x * x + y * y;
        if s < 1.0 {
            break (x, y, s);
        }
    };
    let lift = 2.0 * (1.0 - s).sqrt();
    let d = normal + DVec3::new(x * lift, y * lift, 1.0 - 2.0 * s);
    if d == DVec3::ZERO { normal } else { d }
}
