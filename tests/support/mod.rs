//! What several test files share: the rounding bound, a fixed random stream (the one the
//! benches use), and a set of lights.
#![allow(dead_code)]

pub mod distance;
#[path = "scene.rs"]
mod scene;

#[allow(unused_imports)] // not every test file uses it
pub use scene::SplitMix;

/// `gamma(k) = k u / (1 - k u)`, `u` the unit roundoff: bounds `k` chained roundings.
pub fn gamma(k: u32) -> f64 {
    let nu = f64::from(k) * f64::EPSILON * 0.5;
    nu / (1.0 - nu)
}

/// Four lights of every kind, around the origin: a unit square 2 above it (sampled by solid
/// angle from nearby), a disk to one side, a triangle below and a sphere to the other side.
pub fn four_lights() -> Vec<Box<dyn hitkit::PdfHittable>> {
    use hitkit::glam::DVec3;
    use hitkit::{Disk, Quad, Sphere, Triangle};
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    vec![
        Box::new(Quad::new(DVec3::new(-1.0, 2.0, -1.0), x, z).unwrap()),
        Box::new(Quad::with_interior(DVec3::new(1.5, 1.0, 0.0), 0.5 * y, 0.5 * z, Disk).unwrap()),
        Box::new(Quad::with_interior(DVec3::new(0.0, -2.0, 1.0), x, z, Triangle).unwrap()),
        Box::new(Sphere::new(DVec3::new(-2.0, 0.0, 0.0), 0.5).unwrap()),
    ]
}

/// The closest hit of a list and its position, ties at equal `t` going to the earlier
/// object: what a `Bvh` must return.
pub fn brute_force<T: hitkit::Hittable>(
    objects: &[T],
    ray: &hitkit::Ray,
    ray_t: hitkit::Interval,
) -> Option<(usize, hitkit::HitRecord)> {
    let mut best: Option<(usize, hitkit::HitRecord)> = None;
    for (i, o) in objects.iter().enumerate() {
        if let Some(h) = o.hit(ray, ray_t)
            && best.is_none_or(|(_, b)| h.t < b.t)
        {
            best = Some((i, h));
        }
    }
    best
}
