//! The edges workload: rays aimed exactly at edges that shapes share, where a test that is
//! not watertight lets rays through.

use hitkit::Ray;
use hitkit::glam::DVec3;

use crate::frame::{Frame, Lattice, QuadSpec, Rng, SEED};

/// Where the workloads put their geometry: `(offset, scale)`, the distance of the geometry
/// from the origin (along a fixed direction off the axes) and its size.
pub const PLACEMENTS: [(f64, f64); 10] = [
    (0.0, 1.0),
    (1.0, 1.0),
    (1e3, 1.0),
    (1e6, 1.0),
    (1e9, 1.0),
    (1e12, 1.0),
    (0.0, 1e-6),
    (0.0, 1e-3),
    (0.0, 1e3),
    (0.0, 1e6),
];

/// Shapes and the rays aimed at them: ray `(i, ray)` is traced against `targets[i]`, all of
/// whose faces are of one kind (parallelograms or triangles).
#[derive(Clone, Debug, Default)]
pub struct Group {
    pub targets: Vec<Vec<QuadSpec>>,
    /// The `(offset, scale)` of each target.
    pub placements: Vec<(f64, f64)>,
    pub rays: Vec<(usize, Ray)>,
}

/// The edges workload: rays aimed exactly at shared edges, where a leaky test cracks.
#[derive(Clone, Debug)]
pub struct Edges {
    /// Rotated unit boxes, six parallelograms each, with rays at points on their edges
    /// and at their corners; corners on a [`Lattice`], so the faces close exactly.
    pub boxes: Group,
    /// The same with each corner computed as `offset + R * local corner` and rounded on its
    /// own: `q + u + v` then misses the fourth corner by up to an ulp of the coordinates,
    /// a gap in the geometry that no intersection test can close. Reported apart.
    pub rounded_boxes: Group,
    /// Two coplanar parallelograms sharing an edge, rays at the shared edge.
    pub coplanar: Group,
    /// Two triangles sharing the diagonal of a square, rays at the diagonal.
    pub triangles: Group,
    /// The coplanar pair with corners rounded one by one, as `rounded_boxes`.
    pub rounded_coplanar: Group,
}

/// Rays per placement at the edges of a box (the rest of the box rays go to corners).
const EDGE_RAYS: usize = 16_000;
const CORNER_RAYS: usize = 4_000;
/// Rays per placement at a shared edge of two quads, and at the shared diagonal.
const SHARED_EDGE_RAYS: usize = 4_000;

/// Corner `i` of the unit box centred on the origin: bit `k` of `i` is the side along axis
/// `k`.
fn box_corner(i: usize) -> DVec3 {
    DVec3::new(
        (i & 1) as f64 - 0.5,
        ((i >> 1) & 1) as f64 - 0.5,
        ((i >> 2) & 1) as f64 - 0.5,
    )
}

/// The four corners (indices) of the face of the box at `side` along `axis`, in cyclic
/// order.
fn face_cycle(axis: usize, side: usize) -> [usize; 4] {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(i, j)| side << axis | i << b | j << c)
}

/// The six faces of the box whose corners are `corners`, each built from its own corner (a
/// different position in its cycle for each face) to its two neighbours: the faces share
/// edges only as far as rounding allows.
fn box_faces(corners: &[DVec3; 8]) -> Vec<QuadSpec> {
    let mut faces = Vec::with_capacity(6);
    for axis in 0..3 {
        for side in 0..2 {
            let cycle = face_cycle(axis, side);
            let k = (2 * axis + side) % 4;
            faces.push(QuadSpec::from_corners(
                corners[cycle[k]],
                corners[cycle[(k + 1) % 4]],
                corners[cycle[(k + 3) % 4]],
            ));
        }
    }
    faces
}

/// A random unit direction that enters the box through a point lying on all the faces in
/// `faces` (pairs of axis and side): its cosine with each outward normal is at most -0.1, so
/// the ray crosses the inside of the box and must meet its surface.
fn inward_direction(rng: &mut Rng, frame: &Frame, faces: &[(usize, usize)]) -> DVec3 {
    loop {
        let d = rng.unit_vector();
        let inward = faces.iter().all(|&(axis, side)| {
            let outward = if side == 1 { d[axis] } else { -d[axis] };
            outward <= -0.1
        });
        if inward {
            return frame.direction(d);
        }
    }
}

/// A ray through `p` along `unit`, starting two scale units before it, with a direction of
/// that length: it reaches `p` at `t = 1`, far above any `t_min`.
fn ray_through(p: DVec3, unit: DVec3, scale: f64) -> Ray {
    let direction = unit * (2.0 * scale);
    Ray::new(p - direction, direction)
}

/// The eight corners of the unit box of `frame`: exact lattice points when `exact`, else
/// each `offset + R * local corner` rounded on its own.
fn box_corners(frame: &Frame, exact: bool) -> [DVec3; 8] {
    let lattice = Lattice::new(frame, DVec3::splat(-0.5), 1.0);
    std::array::from_fn(|i| {
        if exact {
            let bit = |k: usize| ((i >> k) & 1) as f64;
            lattice.point(bit(0), bit(1), bit(2))
        } else {
            frame.point(box_corner(i))
        }
    })
}

/// A point to aim at, and the faces (axis, side) it lies on: a random corner, or a random
/// point `corner + s * (other corner - corner)` of a random edge. Not within 0.02 of an
/// edge's ends, where a ray entering through the edge may leave at once through the third
/// face (corners have rays of their own).
fn aim_point(rng: &mut Rng, corners: &[DVec3; 8], at_corner: bool) -> (DVec3, Vec<(usize, usize)>) {
    let corner = rng.below(8);
    let side = |axis: usize| (corner >> axis) & 1;
    if at_corner {
        return (corners[corner], (0..3).map(|a| (a, side(a))).collect());
    }
    let axis = rng.below(3);
    let (from, to) = (corner & !(1 << axis), corner | 1 << axis);
    let s = rng.range(0.02, 0.98);
    let p = corners[from] + s * (corners[to] - corners[from]);
    let faces = (0..3)
        .filter(|&a| a != axis)
        .map(|a| (a, side(a)))
        .collect();
    (p, faces)
}

/// Rotated boxes at every placement, and rays from outside, entering the box, at points on
/// their edges and at their corners. The corners are exact lattice points when `exact`,
/// else rounded one by one.
fn box_group(rng: &mut Rng, rays_per_placement: usize, exact: bool) -> Group {
    let mut group = Group::default();
    let corner_rays = rays_per_placement * CORNER_RAYS / (EDGE_RAYS + CORNER_RAYS);
    for &(offset, scale) in &PLACEMENTS {
        let frame = Frame::new(rng, offset, scale);
        let corners = box_corners(&frame, exact);
        let target = group.targets.len();
        group.targets.push(box_faces(&corners));
        group.placements.push((offset, scale));
        for n in 0..rays_per_placement {
            let (p, faces) = aim_point(rng, &corners, n < corner_rays);
            let unit = inward_direction(rng, &frame, &faces);
            group.rays.push((target, ray_through(p, unit, scale)));
        }
    }
    group
}

/// Two shapes sharing an edge at every placement, and rays at points `a + s (b - a)` of the
/// shared edge `a`-`b` (`s` in `[0.02, 0.98]`, away from the outer boundary).
/// `layout(at)` gives the two shapes and the shared edge from the corners `at(x, y)`, which
/// are exact lattice points when `exact`, else rounded one by one.
fn shared_edge_group(
    rng: &mut Rng,
    rays_per_placement: usize,
    exact: bool,
    layout: impl Fn(&dyn Fn(f64, f64) -> DVec3) -> ([QuadSpec; 2], DVec3, DVec3),
) -> Group {
    let mut group = Group::default();
    for &(offset, scale) in &PLACEMENTS {
        let frame = Frame::new(rng, offset, scale);
        let base = DVec3::new(-1.0, -0.5, 0.0);
        let lattice = Lattice::new(&frame, base, 2.0);
        let at = |x: f64, y: f64| {
            if exact {
                lattice.point(x, y, 0.0)
            } else {
                frame.point(base + DVec3::new(x, y, 0.0))
            }
        };
        let (shapes, a, b) = layout(&at);
        let target = group.targets.len();
        group.targets.push(shapes.to_vec());
        group.placements.push((offset, scale));
        for _ in 0..rays_per_placement {
            let p = a + rng.range(0.02, 0.98) * (b - a);
            let unit = frame.crossing_direction(rng);
            group.rays.push((target, ray_through(p, unit, scale)));
        }
    }
    group
}

/// Two coplanar unit squares side by side, each built from its own far corner, so that
/// each computes the shared edge its own way (as its edge opposite `q`).
fn coplanar_layout(at: &dyn Fn(f64, f64) -> DVec3) -> ([QuadSpec; 2], DVec3, DVec3) {
    let (a, b, c) = (at(0.0, 0.0), at(1.0, 0.0), at(2.0, 0.0));
    let (d, e, f) = (at(0.0, 1.0), at(1.0, 1.0), at(2.0, 1.0));
    let left = QuadSpec::from_corners(a, b, d);
    let right = QuadSpec::from_corners(f, e, c);
    ([left, right], b, e)
}

/// A unit square split along its diagonal into two triangles, each from its own corner.
fn triangles_layout(at: &dyn Fn(f64, f64) -> DVec3) -> ([QuadSpec; 2], DVec3, DVec3) {
    let (a, b, c, d) = (at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0), at(0.0, 1.0));
    let first = QuadSpec::from_corners(a, b, d);
    let second = QuadSpec::from_corners(c, d, b);
    ([first, second], b, d)
}

impl Edges {
    /// The workload; `size` scales the number of rays (1.0 for the full run).
    pub fn generate(size: f64) -> Self {
        let mut rng = Rng::new(SEED);
        let scaled = |n: usize| ((n as f64 * size) as usize).max(10);
        Self {
            boxes: box_group(&mut rng, scaled(EDGE_RAYS + CORNER_RAYS), true),
            rounded_boxes: box_group(&mut rng, scaled(EDGE_RAYS + CORNER_RAYS), false),
            coplanar: shared_edge_group(&mut rng, scaled(SHARED_EDGE_RAYS), true, coplanar_layout),
            triangles: shared_edge_group(
                &mut rng,
                scaled(SHARED_EDGE_RAYS),
                true,
                triangles_layout,
            ),
            rounded_coplanar: shared_edge_group(
                &mut rng,
                scaled(SHARED_EDGE_RAYS),
                false,
                coplanar_layout,
            ),
        }
    }
}
