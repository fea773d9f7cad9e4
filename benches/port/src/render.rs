//! A renderer as the book's Rust ports write one: a camera, materials by id, a recursive
//! `ray_color` with the third volume's mixture of a light and a cosine density. One thread.
//! It drives either geometry through [`Backend`], which says how a ray is traced and how
//! the next one starts: from the hit point with `t_min = 0.001` (the book), or by
//! `spawn_ray` (hitkit).

use std::f64::consts::PI;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{HitRecord, Hittable, Interval, PdfHittable, Ray};

use crate::naive::{self, Span, T_MIN};
use crate::scenes::{self, Color, Material, Scene};

/// What the renderer asks of the geometry.
pub trait Backend {
    fn hit(&self, ray: &Ray) -> Option<HitRecord>;
    fn spawn(&self, hit: &HitRecord, direction: DVec3) -> Ray;
    fn light_pdf(&self, origin: DVec3, direction: DVec3) -> f64;
    fn light_sample(&self, origin: DVec3, u: DVec2) -> DVec3;
}

pub struct Naive {
    world: naive::List,
    lights: naive::List,
}

impl Naive {
    pub fn new(scene: &Scene) -> Self {
        Self {
            world: naive::List(scene.world.iter().map(scenes::naive).collect()),
            lights: naive::List(scene.lights.iter().map(scenes::naive).collect()),
        }
    }
}

impl Backend for Naive {
    fn hit(&self, ray: &Ray) -> Option<HitRecord> {
        use naive::Hittable;
        self.world.hit(
            ray,
            Span {
                min: T_MIN,
                max: f64::INFINITY,
            },
        )
    }
    fn spawn(&self, hit: &HitRecord, direction: DVec3) -> Ray {
        Ray::new(hit.point, direction).at_time(hit.time)
    }
    fn light_pdf(&self, origin: DVec3, direction: DVec3) -> f64 {
        naive::Hittable::pdf_value(&self.lights, origin, direction)
    }
    fn light_sample(&self, origin: DVec3, u: DVec2) -> DVec3 {
        naive::Hittable::random(&self.lights, origin, u)
    }
}

pub struct Hitkit {
    world: Vec<Box<dyn Hittable>>,
    lights: Vec<Box<dyn PdfHittable>>,
}

impl Hitkit {
    pub fn new(scene: &Scene) -> Self {
        Self {
            world: scene.world.iter().map(scenes::hitkit).collect(),
            lights: scene
                .lights
                .iter()
                .map(|l| scenes::hitkit_light(l, scene.area_lights))
                .collect(),
        }
    }
}

impl Backend for Hitkit {
    fn hit(&self, ray: &Ray) -> Option<HitRecord> {
        self.world.hit(ray, Interval::FORWARD)
    }
    fn spawn(&self, hit: &HitRecord, direction: DVec3) -> Ray {
        hit.spawn_ray(direction)
    }
    fn light_pdf(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.lights.pdf_value(origin, direction)
    }
    fn light_sample(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.lights.sample_direction(origin, u)
    }
}

/// xorshift64*, seeded per pixel: the same streams on both sides.
pub struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn unit_vector(&mut self) -> DVec3 {
        let z = 2.0 * self.f() - 1.0;
        let phi = 2.0 * PI * self.f();
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

fn reflect(v: DVec3, n: DVec3) -> DVec3 {
    v - 2.0 * v.dot(n) * n
}

fn ray_color<B: Backend>(b: &B, scene: &Scene, ray: &Ray, depth: u32, rng: &mut Rng) -> Color {
    if depth == 0 {
        return Color::ZERO;
    }
    let Some(rec) = b.hit(ray) else {
        return scene.background;
    };
    let next = |dir: DVec3, rng: &mut Rng| ray_color(b, scene, &b.spawn(&rec, dir), depth - 1, rng);
    match scene.materials[rec.material.0 as usize] {
        Material::Light(c) => {
            if rec.front_face {
                c
            } else {
                Color::ZERO
            }
        }
        Material::Lambertian(albedo) => {
            let cosine = rec.normal + rng.unit_vector();
            let cosine = if cosine.length_squared() < 1e-16 {
                rec.normal
            } else {
                cosine
            };
            if scene.lights.is_empty() {
                return albedo * next(cosine, rng);
            }
            let dir = if rng.f() < 0.5 {
                b.light_sample(rec.point, DVec2::new(rng.f(), rng.f()))
            } else {
                cosine
            };
            let cos = dir.normalize().dot(rec.normal);
            if cos.is_nan() || cos <= 0.0 {
                return Color::ZERO; // the Lambertian density is 0 there
            }
            let pdf = 0.5 * cos / PI + 0.5 * b.light_pdf(rec.point, dir);
            albedo * (cos / PI) * next(dir, rng) / pdf
        }
        Material::Metal(albedo, fuzz) => {
            let dir = reflect(ray.direction, rec.normal).normalize() + fuzz * rng.unit_vector();
            if dir.dot(rec.normal) > 0.0 {
                albedo * next(dir, rng)
            } else {
                Color::ZERO
            }
        }
        Material::Dielectric(ior) => {
            let ri = if rec.front_face { 1.0 / ior } else { ior };
            let unit = ray.direction.normalize();
            let cos = (-unit).dot(rec.normal).min(1.0);
            let sin = (1.0 - cos * cos).sqrt();
            let r0 = ((1.0 - ri) / (1.0 + ri)).powi(2);
            let reflectance = r0 + (1.0 - r0) * (1.0 - cos).powi(5);
            let dir = if ri * sin > 1.0 || reflectance > rng.f() {
                reflect(unit, rec.normal)
            } else {
                let perp = ri * (unit + cos * rec.normal);
                perp - (1.0 - perp.length_squared()).abs().sqrt() * rec.normal
            };
            next(dir, rng)
        }
        Material::Isotropic(albedo) => albedo * next(rng.unit_vector(), rng),
    }
}

/// The render's mean luminance and its standard error (from each pixel's sample variance).
pub struct Render {
    pub mean: f64,
    pub standard_error: f64,
}

pub fn render<B: Backend>(b: &B, scene: &Scene) -> Render {
    let n = scene.width;
    let (mut sum, mut variance) = (0.0, 0.0);
    for j in 0..n {
        for i in 0..n {
            let mut rng = Rng::new((j * n + i) as u64 + 1);
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..scene.samples {
                let x = (i as f64 + rng.f()) / n as f64;
                let y = (j as f64 + rng.f()) / n as f64;
                let ray = scene.camera.ray(x, y, rng.f());
                let c = ray_color(b, scene, &ray, scene.depth, &mut rng);
                let l = c.dot(DVec3::new(0.2126, 0.7152, 0.0722));
                // (A NaN sample counts as black, as a port's image writer shows it.)
                let l = if l.is_finite() { l } else { 0.0 };
                s += l;
                s2 += l * l;
            }
            let k = scene.samples as f64;
            let mean = s / k;
            sum += mean;
            variance += (s2 / k - mean * mean).max(0.0) / (k - 1.0).max(1.0);
        }
    }
    let pixels = (n * n) as f64;
    Render {
        mean: sum / pixels,
        standard_error: variance.sqrt() / pixels,
    }
}
