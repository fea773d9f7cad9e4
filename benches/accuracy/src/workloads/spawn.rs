//! The spawn workload: hits on large quads far from the origin, and the rays spawned from
//! them, toward nothing and toward a second quad a hair away.

use hitkit::Ray;
use hitkit::glam::DVec3;

use crate::numbers::{short, span};
use crate::workloads::frame::{Frame, QuadSpec, Rng, SEED};

/// How far above a surface the second surface of the spawn workload lies, relative to the
/// first surface's size.
pub const SPAWN_GAP: f64 = 4e-5;

/// The spawn workload's `(offset, size)` pairs: every pair of these offsets and sizes whose
/// gap (`SPAWN_GAP * size`) is at least `MIN_GAP * offset`, hundreds of ulps of the offset,
/// so that the two surfaces are apart by much more than the rounding of their coordinates.
pub const SPAWN_OFFSETS: [f64; 5] = [0.0, 1e3, 1e6, 1e9, 1e12];
pub const SPAWN_SIZES: [f64; 4] = [1e-2, 1.0, 1e2, 1e4];
pub const MIN_GAP: f64 = 1e-13;

/// One case of the spawn workload: a ray from below hits `floor`; a ray spawned from that
/// hit along `reflected` (back down) should hit nothing, one along `transmitted` (up) should
/// hit `ceiling`, which lies `SPAWN_GAP` times the floor's size above it.
#[derive(Clone, Copy, Debug)]
pub struct SpawnCase {
    /// The index of the floor and the ceiling in [`Spawn::pairs`].
    pub pair: usize,
    pub primary: Ray,
    pub reflected: DVec3,
    pub transmitted: DVec3,
}

/// The spawn workload: large quads far from the origin, hits on them, and secondary rays.
#[derive(Clone, Debug)]
pub struct Spawn {
    /// `[floor, ceiling]`, one pair per placement.
    pub pairs: Vec<[QuadSpec; 2]>,
    pub cases: Vec<SpawnCase>,
    /// The `(offset, size)` of each pair.
    pub placements: Vec<(f64, f64)>,
}

/// Primary rays per spawn placement.
const SPAWN_RAYS: usize = 2_000;

impl Spawn {
    /// The workload; `size` scales the number of rays (1.0 for the full run).
    pub fn generate(size: f64) -> Self {
        let mut rng = Rng::new(SEED ^ 1);
        let rays = ((SPAWN_RAYS as f64 * size) as usize).max(10);
        let mut spawn = Self {
            pairs: Vec::new(),
            cases: Vec::new(),
            placements: Vec::new(),
        };
        for &size in &SPAWN_SIZES {
            for &offset in &SPAWN_OFFSETS {
                if SPAWN_GAP * size >= MIN_GAP * offset {
                    spawn.add_placement(&mut rng, offset, size, rays);
                }
            }
        }
        spawn
    }

    /// A floor (a square of side `size`), a slightly larger ceiling `SPAWN_GAP * size` above
    /// it, and `rays` cases hitting the floor from `size` below, well inside its edges.
    fn add_placement(&mut self, rng: &mut Rng, offset: f64, size: f64, rays: usize) {
        let frame = Frame::new(rng, offset, size);
        let square = |half: f64, z: f64| {
            let at = |x: f64, y: f64| frame.point(DVec3::new(x, y, z));
            QuadSpec::from_corners(at(-half, -half), at(half, -half), at(-half, half))
        };
        let pair = self.pairs.len();
        // The ceiling overhangs by 0.01: transmitted rays (cosine >= 0.05) travel at most
        // 20 gaps sideways on their way up.
        self.pairs.push([square(0.5, 0.0), square(0.51, SPAWN_GAP)]);
        self.placements.push((offset, size));
        for _ in 0..rays {
            let (x, y) = (rng.range(-0.45, 0.45), rng.range(-0.45, 0.45));
            let target = frame.point(DVec3::new(x, y, 0.0));
            let start = DVec3::new(x + rng.range(-0.3, 0.3), y + rng.range(-0.3, 0.3), -1.0);
            let origin = frame.point(start);
            self.cases.push(SpawnCase {
                pair,
                primary: Ray::new(origin, target - origin),
                reflected: frame.direction(-rng.cone_z(0.0, 1.0)),
                transmitted: frame.direction(rng.cone_z(0.05, 1.0)),
            });
        }
    }
}

impl Spawn {
    /// What the workload is, from the constants that build it, for the printed text.
    pub fn describe(&self) -> String {
        format!(
            "- **spawn** ({} hits, two spawned rays each): a square quad of size S under a \
             random rotation, hit from below, and a second one {gap} S above it, at offsets \
             {offsets} and sizes {sizes} (every pair where the gap, {gap} S, is at least \
             {min_gap} of the offset: hundreds of ulps). From each hit, a random direction back \
             down (should hit nothing) and one up (should hit the quad above). **Self-hit**: a \
             spawned ray hits the quad it left; **lost**: the upward ray misses the quad above \
             (or the first hit is missed).",
            self.cases.len(),
            gap = short(SPAWN_GAP),
            offsets = span(&SPAWN_OFFSETS),
            sizes = span(&SPAWN_SIZES),
            min_gap = short(MIN_GAP),
        )
    }
}
