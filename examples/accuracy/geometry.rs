//! Part 1: every accuracy choice on the same workloads, counting failures and timing. The
//! quad-test rows (the book's, `Exact`, 0.1.0's widened default, today's crossing-region
//! default, and the two ways of spawning rays) are here; the box-test rows in `box_tests`.

use std::hint::black_box;

use hitkit::glam::DVec3;
use hitkit::{
    Exact, GeometryError, HitRecord, Hittable, Interval, Parallelogram, Quad, Ray, Triangle,
};

use crate::book::{self, BookQuad, BookShape};
use crate::box_tests::{self, BoxNotes};
use crate::boxes::Boxes;
use crate::degenerate::{Degenerate, DegenerateKind, DegenerateRay};
use crate::distance::{Outline, is_false_hit};
use crate::edges::{Edges, Group, PLACEMENTS};
use crate::frame::{QuadSpec, Rng, SEED};
use crate::grazing::{Approach, Grazing, GrazingRay};
use crate::spawn::{Spawn, SpawnCase};
use crate::tally::{Failure, Measured, Row, Tally, median_ns_per_ray, row, short};
use crate::widened::{Widened, WidenedShape};

/// All the workloads, generated once and shared by every choice.
pub struct Workloads {
    pub edges: Edges,
    pub grazing: Grazing,
    pub spawn: Spawn,
    pub degenerate: Degenerate,
    pub boxes: Boxes,
}

impl Workloads {
    /// Every workload; `size` scales the number of rays (1.0 for the full run).
    pub fn generate(size: f64) -> Self {
        Self {
            edges: Edges::generate(size),
            grazing: Grazing::generate(size),
            spawn: Spawn::generate(size),
            degenerate: Degenerate::generate(size),
            boxes: Boxes::generate(size),
        }
    }
}

/// How a choice starts secondary rays, and the range it traces every ray over.
#[derive(Clone, Copy, Debug)]
enum Spawning {
    /// hitkit's `HitRecord::spawn_ray`, traced over `[0, inf)`.
    Offset,
    /// At the hit point, every ray traced over `[t_min, inf)` (the book's renderer).
    TMin(f64),
}

impl Spawning {
    /// The range of every ray.
    fn range(self) -> Interval {
        match self {
            Spawning::Offset => Interval::new(0.0, f64::INFINITY),
            Spawning::TMin(t_min) => Interval::new(t_min, f64::INFINITY),
        }
    }

    /// The ray leaving `hit` along `direction`.
    fn secondary(self, hit: &HitRecord, direction: DVec3) -> Ray {
        match self {
            Spawning::Offset => hit.spawn_ray(direction),
            Spawning::TMin(_) => Ray::new(hit.point, direction),
        }
    }
}

/// How a choice builds parallelograms and triangles from the workloads' `(q, u, v)`.
trait Shapes {
    type Parallelogram: Hittable + 'static;
    type Triangle: Hittable + 'static;
    fn parallelogram(&self, s: &QuadSpec) -> Result<Self::Parallelogram, GeometryError>;
    fn triangle(&self, s: &QuadSpec) -> Result<Self::Triangle, GeometryError>;
}

/// The book's test.
struct BookShapes;

impl Shapes for BookShapes {
    type Parallelogram = BookQuad;
    type Triangle = BookQuad;
    fn parallelogram(&self, s: &QuadSpec) -> Result<BookQuad, GeometryError> {
        Ok(BookQuad::new(s.q, s.u, s.v, BookShape::Parallelogram))
    }
    fn triangle(&self, s: &QuadSpec) -> Result<BookQuad, GeometryError> {
        Ok(BookQuad::new(s.q, s.u, s.v, BookShape::Triangle))
    }
}

/// hitkit's plane test with exact interiors (`Exact`), no widening.
struct ExactShapes;

impl Shapes for ExactShapes {
    type Parallelogram = Quad<Exact<Parallelogram>>;
    type Triangle = Quad<Exact<Triangle>>;
    fn parallelogram(&self, s: &QuadSpec) -> Result<Self::Parallelogram, GeometryError> {
        Quad::with_interior(s.q, s.u, s.v, Exact(Parallelogram))
    }
    fn triangle(&self, s: &QuadSpec) -> Result<Self::Triangle, GeometryError> {
        Quad::with_interior(s.q, s.u, s.v, Exact(Triangle))
    }
}

/// hitkit 0.1.0's default: `(alpha, beta)` widened by their error bound
/// ([`Widened`](crate::widened::Widened)).
struct WidenedShapes;

impl Shapes for WidenedShapes {
    type Parallelogram = Widened;
    type Triangle = Widened;
    fn parallelogram(&self, s: &QuadSpec) -> Result<Widened, GeometryError> {
        Widened::new(s.q, s.u, s.v, WidenedShape::Parallelogram)
    }
    fn triangle(&self, s: &QuadSpec) -> Result<Widened, GeometryError> {
        Widened::new(s.q, s.u, s.v, WidenedShape::Triangle)
    }
}

/// hitkit's defaults: shapes decided by the crossing region.
struct DefaultShapes;

impl Shapes for DefaultShapes {
    type Parallelogram = Quad;
    type Triangle = Quad<Triangle>;
    fn parallelogram(&self, s: &QuadSpec) -> Result<Quad, GeometryError> {
        Quad::new(s.q, s.u, s.v)
    }
    fn triangle(&self, s: &QuadSpec) -> Result<Quad<Triangle>, GeometryError> {
        Quad::with_interior(s.q, s.u, s.v, Triangle)
    }
}

/// The closest hit among `faces` and which face it is.
#[inline]
fn closest<T: Hittable>(faces: &[T], ray: &Ray, range: Interval) -> Option<(usize, HitRecord)> {
    let mut best = None;
    let mut max = range.max;
    for (i, face) in faces.iter().enumerate() {
        if let Some(hit) = face.hit(ray, Interval::new(range.min, max)) {
            max = hit.t;
            best = Some((i, hit));
        }
    }
    best
}

/// Whether any number a hit reports is NaN.
fn has_nan(hit: &HitRecord) -> bool {
    hit.t.is_nan() || hit.point.is_nan() || hit.normal.is_nan() || hit.uv.is_nan()
}

/// Builds every shape of `specs` with `build`, naming what failed.
pub fn build_all<T>(
    specs: &[QuadSpec],
    build: impl Fn(&QuadSpec) -> Result<T, GeometryError>,
    what: &str,
) -> Result<Vec<T>, String> {
    specs
        .iter()
        .map(|s| build(s).map_err(|e| format!("cannot build a {what} ({s:?}): {e}")))
        .collect()
}

/// Every target of `group`, built with `build`.
fn build_group<T>(
    group: &Group,
    build: impl Fn(&QuadSpec) -> Result<T, GeometryError> + Copy,
    what: &str,
) -> Result<Vec<Vec<T>>, String> {
    group
        .targets
        .iter()
        .map(|faces| build_all(faces, build, what))
        .collect()
}

/// Counts cracks (rays hitting none of their target's shapes), false hits (hits farther
/// than the contract's bound from the shape hit, whose kind is `outline`) and NaN hits.
fn count_cracks<T: Hittable>(
    tally: &mut Tally,
    group: &Group,
    targets: &[Vec<T>],
    range: Interval,
    name: &str,
    outline: Outline,
) {
    for kind in [Failure::Crack, Failure::FalseHit, Failure::Nan] {
        tally.measured(kind);
    }
    for &(target, ray) in &group.rays {
        let place = || {
            let (offset, scale) = group.placements[target];
            format!("{name} at {} x {}", short(offset), short(scale))
        };
        match closest(&targets[target], &ray, range) {
            None => tally.add(Failure::Crack, place),
            Some((_, hit)) if has_nan(&hit) => tally.add(Failure::Nan, place),
            Some((face, hit)) if is_false_hit(outline, &group.targets[target][face], hit.point) => {
                tally.add(Failure::FalseHit, place)
            }
            Some(_) => {}
        }
    }
}

/// Builds the shapes of `group` and counts its failures (as [`count_cracks`]).
fn run_group<T: Hittable>(
    tally: &mut Tally,
    group: &Group,
    build: impl Fn(&QuadSpec) -> Result<T, GeometryError> + Copy,
    range: Interval,
    name: &str,
    outline: Outline,
) -> Result<(), String> {
    let targets = build_group(group, build, name)?;
    count_cracks(tally, group, &targets, range, name, outline);
    Ok(())
}

/// Counts the grazing workload's false hits (hits farther than the contract's bound from
/// the shape; a ray may pass within the bound of it, and such hits are not counted) and
/// NaN hits.
fn count_grazing<S: Shapes>(
    tally: &mut Tally,
    grazing: &Grazing,
    shapes: &S,
    range: Interval,
) -> Result<(), String> {
    tally.measured(Failure::FalseHit);
    tally.measured(Failure::Nan);
    let built: Vec<Box<dyn Hittable>> = grazing
        .shapes
        .iter()
        .map(|g| -> Result<Box<dyn Hittable>, String> {
            Ok(match g.outline {
                Outline::Parallelogram => {
                    Box::new(build_one(&g.spec, |s| shapes.parallelogram(s))?)
                }
                Outline::Triangle => Box::new(build_one(&g.spec, |s| shapes.triangle(s))?),
            })
        })
        .collect::<Result<_, _>>()?;
    for &GrazingRay {
        shape,
        ray,
        approach,
    } in &grazing.rays
    {
        let g = &grazing.shapes[shape];
        let place = || {
            let (offset, scale) = g.placement;
            format!(
                "{} beside a {} at {} x {}",
                approach.label(),
                g.outline.name(),
                short(offset),
                short(scale)
            )
        };
        match built[shape].hit(&ray, range) {
            Some(hit) if has_nan(&hit) => tally.add(Failure::Nan, place),
            Some(hit) if is_false_hit(g.outline, &g.spec, hit.point) => {
                tally.add(Failure::FalseHit, place)
            }
            _ => {}
        }
    }
    Ok(())
}

/// The timed loop of the geometry rows: every ray of `group` against its target's faces.
fn trace_group<T: Hittable>(group: &Group, targets: &[Vec<T>], range: Interval) -> u64 {
    let mut hits = 0;
    for &(target, ray) in &group.rays {
        if closest(black_box(&targets[target]), black_box(&ray), range).is_some() {
            hits += 1;
        }
    }
    hits
}

/// Traces one spawn case: the primary ray, then the reflected and transmitted rays spawned
/// from its hit. Failures go to `fail` (the tally, or a counter when timing).
#[inline]
fn trace_spawn_case<T: Hittable>(
    pair: &[T; 2],
    case: &SpawnCase,
    spawning: Spawning,
    mut fail: impl FnMut(Failure),
) {
    let range = spawning.range();
    let hit = match closest(pair, &case.primary, range) {
        Some((0, hit)) => hit,
        _ => return fail(Failure::Lost),
    };
    if has_nan(&hit) {
        fail(Failure::Nan);
    }
    for (direction, up) in [(case.reflected, false), (case.transmitted, true)] {
        let ray = spawning.secondary(&hit, direction);
        match closest(pair, &ray, range) {
            Some((0, _)) => fail(Failure::SelfHit),
            Some((_, h)) if has_nan(&h) => fail(Failure::Nan),
            // The reflected ray goes down, away from the ceiling; the transmitted one must
            // reach it.
            None if up => fail(Failure::Lost),
            _ => {}
        }
    }
}

/// The floor and ceiling of every spawn placement, built with `build`.
fn spawn_pairs<T>(
    spawn: &Spawn,
    build: impl Fn(&QuadSpec) -> Result<T, GeometryError> + Copy,
) -> Result<Vec<[T; 2]>, String> {
    spawn
        .pairs
        .iter()
        .map(|[floor, ceiling]| Ok([build_one(floor, build)?, build_one(ceiling, build)?]))
        .collect()
}

/// Counts the spawn workload's self-hits, lost hits and NaN hits.
fn count_spawn<T: Hittable>(
    tally: &mut Tally,
    spawn: &Spawn,
    pairs: &[[T; 2]],
    spawning: Spawning,
) {
    for kind in [Failure::SelfHit, Failure::Lost, Failure::Nan] {
        tally.measured(kind);
    }
    for case in &spawn.cases {
        trace_spawn_case(&pairs[case.pair], case, spawning, |kind| {
            tally.add(kind, || {
                let (offset, size) = spawn.placements[case.pair];
                format!("spawn at {} x {}", short(offset), short(size))
            });
        });
    }
}

/// The time per traced ray of the spawn workload (each case traces three).
fn time_spawn<T: Hittable>(
    spawn: &Spawn,
    pairs: &[[T; 2]],
    spawning: Spawning,
    repetitions: usize,
) -> f64 {
    median_ns_per_ray(repetitions, 3 * spawn.cases.len(), || {
        let mut failures = 0;
        for case in &spawn.cases {
            trace_spawn_case(black_box(&pairs[case.pair]), case, spawning, |_| {
                failures += 1;
            });
        }
        failures
    })
}

/// One shape, with the error message naming it.
fn build_one<T>(
    spec: &QuadSpec,
    build: impl Fn(&QuadSpec) -> Result<T, GeometryError>,
) -> Result<T, String> {
    build(spec).map_err(|e| format!("cannot build a quad ({spec:?}): {e}"))
}

/// Counts the degenerate workload's lost hits (rays aimed well inside a quad that miss it),
/// false hits and NaN hits.
fn count_degenerate<T: Hittable>(
    tally: &mut Tally,
    degenerate: &Degenerate,
    quads: &[T],
    range: Interval,
) {
    for kind in [Failure::Lost, Failure::FalseHit, Failure::Nan] {
        tally.measured(kind);
    }
    for r in &degenerate.rays {
        let DegenerateRay { quad, ray, kind } = *r;
        let place = || {
            let what = match kind {
                DegenerateKind::Length(e) => format!("direction length 1e{e}"),
                DegenerateKind::Grazing(angle) => format!("grazing at {} rad", short(angle)),
                DegenerateKind::Zero => "zero direction".to_string(),
            };
            format!("{what} at {}", short(degenerate.offsets[quad]))
        };
        let spec = &degenerate.quads[quad];
        match quads[quad].hit(&ray, range) {
            None if r.should_hit() => tally.add(Failure::Lost, place),
            Some(hit) if has_nan(&hit) => tally.add(Failure::Nan, place),
            Some(hit) if is_false_hit(Outline::Parallelogram, spec, hit.point) => {
                tally.add(Failure::FalseHit, place)
            }
            _ => {}
        }
    }
}

/// Rows 1-4: one choice of shapes on the edges, grazing, spawn and degenerate workloads;
/// timed on the box-edge rays from near.
fn shape_row<S: Shapes>(
    shapes: &S,
    spawning: Spawning,
    workloads: &Workloads,
    repetitions: usize,
) -> Result<Measured, String> {
    let mut tally = Tally::default();
    let range = spawning.range();
    let edges = &workloads.edges;
    let para = |s: &QuadSpec| shapes.parallelogram(s);
    let tri = |s: &QuadSpec| shapes.triangle(s);
    let (p, t) = (Outline::Parallelogram, Outline::Triangle);

    let boxes = build_group(&edges.boxes, para, "box face")?;
    count_cracks(&mut tally, &edges.boxes, &boxes, range, "box edges", p);
    for (group, name) in [
        (&edges.coplanar, "coplanar edge"),
        (&edges.rounded_boxes, "rounded box edges"),
        (&edges.rounded_coplanar, "rounded coplanar edge"),
        (&edges.far_boxes, "box edges from afar"),
        (&edges.far_rounded_boxes, "rounded box edges from afar"),
    ] {
        run_group(&mut tally, group, para, range, name, p)?;
    }
    run_group(&mut tally, &edges.triangles, tri, range, "diagonal", t)?;
    count_grazing(&mut tally, &workloads.grazing, shapes, range)?;

    let pairs = spawn_pairs(&workloads.spawn, para)?;
    count_spawn(&mut tally, &workloads.spawn, &pairs, spawning);
    let quads = build_all(&workloads.degenerate.quads, para, "quad")?;
    count_degenerate(&mut tally, &workloads.degenerate, &quads, range);

    let ns_per_ray = median_ns_per_ray(repetitions, edges.boxes.rays.len(), || {
        trace_group(&edges.boxes, &boxes, range)
    });
    let inside = inside_rays(&edges.boxes);
    let ns_per_inside_ray = median_ns_per_ray(repetitions, inside.rays.len(), || {
        trace_group(&inside, &boxes, range)
    });
    Ok(Measured {
        ns_per_inside_ray: Some(ns_per_inside_ray),
        ..Measured::new(tally, ns_per_ray)
    })
}

/// Rays per box for the timing on rays through faces' insides.
pub const INSIDE_RAYS: usize = 20_000;

/// The boxes of `group` with rays of a render's kind instead: from `3 s` away in a random
/// direction (`s` the box's edge) toward a random point within `0.35 s` of its centre, so
/// that they enter through a face's inside, almost all of them well away from its edges.
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
            let origin = centre + 3.0 * size * rng.unit_vector();
            let target = centre + 0.35 * size * rng.uniform() * rng.unit_vector();
            rays.push((i, Ray::new(origin, target - origin)));
        }
    }
    Group {
        targets: group.targets.clone(),
        placements: group.placements.clone(),
        rays,
    }
}

/// Rows 5-6: the spawn workload on hitkit's default quads, with one way of spawning.
fn spawn_offset_row(
    workloads: &Workloads,
    spawning: Spawning,
    repetitions: usize,
) -> Result<Measured, String> {
    let pairs = spawn_pairs(&workloads.spawn, |s| Quad::new(s.q, s.u, s.v))?;
    let mut tally = Tally::default();
    count_spawn(&mut tally, &workloads.spawn, &pairs, spawning);
    let ns = time_spawn(&workloads.spawn, &pairs, spawning, repetitions);
    Ok(Measured::new(tally, ns))
}

/// Every row of the table, in order, and the notes on the box tests.
pub fn measure(workloads: &Workloads, repetitions: usize) -> Result<(Vec<Row>, BoxNotes), String> {
    let book = Spawning::TMin(book::T_MIN);
    let mut rows = vec![
        row(
            "book",
            "nothing (the baseline: 1e-8 parallel test, t = (D - n.o) / n.d, p = o + t d, t_min = 0.001)",
            shape_row(&BookShapes, book, workloads, repetitions)?,
        ),
        row(
            "well-conditioned (`Exact`)",
            "far-out accuracy: t = n.(q - o) / n.d, p - q = (o - q) + t d; no 1e-8 test or t_min; `spawn_ray`",
            shape_row(&ExactShapes, Spawning::Offset, workloads, repetitions)?,
        ),
        row(
            "widened in (alpha, beta) (0.1.0 default)",
            "cracks at exactly shared corners: points within the coordinates' error bound, which grows as 1 / |n.d|, count as inside",
            shape_row(&WidenedShapes, Spawning::Offset, workloads, repetitions)?,
        ),
        row(
            "crossing region (default)",
            "cracks (shared corners exact or rounded apart) without false hits: the exact crossing's region, narrow across the ray at any angle; double-double near edges; hits kept in the shape's box",
            shape_row(&DefaultShapes, Spawning::Offset, workloads, repetitions)?,
        ),
        row(
            "spawn offset: `spawn_ray`, t >= 0",
            "self-hits, with no epsilon: the origin moves off by the hit point's error bound",
            spawn_offset_row(workloads, Spawning::Offset, repetitions)?,
        ),
        row(
            "spawn offset: hit point, t_min = 0.001",
            "self-hits where errors stay below 0.001 (the book's way), losing nearer surfaces",
            spawn_offset_row(workloads, book, repetitions)?,
        ),
    ];
    let (box_rows, notes) = box_tests::box_rows(&workloads.boxes, repetitions)?;
    rows.extend(box_rows);
    Ok((rows, notes))
}

/// How many rays each workload traces, for the printed description.
pub struct RayCounts {
    /// Every ray of the edges workload.
    pub edges: usize,
    /// Its parts: box rays from near (exact, rounded), shared-edge rays (coplanar exact and
    /// rounded, triangles), box rays from afar (exact, rounded).
    pub boxes: [usize; 2],
    pub shared: [usize; 3],
    pub far: [usize; 2],
    /// The grazing workload's shapes, grazing rays and rays from afar.
    pub grazing_shapes: usize,
    pub grazing: [usize; 2],
    pub spawn: usize,
    pub degenerate: usize,
    pub box_rays: usize,
}

impl RayCounts {
    /// The counts of `workloads`.
    pub fn of(workloads: &Workloads) -> Self {
        let edges = &workloads.edges;
        let boxes = [edges.boxes.rays.len(), edges.rounded_boxes.rays.len()];
        let shared = [
            edges.coplanar.rays.len(),
            edges.rounded_coplanar.rays.len(),
            edges.triangles.rays.len(),
        ];
        let far = [
            edges.far_boxes.rays.len(),
            edges.far_rounded_boxes.rays.len(),
        ];
        let grazing = &workloads.grazing;
        let approached = |a: Approach| grazing.rays.iter().filter(|r| r.approach == a).count();
        Self {
            edges: boxes.iter().chain(&shared).chain(&far).sum(),
            boxes,
            shared,
            far,
            grazing_shapes: grazing.shapes.len(),
            grazing: [approached(Approach::Grazing), approached(Approach::Afar)],
            spawn: workloads.spawn.cases.len(),
            degenerate: workloads.degenerate.rays.len(),
            box_rays: workloads.boxes.rays.len(),
        }
    }
}

/// The placements of the edges workload, for the printed description.
pub fn placements() -> String {
    PLACEMENTS
        .iter()
        .map(|&(offset, scale)| format!("{} x {}", short(offset), short(scale)))
        .collect::<Vec<_>>()
        .join(", ")
}
