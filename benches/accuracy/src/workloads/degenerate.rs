//! The degenerate workload: rays whose direction is tiny, huge, grazing or zero.

use hitkit::Ray;
use hitkit::glam::DVec3;

use crate::numbers::{short, span};
use crate::workloads::frame::{Frame, QuadSpec, Rng, SEED};

/// What is unusual about a ray of the degenerate workload.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DegenerateKind {
    /// A direction of length `10^k`.
    Length(i32),
    /// A unit direction at this angle (radians) to the plane.
    Grazing(f64),
    /// A zero direction.
    Zero,
}

/// One ray of the degenerate workload, aimed at `quads[quad]`.
#[derive(Clone, Copy, Debug)]
pub struct DegenerateRay {
    pub quad: usize,
    pub ray: Ray,
    pub kind: DegenerateKind,
}

impl DegenerateRay {
    /// Whether the ray meets the quad: it is aimed at a point well inside, unless its
    /// direction is zero.
    pub fn should_hit(&self) -> bool {
        self.kind != DegenerateKind::Zero
    }
}

/// The degenerate workload: rays whose direction is tiny, huge, grazing or zero.
#[derive(Clone, Debug)]
pub struct Degenerate {
    pub quads: Vec<QuadSpec>,
    /// The offset of each quad (all have size 1).
    pub offsets: Vec<f64>,
    pub rays: Vec<DegenerateRay>,
}

/// Decimal exponents of the direction lengths.
pub const DIRECTION_EXPONENTS: [i32; 8] = [-12, -9, -6, -3, 0, 3, 6, 9];
/// Angles (radians) between grazing rays and the plane.
pub const GRAZING_ANGLES: [f64; 6] = [1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12];
/// The offsets (with scale 1) of the degenerate workload's quads.
pub const DEGENERATE_OFFSETS: [f64; 3] = [0.0, 1e3, 1e6];
/// Rays per offset and per direction length or angle.
const DEGENERATE_RAYS: usize = 200;

impl Degenerate {
    /// The workload; `size` scales the number of rays (1.0 for the full run).
    pub fn generate(size: f64) -> Self {
        let mut rng = Rng::new(SEED ^ 2);
        let rays = ((DEGENERATE_RAYS as f64 * size) as usize).max(4);
        let mut workload = Self {
            quads: Vec::new(),
            offsets: Vec::new(),
            rays: Vec::new(),
        };
        for &offset in &DEGENERATE_OFFSETS {
            workload.add_placement(&mut rng, offset, rays);
        }
        workload
    }

    /// A unit square at `offset`, and rays at points well inside it (alpha and beta in
    /// `[0.1, 0.9]`) from one unit away.
    fn add_placement(&mut self, rng: &mut Rng, offset: f64, rays: usize) {
        let frame = Frame::new(rng, offset, 1.0);
        let at = |x: f64, y: f64| frame.point(DVec3::new(x - 0.5, y - 0.5, 0.0));
        let quad = self.quads.len();
        self.quads.push(QuadSpec::from_corners(
            at(0.0, 0.0),
            at(1.0, 0.0),
            at(0.0, 1.0),
        ));
        self.offsets.push(offset);
        let target = |rng: &mut Rng| at(rng.range(0.1, 0.9), rng.range(0.1, 0.9));
        for exponent in DIRECTION_EXPONENTS {
            for _ in 0..rays {
                let p = target(rng);
                let unit = frame.crossing_direction(rng);
                let ray = Ray::new(p - unit, unit * 10f64.powi(exponent));
                self.rays.push(DegenerateRay {
                    quad,
                    ray,
                    kind: DegenerateKind::Length(exponent),
                });
            }
        }
        for angle in GRAZING_ANGLES {
            // Rounding moves the origin by a few ulps of the coordinates, which moves the
            // crossing point by that over the angle: keep angles where it stays within 0.05
            // (the target is at least 0.1 inside).
            let magnitude = (frame.origin.abs().max_element() + 2.0) * 8.0 * f64::EPSILON;
            if magnitude / angle > 0.05 {
                continue;
            }
            for _ in 0..rays {
                let p = target(rng);
                let phi = rng.range(0.0, std::f64::consts::TAU);
                let side = if rng.coin() { 1.0 } else { -1.0 };
                let local = DVec3::new(
                    angle.cos() * phi.cos(),
                    angle.cos() * phi.sin(),
                    -side * angle.sin(),
                );
                let unit = frame.direction(local);
                self.rays.push(DegenerateRay {
                    quad,
                    ray: Ray::new(p - unit, unit),
                    kind: DegenerateKind::Grazing(angle),
                });
            }
        }
        let p = target(rng);
        self.rays.push(DegenerateRay {
            quad,
            ray: Ray::new(p + frame.direction(DVec3::Z), DVec3::ZERO),
            kind: DegenerateKind::Zero,
        });
    }
}

impl Degenerate {
    /// What the workload is, from the constants that build it, for the printed text.
    pub fn describe(&self) -> String {
        let lengths: Vec<f64> = DIRECTION_EXPONENTS.iter().map(|&e| 10f64.powi(e)).collect();
        format!(
            "- **degenerate** ({} rays): unit quads at offsets {offsets}; rays aimed well inside \
             with direction lengths {lengths}, grazing rays at {angles} rad to the plane (where \
             rounding of the origin cannot move the crossing out), and zero directions. \
             **Lost**: a ray that should hit misses.",
            self.rays.len(),
            offsets = DEGENERATE_OFFSETS
                .iter()
                .map(|&x| short(x))
                .collect::<Vec<_>>()
                .join(", "),
            lengths = span(&lengths),
            angles = span(&GRAZING_ANGLES),
        )
    }
}
