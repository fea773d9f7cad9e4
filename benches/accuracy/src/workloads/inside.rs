//! Rays of a render's kind at the edges workload's boxes: through the faces' insides, away
//! from their edges, for the quad rows' second timing (the typical ray of a render, beside
//! the watertight test's worst case at edges).

use hitkit::Ray;
use hitkit::glam::DVec3;

use crate::workloads::edges::Group;
use crate::workloads::frame::{Rng, SEED};

/// Rays per box for the timing on rays through faces' insides.
pub const INSIDE_RAYS: usize = 20_000;

/// Where the rays start: this many box edges from the box's centre, in a random direction.
pub const INSIDE_FROM: f64 = 3.0;
/// Where they aim: a random point within this many box edges of the centre.
pub const INSIDE_WITHIN: f64 = 0.35;

/// The boxes of `group` with rays of a render's kind instead: from `INSIDE_FROM s` away in a
/// random direction (`s` the box's edge) toward a random point within `INSIDE_WITHIN s` of its
/// centre, so that they enter through a face's inside, almost all of them well away from its
/// edges.
pub fn inside_rays(group: &Group) -> Group {
    let mut rng = Rng::new(SEED ^ 0x1a5);
    let mut rays = Vec::with_capacity(group.targets.len() * INSIDE_RAYS);
    for (i, faces) in group.targets.iter().enumerate() {
        let n = faces.len() as f64;
        let centre = faces
            .iter()
            .fold(DVec3::ZERO, |c, f| c + (f.q + 0.5 * (f.u + f.v)) / n);
        let size = faces[0].u.length();
        for _ in 0..INSIDE_RAYS {
            let origin = centre + INSIDE_FROM * size * rng.unit_vector();
            let target = centre + INSIDE_WITHIN * size * rng.uniform() * rng.unit_vector();
            rays.push((i, Ray::new(origin, target - origin)));
        }
    }
    Group {
        targets: group.targets.clone(),
        placements: group.placements.clone(),
        rays,
    }
}

/// What these rays are, from the constants that build them, for the printed text.
pub fn describe() -> String {
    format!(
        "{INSIDE_RAYS} rays per box from {INSIDE_FROM} box sizes away toward random points \
         within {INSIDE_WITHIN} box sizes of its centre"
    )
}
