//! The quad-test rows (the book's, `Exact`, 0.1.0's widened default, today's
//! crossing-region default) and the two ways of spawning rays: each counts its failures on
//! every workload it runs and is timed on the edges workload's box rays.

use std::hint::black_box;

use hitkit::glam::DVec3;
use hitkit::{
    Exact, GeometryError, HitRecord, Hittable, Interval, Parallelogram, Quad, Ray, Triangle,
};

use crate::numbers::short;
use crate::rows::book::{BookQuad, BookShape};
use crate::rows::distance::is_false_hit;
use crate::rows::tally::{Failure, Measured, Tally, median_ns_per_ray};
use crate::rows::widened::{Widened, WidenedShape};
use crate::workloads::Workloads;
use crate::workloads::degenerate::{Degenerate, DegenerateKind, DegenerateRay};
use crate::workloads::edges::Group;
use crate::workloads::frame::{Outline, QuadSpec};
use crate::workloads::grazing::{Grazing, GrazingRay};
use crate::workloads::inside::inside_rays;
use crate::workloads::spawn::{Spawn, SpawnCase};

/// How a choice starts secondary rays, and the range it traces every ray over.
#[derive(Clone, Copy, Debug)]
pub enum Spawning {
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
pub trait Shapes {
    type Parallelogram: Hittable + 'static;
    type Triangle: Hittable + 'static;
    fn parallelogram(&self, s: &QuadSpec) -> Result<Self::Parallelogram, GeometryError>;
    fn triangle(&self, s: &QuadSpec) -> Result<Self::Triangle, GeometryError>;
}

/// The book's test.
pub struct BookShapes;

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
pub struct ExactShapes;

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
/// ([`Widened`](crate::rows::widened::Widened)).
pub struct WidenedShapes;

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
pub struct DefaultShapes;

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
pub fn shape_row<S: Shapes>(
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

/// Rows 5-6: the spawn workload on hitkit's default quads, with one way of spawning.
pub fn spawn_offset_row(
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
