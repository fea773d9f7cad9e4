//! The workloads' generator and where their geometry goes: a fixed seed, local shapes
//! rotated, scaled and moved into the world, and lattices whose corners are exact.

use hitkit::glam::{DMat3, DQuat, DVec3};

/// The seed of every workload.
pub const SEED: u64 = 0x5eed;

/// Rays that cross a plane at an angle make a cosine of at least this with its normal.
pub const CROSSING_COSINE: f64 = 0.1;

/// Offsets are along this direction (not an axis, so that every coordinate is large).
const OFFSET_DIRECTION: DVec3 = DVec3::new(1.0, 0.75, -0.5);

/// The shared fixed stream (SplitMix64, as the benches use), with the draws the workloads
/// need.
#[derive(Clone)]
pub struct Rng(hitkit_render::workloads::SplitMix);

impl Rng {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self(hitkit_render::workloads::SplitMix::new(seed))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.uniform() * n as f64) as usize % n
    }

    /// A fair coin.
    pub fn coin(&mut self) -> bool {
        self.next_u64() >> 63 == 1
    }

    /// A uniformly distributed unit vector.
    pub fn unit_vector(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// A unit vector whose z component (the cosine to +z) is uniform in `[lo, hi]`.
    pub fn cone_z(&mut self, lo: f64, hi: f64) -> DVec3 {
        let z = self.range(lo, hi);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// A uniformly distributed rotation (Shoemake's method).
    pub fn rotation(&mut self) -> DMat3 {
        let (u1, u2, u3) = (self.uniform(), self.uniform(), self.uniform());
        let tau = std::f64::consts::TAU;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let q = DQuat::from_xyzw(
            a * (tau * u2).sin(),
            a * (tau * u2).cos(),
            b * (tau * u3).sin(),
            b * (tau * u3).cos(),
        );
        DMat3::from_quat(q.normalize())
    }
}

/// A parallelogram (or triangle) as the book describes it: corner `q`, edges `u` and `v`.
#[derive(Clone, Copy, Debug)]
pub struct QuadSpec {
    pub q: DVec3,
    pub u: DVec3,
    pub v: DVec3,
}

impl QuadSpec {
    /// The shape with corner `q` whose edges run to the corners `a` and `b`.
    pub fn from_corners(q: DVec3, a: DVec3, b: DVec3) -> Self {
        Self {
            q,
            u: a - q,
            v: b - q,
        }
    }
}

/// Where local geometry goes in the world: `origin + rotation * (scale * local)`.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub origin: DVec3,
    pub rotation: DMat3,
    pub scale: f64,
}

impl Frame {
    /// A random rotation, then a move by `offset` along [`OFFSET_DIRECTION`].
    pub fn new(rng: &mut Rng, offset: f64, scale: f64) -> Self {
        Self {
            origin: OFFSET_DIRECTION * offset,
            rotation: rng.rotation(),
            scale,
        }
    }

    /// A local point in world space.
    pub fn point(&self, local: DVec3) -> DVec3 {
        self.origin + self.rotation * (self.scale * local)
    }

    /// A local direction in world space (not scaled).
    pub fn direction(&self, local: DVec3) -> DVec3 {
        self.rotation * local
    }

    /// A random unit direction that crosses the local plane `z = 0` at an angle: its cosine
    /// with the normal is at least [`CROSSING_COSINE`] in size, from either side.
    pub fn crossing_direction(&self, rng: &mut Rng) -> DVec3 {
        let d = rng.cone_z(CROSSING_COSINE, 1.0);
        let d = if rng.coin() { d } else { -d };
        self.direction(d)
    }
}

/// Points `base + i e0 + j e1 + k e2` for small whole `i, j, k`, computed without rounding:
/// the frame's axes (times its scale) are rounded to a grid of a power of two coarse
/// enough that every such sum is a float. Shapes built from these corners close exactly
/// (`q + u + v` is the fourth corner), so a ray through a shared edge meets one of them in
/// exact arithmetic, and only a test's own rounding can let it through.
#[derive(Clone, Copy, Debug)]
pub struct Lattice {
    base: DVec3,
    axes: [DVec3; 3],
}

impl Lattice {
    /// The lattice whose point `(0, 0, 0)` is the frame's local point `local_base` (to
    /// within the grid), for whole coordinates up to `reach` in size.
    pub fn new(frame: &Frame, local_base: DVec3, reach: f64) -> Self {
        // No lattice point (nor partial sum on the way to one) is farther out than this.
        let extent = frame.scale * (local_base.length() + 3f64.sqrt() * reach);
        let magnitude = frame.origin.abs().max_element() + extent;
        // A power of two `grid` with `magnitude < 2^52 grid`: every multiple of it up to
        // `2^53 grid` in size is a float, so the lattice's sums are exact.
        let exponent = magnitude.max(f64::MIN_POSITIVE).log2().floor() as i32 + 1;
        let grid = 2f64.powi(exponent - 52);
        let snap = |v: DVec3| (v / grid).round() * grid;
        Self {
            base: snap(frame.point(local_base)),
            axes: [DVec3::X, DVec3::Y, DVec3::Z].map(|a| snap(frame.rotation * (frame.scale * a))),
        }
    }

    /// The point with whole lattice coordinates `(i, j, k)`.
    pub fn point(&self, i: f64, j: f64, k: f64) -> DVec3 {
        self.base + i * self.axes[0] + j * self.axes[1] + k * self.axes[2]
    }
}

/// Which shape a `(q, u, v)` stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outline {
    /// Corners `q`, `q + u`, `q + u + v`, `q + v`.
    Parallelogram,
    /// Corners `q`, `q + u`, `q + v`.
    Triangle,
}

impl Outline {
    /// The shape's name in the printed text.
    pub fn name(self) -> &'static str {
        match self {
            Outline::Parallelogram => "parallelogram",
            Outline::Triangle => "triangle",
        }
    }

    /// The corners of the shape `s`, in order around `u x v` (the last repeats the first
    /// for a triangle, whose fourth slot is unused: see [`Outline::corner_count`]).
    pub fn corners(self, s: &QuadSpec) -> [DVec3; 4] {
        match self {
            Outline::Parallelogram => [s.q, s.q + s.u, s.q + s.u + s.v, s.q + s.v],
            Outline::Triangle => [s.q, s.q + s.u, s.q + s.v, s.q],
        }
    }

    /// How many of [`Outline::corners`] are corners.
    pub fn corner_count(self) -> usize {
        match self {
            Outline::Parallelogram => 4,
            Outline::Triangle => 3,
        }
    }
}
