//! The edges workload: rays aimed exactly at edges that shapes share, where a test that is
//! not watertight lets rays through; from near, and from far away.

use hitkit::Ray;
use hitkit::glam::DVec3;

use crate::numbers::{decades, short};
use crate::workloads::frame::{Frame, Lattice, QuadSpec, Rng, SEED};

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
    /// own (a box built face by face in world space): `q + u + v` then misses the fourth
    /// corner by up to an ulp of the coordinates, a gap that only a test widened by more
    /// than that closes.
    pub rounded_boxes: Group,
    /// Two coplanar parallelograms sharing an edge, rays at the shared edge.
    pub coplanar: Group,
    /// Two triangles sharing the diagonal of a square, rays at the diagonal.
    pub triangles: Group,
    /// The coplanar pair with corners rounded one by one, as `rounded_boxes`.
    pub rounded_coplanar: Group,
    /// The boxes of `boxes` again, with rays at some of the same points of their edges and
    /// corners from far away (see [`ray_from_afar`]).
    pub far_boxes: Group,
    /// The same for `rounded_boxes`.
    pub far_rounded_boxes: Group,
}

/// Where a box ray was aimed, so that rays from far away can aim there again.
#[derive(Clone, Copy, Debug)]
struct Aim {
    /// The ray's target (the box) in its group.
    target: usize,
    /// The point on an edge or at a corner.
    point: DVec3,
    /// The unit direction the near ray entered by.
    unit: DVec3,
    /// The centre of the box.
    centre: DVec3,
    scale: f64,
}

/// Rays per placement at the edges of a box (the rest of the box rays go to corners).
const EDGE_RAYS: usize = 16_000;
const CORNER_RAYS: usize = 4_000;
/// Rays at edges are aimed at `corner + s (other corner - corner)` with `s` at least this
/// far from 0 and 1.
pub const EDGE_MARGIN: f64 = 0.02;
/// Box rays enter with a cosine of at least this with the inward normal of every face
/// their point lies on.
pub const INWARD_COSINE: f64 = 0.1;
/// Rays per placement at a shared edge of two quads, and at the shared diagonal.
const SHARED_EDGE_RAYS: usize = 4_000;
/// Rays per placement from far away at the edges and corners of a box (of each kind).
const FAR_BOX_RAYS: usize = 4_000;
/// Near rays start this many scale units before the point they are aimed at.
pub const START_DISTANCE: f64 = 2.0;
/// Rays from far away start `10^k` scale units from their target, `k` uniform in this
/// range.
pub const FAR_EXPONENTS: (f64, f64) = (3.0, 12.0);
/// A ray from far away is aimed this many times its origin's rounding inside the box (see
/// [`ray_from_afar`]).
pub const FAR_INSET: f64 = 4.0;

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
/// `faces` (pairs of axis and side): its cosine with each outward normal is at most
/// `-INWARD_COSINE`, so the ray crosses the inside of the box and must meet its surface.
fn inward_direction(rng: &mut Rng, frame: &Frame, faces: &[(usize, usize)]) -> DVec3 {
    loop {
        let d = rng.unit_vector();
        let inward = faces.iter().all(|&(axis, side)| {
            let outward = if side == 1 { d[axis] } else { -d[axis] };
            outward <= -INWARD_COSINE
        });
        if inward {
            return frame.direction(d);
        }
    }
}

/// A ray through `p` along `unit`, starting [`START_DISTANCE`] scale units before it, with
/// a direction of that length: it reaches `p` at `t = 1`, far above any `t_min`.
pub fn ray_through(p: DVec3, unit: DVec3, scale: f64) -> Ray {
    let direction = unit * (START_DISTANCE * scale);
    Ray::new(p - direction, direction)
}

/// `10^k` for `k` uniform in [`FAR_EXPONENTS`]: how many scale units away a ray from afar
/// starts.
pub fn far_distance(rng: &mut Rng) -> f64 {
    10f64.powf(rng.range(FAR_EXPONENTS.0, FAR_EXPONENTS.1))
}

/// A ray along `unit` (entering the box whose centre is `centre`) from `distance` scale
/// units before the point `p` of the box's edge or corner, with a direction of one scale
/// unit (so `t` is about `distance`, far above any `t_min`).
///
/// The origin rounds by an ulp of its coordinates, which moves the ray's line by up to an
/// ulp of `distance` (and `p` itself is off the exact edge by an ulp of its own
/// coordinates): aimed exactly at `p`, half of these rays would pass beside the box. So the
/// ray is aimed at `p` moved toward the centre by [`FAR_INSET`]` e`, where
/// `e = eps (distance |d|_inf + 3 |p|_inf + 2 scale)` (`d` the direction) bounds those
/// roundings per coordinate (`sqrt 3 e` in length). The move takes the aim at least 0.57 of
/// its length inside each face plane through `p` (`(0.5, 0.5, 0.48)` normalized is the
/// shallowest it gets), and `0.57 * 4 e > sqrt 3 e`: the exact line passes through the
/// inside of the box, within a few ulps of its edge, and must hit one of its faces.
fn ray_from_afar(p: DVec3, unit: DVec3, centre: DVec3, scale: f64, distance: f64) -> Ray {
    let direction = unit * scale;
    let e = f64::EPSILON
        * (distance * direction.abs().max_element() + 3.0 * p.abs().max_element() + 2.0 * scale);
    let aim = p + (FAR_INSET * e) * (centre - p).normalize();
    Ray::new(aim - distance * direction, direction)
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
/// point `corner + s * (other corner - corner)` of a random edge. Not within
/// [`EDGE_MARGIN`] of an edge's ends, where a ray entering through the edge may leave at
/// once through the third face (corners have rays of their own).
fn aim_point(rng: &mut Rng, corners: &[DVec3; 8], at_corner: bool) -> (DVec3, Vec<(usize, usize)>) {
    let corner = rng.below(8);
    let side = |axis: usize| (corner >> axis) & 1;
    if at_corner {
        return (corners[corner], (0..3).map(|a| (a, side(a))).collect());
    }
    let axis = rng.below(3);
    let (from, to) = (corner & !(1 << axis), corner | 1 << axis);
    let s = rng.range(EDGE_MARGIN, 1.0 - EDGE_MARGIN);
    let p = corners[from] + s * (corners[to] - corners[from]);
    let faces = (0..3)
        .filter(|&a| a != axis)
        .map(|a| (a, side(a)))
        .collect();
    (p, faces)
}

/// Rotated boxes at every placement, and rays from outside, entering the box, at points on
/// their edges and at their corners; and where each ray was aimed. The corners are exact
/// lattice points when `exact`, else rounded one by one.
fn box_group(rng: &mut Rng, rays_per_placement: usize, exact: bool) -> (Group, Vec<Aim>) {
    let mut group = Group::default();
    let mut aims = Vec::new();
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
            aims.push(Aim {
                target,
                point: p,
                unit,
                centre: frame.origin,
                scale,
            });
        }
    }
    (group, aims)
}

/// The boxes of `near` again, and `rays_per_placement` rays from far away at the points
/// (every so many of `aims`, corners and edges alike) its rays were aimed at, entering the
/// box as they did.
fn far_group(rng: &mut Rng, near: &Group, aims: &[Aim], rays_per_placement: usize) -> Group {
    let per_placement = aims.len() / near.targets.len().max(1);
    let stride = (per_placement / rays_per_placement.max(1)).max(1);
    let mut group = Group {
        targets: near.targets.clone(),
        placements: near.placements.clone(),
        rays: Vec::new(),
    };
    for aim in aims.iter().step_by(stride) {
        let distance = far_distance(rng);
        let ray = ray_from_afar(aim.point, aim.unit, aim.centre, aim.scale, distance);
        group.rays.push((aim.target, ray));
    }
    group
}

/// Two shapes sharing an edge at every placement, and rays at points `a + s (b - a)` of the
/// shared edge `a`-`b` (`s` at least [`EDGE_MARGIN`] from its ends, away from the outer
/// boundary).
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
            let p = a + rng.range(EDGE_MARGIN, 1.0 - EDGE_MARGIN) * (b - a);
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
        let (boxes, aims) = box_group(&mut rng, scaled(EDGE_RAYS + CORNER_RAYS), true);
        let (rounded_boxes, rounded_aims) =
            box_group(&mut rng, scaled(EDGE_RAYS + CORNER_RAYS), false);
        let coplanar = shared_edge_group(&mut rng, scaled(SHARED_EDGE_RAYS), true, coplanar_layout);
        let triangles =
            shared_edge_group(&mut rng, scaled(SHARED_EDGE_RAYS), true, triangles_layout);
        let rounded_coplanar =
            shared_edge_group(&mut rng, scaled(SHARED_EDGE_RAYS), false, coplanar_layout);
        // Drawn after the near rays, which stay as they were.
        let far_boxes = far_group(&mut rng, &boxes, &aims, scaled(FAR_BOX_RAYS));
        let far_rounded_boxes = far_group(
            &mut rng,
            &rounded_boxes,
            &rounded_aims,
            scaled(FAR_BOX_RAYS),
        );
        Self {
            boxes,
            rounded_boxes,
            coplanar,
            triangles,
            rounded_coplanar,
            far_boxes,
            far_rounded_boxes,
        }
    }
}

/// The placements, as the text prints them: `offset x scale, ...`.
pub fn placements() -> String {
    PLACEMENTS
        .iter()
        .map(|&(offset, scale)| format!("{} x {}", short(offset), short(scale)))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Edges {
    /// Every ray of the workload.
    pub fn ray_count(&self) -> usize {
        self.groups().iter().map(|g| g.rays.len()).sum()
    }

    fn groups(&self) -> [&Group; 7] {
        [
            &self.boxes,
            &self.rounded_boxes,
            &self.coplanar,
            &self.triangles,
            &self.rounded_coplanar,
            &self.far_boxes,
            &self.far_rounded_boxes,
        ]
    }

    /// What the workload is, from the constants that build it, for the printed text.
    pub fn describe(&self) -> String {
        let farthest = PLACEMENTS
            .iter()
            .map(|&(offset, _)| offset)
            .fold(0.0, f64::max);
        format!(
            "- **edges** ({} rays): a unit box under a random rotation, built in world space as \
             six quads each from its own corner (`q` one of the face's corners, `u` and `v` \
             differences of corners), at (offset x scale) {placements}. Corners are `offset + R \
             * local corner` with `R`'s columns rounded to a power-of-two grid so that every \
             corner is an exact sum: the faces close exactly (`q + u + v` is the fourth corner). \
             Rays from {start} scale units outside, entering the box (cosine at least {inward} \
             with the inward normal of each face they aim at), aimed at points on its edges \
             (`corner + s (other corner - corner)`, `s` in [{margin}, {far_margin}]) and at its \
             corners ({} rays); plus rays at the shared edge of two coplanar quads (each built \
             from its far corner; {} rays) and at the shared diagonal of two triangles ({} \
             rays), on the same kind of grid and placements. The same boxes ({} rays) and \
             coplanar pairs ({} rays) again with each corner computed as `offset + R * local \
             corner` and rounded on its own, as a box built face by face in world space is: a \
             quad's `q + u + v` then misses the fourth corner by up to an ulp of the coordinates \
             ({ulp:.1e} at {farthest}). And rays from far away, {far_distances} scale units, at \
             the same edge and corner points of the exact ({} rays) and rounded ({} rays) boxes, \
             entering as the near rays do: their origins round by an ulp of that distance, which \
             can move them off the edge to either side, so each is aimed {inset} times that \
             rounding (and the target's) inside the box, still within a few ulps of its edge. \
             **Crack**: the ray hits none of the shapes.",
            self.ray_count(),
            self.boxes.rays.len(),
            self.coplanar.rays.len(),
            self.triangles.rays.len(),
            self.rounded_boxes.rays.len(),
            self.rounded_coplanar.rays.len(),
            self.far_boxes.rays.len(),
            self.far_rounded_boxes.rays.len(),
            placements = placements(),
            start = short(START_DISTANCE),
            inward = INWARD_COSINE,
            margin = EDGE_MARGIN,
            far_margin = 1.0 - EDGE_MARGIN,
            ulp = farthest.next_up() - farthest,
            farthest = short(farthest),
            far_distances = decades(FAR_EXPONENTS),
            inset = short(FAR_INSET),
        )
    }
}
