//! The book's constant medium (*Ray Tracing: The Next Week*, "Volumes"), written the way a
//! renderer on hitkit writes it: copy it into your own renderer.
//!
//! It implements `hit` alone and draws its scattering distance inside it. hitkit's
//! containers (lists, `Bvh` and trees in trees, `Transformed`, `Moving`) ask such a shape
//! once per query, so the distance drawn is the distance reported: the fog is not biased
//! toward its surface, as it is in a container that calls `hit` again for the record.

use hitkit::custom::Made;
use hitkit::glam::DVec3;
use hitkit::{Aabb, HitRecord, Hittable, Interval, MaterialId, Ray};

/// A medium of constant density inside a closed, convex `boundary` (a sphere, a box): a
/// ray that enters it scatters after an exponentially distributed distance, of mean
/// `1 / density`, or passes through. The hit's normal is arbitrary (an isotropic medium
/// has none) and its `front_face` true.
///
/// `uniform` gives the random number in `(0, 1]` for a query: from the ray alone (the
/// examples hash it, so that a render is the same on any number of threads), or from any
/// generator that is `Sync`.
pub struct ConstantMedium<B, U> {
    boundary: B,
    neg_inv_density: f64,
    material: MaterialId,
    uniform: U,
}

impl<B: Hittable, U: Fn(&Ray) -> f64 + Send + Sync> ConstantMedium<B, U> {
    pub fn new(boundary: B, density: f64, material: MaterialId, uniform: U) -> Self {
        Self {
            boundary,
            neg_inv_density: -1.0 / density,
            material,
            uniform,
        }
    }
}

impl<B: Hittable, U: Fn(&Ray) -> f64 + Send + Sync> Hittable for ConstantMedium<B, U> {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        // Where the ray enters the boundary (perhaps behind its origin) and where it
        // leaves: the exit is found from the entry by a ray spawned there, which does not
        // find the surface it leaves (no 0.0001 as in the book). Of the exit only `t` is
        // read: `find` leaves its record (a sphere's `uv`: an `acos` and an `atan2`) unmade.
        let entry = self.boundary.hit(ray, Interval::UNIVERSE)?;
        let inside = entry.spawn_ray(ray.direction);
        let exit = self
            .boundary
            .find(&inside, Interval::FORWARD, &mut Made::new())?;
        let (enter_t, exit_t) = (entry.t.max(ray_t.min), (entry.t + exit.t).min(ray_t.max));
        if enter_t >= exit_t {
            return None;
        }
        let length = ray.direction.length();
        let distance_inside = (exit_t - enter_t) * length;
        let hit_distance = self.neg_inv_density * (self.uniform)(ray).ln();
        if hit_distance > distance_inside {
            return None;
        }
        let t = enter_t + hit_distance / length;
        Some(
            HitRecord::new(ray, t, ray.at(t), -ray.direction.normalize())
                .with_material(self.material),
        )
    }

    fn bounding_box(&self) -> Aabb {
        self.boundary.bounding_box()
    }
}

/// A number in `(0, 1]` from the ray's bits (SplitMix64's finalizer over them): the same
/// ray gives the same number, different rays independent ones.
pub fn hash_uniform(ray: &Ray) -> f64 {
    let bits = |v: DVec3| [v.x, v.y, v.z].map(f64::to_bits);
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for word in bits(ray.origin)
        .into_iter()
        .chain(bits(ray.direction))
        .chain([ray.time.to_bits()])
    {
        h = mix(h ^ word);
    }
    ((h >> 11) as f64 + 1.0) / (1u64 << 53) as f64
}

fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
