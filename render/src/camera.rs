//! The book's camera: vertical field of view, look-from / look-at / up, and a thin lens.

use hitkit::Ray;
use hitkit::glam::DVec3;
use rand::RngExt;
use rand::rngs::SmallRng;

/// How the camera is placed; as in "Ray Tracing in One Weekend".
#[derive(Clone, Copy, Debug)]
pub struct CameraSettings {
    pub width: usize,
    pub height: usize,
    /// Vertical field of view, degrees.
    pub vfov: f64,
    pub lookfrom: DVec3,
    pub lookat: DVec3,
    pub vup: DVec3,
    /// Angle of the cone from a pixel to the lens, degrees; 0 for a pinhole.
    pub defocus_angle: f64,
    /// Distance to the plane in perfect focus.
    pub focus_dist: f64,
    /// Whether the shutter is open from time 0 to 1 (each ray at a random time: motion
    /// blur) rather than an instant at time 0; only scenes with moving objects need it.
    pub shutter: bool,
    /// What the camera's rays see (`Ray::mask`): every bit, unless a scene hides objects
    /// from the camera (`hitkit::Masked`).
    pub mask: u32,
}

/// The camera, set up once per render.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    center: DVec3,
    pixel00: DVec3,
    du: DVec3,
    dv: DVec3,
    defocus_u: DVec3,
    defocus_v: DVec3,
    shutter: bool,
    mask: u32,
}

impl Camera {
    pub fn new(s: &CameraSettings) -> Self {
        let h = (s.vfov.to_radians() / 2.0).tan();
        let viewport_height = 2.0 * h * s.focus_dist;
        let viewport_width = viewport_height * s.width as f64 / s.height as f64;
        let w = (s.lookfrom - s.lookat).normalize();
        let u = s.vup.cross(w).normalize();
        let v = w.cross(u);
        let du = viewport_width * u / s.width as f64;
        let dv = -viewport_height * v / s.height as f64;
        let upper_left = s.lookfrom - s.focus_dist * w - 0.5 * (viewport_width * u)
            + 0.5 * (viewport_height * v);
        let radius = s.focus_dist * (s.defocus_angle.to_radians() / 2.0).tan();
        Self {
            center: s.lookfrom,
            pixel00: upper_left + 0.5 * (du + dv),
            du,
            dv,
            defocus_u: radius * u,
            defocus_v: radius * v,
            shutter: s.shutter,
            mask: s.mask,
        }
    }

    /// A ray through a random point of pixel (i, j), from a random point of the lens when
    /// `LENS`, else from the centre.
    #[inline]
    pub fn ray<const LENS: bool>(&self, i: usize, j: usize, rng: &mut SmallRng) -> Ray {
        let (x, y): (f64, f64) = (rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        let target = self.pixel00 + (i as f64 + x) * self.du + (j as f64 + y) * self.dv;
        let origin = if LENS {
            let p = in_unit_disk(rng);
            self.center + p.x * self.defocus_u + p.y * self.defocus_v
        } else {
            self.center
        };
        let ray = Ray::new(origin, target - origin).with_mask(self.mask);
        // Drawn only with the shutter open, so that still scenes use the same random
        // numbers (and make the same images) as before motion existed.
        if self.shutter {
            ray.at_time(rng.random())
        } else {
            ray
        }
    }
}

fn in_unit_disk(rng: &mut SmallRng) -> DVec3 {
    loop {
        let p = DVec3::new(
            2.0 * rng.random::<f64>() - 1.0,
            2.0 * rng.random::<f64>() - 1.0,
            0.0,
        );
        if p.length_squared() < 1.0 {
            return p;
        }
    }
}
