//! The grazing workload: rays aimed at points of a shape's plane just outside it, arriving
//! along the plane or from far away, where a test widened by a bound that grows as
//! `1 / |n.d|` reports hits beside the shape.

use hitkit::Ray;
use hitkit::glam::DVec3;

use crate::numbers::{decades, short};
use crate::workloads::edges::{
    FAR_EXPONENTS, PLACEMENTS, START_DISTANCE, far_distance, ray_through,
};
use crate::workloads::frame::{CROSSING_COSINE, Frame, Outline, QuadSpec, Rng, SEED};

/// Shapes of each kind (parallelogram, triangle) per placement.
pub const SHAPES_PER_KIND: usize = 4;
/// The lengths of `u` and `v`, in scale units: uniform in this range.
pub const EDGE_LENGTHS: (f64, f64) = (0.5, 1.5);
/// The angle between `u` and `v`, in degrees: uniform in this range.
pub const UV_ANGLES: (f64, f64) = (20.0, 160.0);
/// Targets lie `10^k` scale units outside the shape, `k` uniform in this range.
pub const OUTSIDE_EXPONENTS: (f64, f64) = (-12.0, -1.0);
/// One target in this many lies past a corner; the others beside an edge.
pub const PAST_CORNER_ONE_IN: usize = 4;
/// Grazing rays rise or fall `10^k` per unit along the plane, `k` uniform in this range.
pub const SLOPE_EXPONENTS: (f64, f64) = (-15.0, -1.0);
/// Grazing rays per placement (spread over its shapes).
const GRAZING_RAYS: usize = 8_000;
/// Rays from far away per placement.
const FAR_RAYS: usize = 2_000;

/// How a ray of the grazing workload comes to its target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Approach {
    /// Along the plane, at a slope, from a few scale units away.
    Grazing,
    /// From far away, crossing the plane at an angle.
    Afar,
}

impl Approach {
    /// A short name for the printed details.
    pub fn label(self) -> &'static str {
        match self {
            Approach::Grazing => "grazing",
            Approach::Afar => "from afar",
        }
    }
}

/// One shape of the workload.
#[derive(Clone, Copy, Debug)]
pub struct GrazingShape {
    pub spec: QuadSpec,
    pub outline: Outline,
    /// The `(offset, scale)` it stands at.
    pub placement: (f64, f64),
}

/// One ray, aimed at a point outside `shapes[shape]`.
#[derive(Clone, Copy, Debug)]
pub struct GrazingRay {
    pub shape: usize,
    pub ray: Ray,
    pub approach: Approach,
}

/// The grazing workload.
#[derive(Clone, Debug)]
pub struct Grazing {
    pub shapes: Vec<GrazingShape>,
    pub rays: Vec<GrazingRay>,
}

/// A point of the plane of `s` outside it by `distance` (as rounding allows): beside an edge
/// (a point of the edge moved out along the plane, square to the edge) or past a corner (the
/// corner moved out along a direction between its two edges' outward normals).
fn outside_point(rng: &mut Rng, s: &QuadSpec, outline: Outline, distance: f64) -> DVec3 {
    let corners = outline.corners(s);
    let count = outline.corner_count();
    let n = s.u.cross(s.v).normalize();
    // Corners go around u x v: the outward normal of the edge from a to b is (b - a) x n.
    let outward = |i: usize| {
        let (a, b) = (corners[i % count], corners[(i + 1) % count]);
        (b - a).cross(n).normalize()
    };
    let i = rng.below(count);
    if rng.below(PAST_CORNER_ONE_IN) == 0 {
        // Corner i + 1, between edge i (ending there) and edge i + 1 (starting there).
        let k = rng.uniform();
        let away = ((1.0 - k) * outward(i) + k * outward(i + 1)).normalize();
        corners[(i + 1) % count] + distance * away
    } else {
        let (a, b) = (corners[i], corners[(i + 1) % count]);
        a + rng.uniform() * (b - a) + distance * outward(i)
    }
}

impl Grazing {
    /// The workload; `size` scales the number of rays (1.0 for the full run).
    pub fn generate(size: f64) -> Self {
        let mut rng = Rng::new(SEED ^ 4);
        let scaled = |n: usize| ((n as f64 * size) as usize).max(2 * SHAPES_PER_KIND);
        let mut workload = Self {
            shapes: Vec::new(),
            rays: Vec::new(),
        };
        for &(offset, scale) in &PLACEMENTS {
            let frame = Frame::new(&mut rng, offset, scale);
            let first = workload.shapes.len();
            for outline in [Outline::Parallelogram, Outline::Triangle] {
                for _ in 0..SHAPES_PER_KIND {
                    let spec = random_shape(&mut rng, &frame);
                    workload.shapes.push(GrazingShape {
                        spec,
                        outline,
                        placement: (offset, scale),
                    });
                }
            }
            let shapes = workload.shapes.len() - first;
            for (approach, rays) in [
                (Approach::Grazing, scaled(GRAZING_RAYS)),
                (Approach::Afar, scaled(FAR_RAYS)),
            ] {
                for k in 0..rays {
                    let shape = first + k % shapes;
                    let ray = workload.aim(&mut rng, &frame, shape, approach);
                    workload.rays.push(GrazingRay {
                        shape,
                        ray,
                        approach,
                    });
                }
            }
        }
        workload
    }

    /// A ray at a random point outside shape `shape`.
    fn aim(&self, rng: &mut Rng, frame: &Frame, shape: usize, approach: Approach) -> Ray {
        let GrazingShape { spec, outline, .. } = self.shapes[shape];
        let scale = frame.scale;
        let outside = 10f64.powf(rng.range(OUTSIDE_EXPONENTS.0, OUTSIDE_EXPONENTS.1)) * scale;
        let target = outside_point(rng, &spec, outline, outside);
        match approach {
            Approach::Grazing => {
                // A unit direction of the plane, tilted off it by the slope, to either side.
                let n = spec.u.cross(spec.v).normalize();
                let e1 = spec.u.normalize();
                let e2 = n.cross(e1);
                let phi = rng.range(0.0, std::f64::consts::TAU);
                let slope = 10f64.powf(rng.range(SLOPE_EXPONENTS.0, SLOPE_EXPONENTS.1));
                let side = if rng.coin() { 1.0 } else { -1.0 };
                let unit = phi.cos() * e1 + phi.sin() * e2 - side * slope * n;
                ray_through(target, unit, scale)
            }
            Approach::Afar => {
                let unit = frame.crossing_direction(rng);
                let direction = unit * scale;
                let distance = far_distance(rng);
                Ray::new(target - distance * direction, direction)
            }
        }
    }
}

/// A shape of the frame: `u` and `v` of random lengths in [`EDGE_LENGTHS`] at a random angle
/// in [`UV_ANGLES`], centred (`q = -(u + v) / 2`) on the frame's origin, under its rotation.
fn random_shape(rng: &mut Rng, frame: &Frame) -> QuadSpec {
    let (a, b) = (
        rng.range(EDGE_LENGTHS.0, EDGE_LENGTHS.1),
        rng.range(EDGE_LENGTHS.0, EDGE_LENGTHS.1),
    );
    let angle = rng.range(UV_ANGLES.0, UV_ANGLES.1).to_radians();
    let local_u = DVec3::new(a, 0.0, 0.0);
    let local_v = DVec3::new(b * angle.cos(), b * angle.sin(), 0.0);
    let scaled = |local: DVec3| frame.direction(frame.scale * local);
    QuadSpec {
        q: frame.point(-0.5 * (local_u + local_v)),
        u: scaled(local_u),
        v: scaled(local_v),
    }
}

impl Grazing {
    /// What the workload is, from the constants that build it, for the printed text.
    pub fn describe(&self) -> String {
        let approached = |a: Approach| self.rays.iter().filter(|r| r.approach == a).count();
        format!(
            "- **grazing** ({} rays): at the same placements, {per_kind} parallelograms and \
             {per_kind} triangles each ({shapes} shapes), built from `(q, u, v)` with `|u|` and \
             `|v|` of {lo_len} to {hi_len} scale units at {lo_angle} to {hi_angle} degrees to \
             each other, under a random rotation. Rays aimed at points of the shape's plane \
             outside it by {outside} scale units (as rounding of the target allows), beside an \
             edge or (one in {corner}) past a corner: {} arriving along the plane at slopes of \
             {slopes}, from either side, from {start} scale units before the target; and {} from \
             {far_distances} scale units away, crossing the plane at a cosine of at least \
             {crossing}. **False hit**: a hit whose point lies farther from the shape than the \
             contract's bound (below); a ray that passes within the bound of the shape may hit \
             it.",
            self.rays.len(),
            approached(Approach::Grazing),
            approached(Approach::Afar),
            per_kind = SHAPES_PER_KIND,
            shapes = self.shapes.len(),
            lo_len = EDGE_LENGTHS.0,
            hi_len = EDGE_LENGTHS.1,
            lo_angle = UV_ANGLES.0,
            hi_angle = UV_ANGLES.1,
            outside = decades(OUTSIDE_EXPONENTS),
            corner = PAST_CORNER_ONE_IN,
            slopes = decades((SLOPE_EXPONENTS.1, SLOPE_EXPONENTS.0)),
            start = short(START_DISTANCE),
            far_distances = decades(FAR_EXPONENTS),
            crossing = CROSSING_COSINE,
        )
    }
}
