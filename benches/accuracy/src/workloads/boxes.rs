//! The boxes workload: flat boxes (of axis-aligned squares) near and far from the origin,
//! and rays lying in their slab planes or crossing them, each meeting its square exactly.

use hitkit::Ray;
use hitkit::glam::DVec3;

use crate::numbers::span;
use crate::workloads::frame::{QuadSpec, Rng, SEED};

/// One ray of the boxes workload: it meets `quads[quad]` exactly (by construction), so a box
/// test that rejects the quad's box loses the hit.
#[derive(Clone, Copy, Debug)]
pub struct BoxRay {
    pub quad: usize,
    pub ray: Ray,
    pub kind: BoxRayKind,
}

/// How a ray of the boxes workload meets its square.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoxRayKind {
    /// Lying in the slab plane of an edge (a zero or `-0.0` direction component), crossing
    /// the edge.
    SlabPlane,
    /// Lying in two slab planes, at a corner.
    Corner,
    /// Perpendicular to the square, inside it.
    Perpendicular,
    /// At a slant, inside.
    Slanted,
}

impl BoxRayKind {
    /// A short name for the printed details.
    pub fn label(self) -> &'static str {
        match self {
            BoxRayKind::SlabPlane => "slab-plane rays",
            BoxRayKind::Corner => "corner rays",
            BoxRayKind::Perpendicular => "perpendicular rays",
            BoxRayKind::Slanted => "slanted rays",
        }
    }
}

/// The boxes workload: axis-aligned unit squares (flat boxes) at offsets up to 6e11, and
/// rays lying in their boxes' slab planes (zero and `-0.0` direction components) or
/// crossing them perpendicularly or at a slant.
#[derive(Clone, Debug)]
pub struct Boxes {
    pub quads: Vec<QuadSpec>,
    /// The offset of each square.
    pub offsets: Vec<f64>,
    pub rays: Vec<BoxRay>,
}

/// Offsets of the boxes workload: 6e11 is where the book's 0.0001 padding rounds away.
pub const BOX_OFFSETS: [f64; 5] = [0.0, 1.0, 1e3, 1e6, 6e11];
/// Squares per offset and normal axis.
const BOX_QUADS: usize = 100;
/// Rays per square of each kind (slab plane of an edge, corner, perpendicular, slanted).
const BOX_RAYS_PER_KIND: usize = 8;

/// A signed zero, either sign.
fn signed_zero(rng: &mut Rng) -> f64 {
    if rng.coin() { 0.0 } else { -0.0 }
}

impl Boxes {
    /// The workload; `size` scales the number of squares (1.0 for the full run).
    pub fn generate(size: f64) -> Self {
        let mut rng = Rng::new(SEED ^ 3);
        let quads = ((BOX_QUADS as f64 * size) as usize).max(2);
        let mut workload = Self {
            quads: Vec::new(),
            offsets: Vec::new(),
            rays: Vec::new(),
        };
        for &offset in &BOX_OFFSETS {
            for axis in 0..3 {
                for _ in 0..quads {
                    workload.add_square(&mut rng, offset, axis);
                }
            }
        }
        workload
    }

    /// A unit square with its normal along `axis`, corners on a grid of quarters near
    /// `offset` (exact at every offset used), and rays that meet it exactly.
    fn add_square(&mut self, rng: &mut Rng, offset: f64, axis: usize) {
        let (b, e) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut grid = || offset + 0.25 * (rng.below(17) as f64 - 8.0);
        let mut q = DVec3::ZERO;
        q[axis] = grid();
        q[b] = grid();
        q[e] = grid();
        let (mut u, mut v) = (DVec3::ZERO, DVec3::ZERO);
        u[b] = 1.0;
        v[e] = 1.0;
        let quad = self.quads.len();
        self.quads.push(QuadSpec { q, u, v });
        self.offsets.push(offset);

        // A ray from two units off the plane (on a random side) to the point `p` of the
        // square, along `d_b`, `d_e` in the plane: `d_b = ±0` keeps it in the slab plane
        // through `p`.
        let mut push = |rng: &mut Rng, kind, p_b: f64, p_e: f64, d_b: f64, d_e: f64| {
            let side = if rng.coin() { 1.0 } else { -1.0 };
            let mut origin = DVec3::ZERO;
            let mut direction = DVec3::ZERO;
            origin[axis] = q[axis] + 2.0 * side;
            direction[axis] = -side;
            origin[b] = p_b - 2.0 * d_b;
            origin[e] = p_e - 2.0 * d_e;
            direction[b] = d_b;
            direction[e] = d_e;
            self.rays.push(BoxRay {
                quad,
                ray: Ray::new(origin, direction),
                kind,
            });
        };
        for _ in 0..BOX_RAYS_PER_KIND {
            // In the slab plane of an edge (along b or along e), crossing the edge.
            let edge = q[b] + if rng.coin() { 1.0 } else { 0.0 };
            let along = q[e] + rng.range(0.1, 0.9);
            let slope = if rng.coin() {
                signed_zero(rng)
            } else {
                rng.range(-0.5, 0.5)
            };
            let zero = signed_zero(rng);
            if rng.coin() {
                push(rng, BoxRayKind::SlabPlane, edge, along, zero, slope);
            } else {
                let edge_e = q[e] + (edge - q[b]);
                let along_b = q[b] + (along - q[e]);
                push(rng, BoxRayKind::SlabPlane, along_b, edge_e, slope, zero);
            }
        }
        for _ in 0..BOX_RAYS_PER_KIND {
            // At a corner, lying in two slab planes.
            let corner_b = q[b] + if rng.coin() { 1.0 } else { 0.0 };
            let corner_e = q[e] + if rng.coin() { 1.0 } else { 0.0 };
            let (zero_b, zero_e) = (signed_zero(rng), signed_zero(rng));
            push(rng, BoxRayKind::Corner, corner_b, corner_e, zero_b, zero_e);
        }
        for _ in 0..BOX_RAYS_PER_KIND {
            // Perpendicular, inside.
            let (p_b, p_e) = (q[b] + rng.range(0.1, 0.9), q[e] + rng.range(0.1, 0.9));
            let (zero_b, zero_e) = (signed_zero(rng), signed_zero(rng));
            push(rng, BoxRayKind::Perpendicular, p_b, p_e, zero_b, zero_e);
        }
        for _ in 0..BOX_RAYS_PER_KIND {
            // Slanted, inside.
            let (p_b, p_e) = (q[b] + rng.range(0.1, 0.9), q[e] + rng.range(0.1, 0.9));
            let (d_b, d_e) = (rng.range(-0.5, 0.5), rng.range(-0.5, 0.5));
            push(rng, BoxRayKind::Slanted, p_b, p_e, d_b, d_e);
        }
    }
}

impl Boxes {
    /// What the workload is, from the constants that build it, for the printed text.
    pub fn describe(&self) -> String {
        format!(
            "- **boxes** ({} rays): axis-aligned unit squares (flat boxes) at offsets {offsets}, \
             rays lying in their boxes' slab planes with 0 and -0.0 direction components (across \
             an edge, at a corner), perpendicular and slanted. **Lost**: hitkit's quad test \
             accepts the square, the box test rejects its box.",
            self.rays.len(),
            offsets = span(&BOX_OFFSETS),
        )
    }
}
