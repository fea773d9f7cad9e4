//! Runs the same scenes and the same rays through hitkit, the `bvh` crate and `obvhs`,
//! single-threaded, in one process, and prints a Markdown table.
//!
//! Every library finds the closest hit with hitkit's own f64 triangle test at its leaves, so
//! the hits must agree and the timings compare hierarchies and traversals.
//!
//! `cargo run --release -p hitkit-peers -- --help`

#[cfg(feature = "embree")]
mod embree;
mod halls;
mod library;
mod lights;
mod triad;
mod updates;

use hitkit_render::workloads;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicU64;
use std::sync::atomic::Ordering::Relaxed;
use std::time::{Duration, Instant};

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::AtomicUsize;

use hitkit::glam::DVec3;
use hitkit::{Aabb, Bvh, Hittable, Interval, Quad, Ray, Triangle, TriangleMesh};
use nalgebra::{Point3, Vector3};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::RayHit;

const USAGE: &str = "\
Compares hitkit's BVH with the bvh crate (0.13) and obvhs (0.4): build time and single-threaded
closest-hit throughput on the same triangles and the same rays. Prints a Markdown table.

Usage: cargo run --release -p hitkit-peers -- [OPTIONS]

Options:
  --obj PATH     OBJ mesh for the `bunny` row, skipped with a warning if missing
                 [default: ../shared/data/stanford-bunny.obj]
  --soups LIST   comma-separated triangle counts of random soups, empty for none
                 [default: 1000,1000000]
  --sphere L     a closed mesh with shared vertices: an icosphere subdivided L times
                 (20 * 4^L triangles), 0 for none [default: 8, 1.3M triangles]
  --mesh-only    only the rows of hitkit's TriangleMesh and obvhs on its own triangles
                 (for scenes too large for the other rows)
  --updates      instead of the tables above, what moving a mesh costs: TriangleMesh's refit
                 (set_vertices) against its rebuild and against obvhs's refit, and the
                 throughput of a refitted tree as the mesh twists further, against a fresh
                 one (the rays as above)
  --lights       instead of the tables above, what picking among many lights costs:
                 LightTree against a power-weighted Mixture, per sample and per density
                 query, at 10 to 1,000,000 lights, and the tree's build time and bytes
  --halls        instead of the tables above, the light tree against pbrt-v4's BVH light
                 sampler (written from the book) and the power mixture on halls of 1,000
                 and 10,000 lamps: the variance of the choice of lamp at units of length
                 0.01 to 100, and relative MSE x time of next-event estimation from the
                 floor at 16 and 64 samples per point
  --picks        with --halls: instead of its tables, nanoseconds a pick alone, the tree's
                 and pbrt-v4's (functions of their own, for callgrind's --toggle-collect)
  --triad        instead of the tables above, what a path tracer traces: primary rays
                 from a camera, a cosine bounce and a shadow ray to a lamp from each
                 primary hit, on the bunny, the book's Cornell box (its lamp inside, and
                 above a skylight in the ceiling), a crowd of turned bunnies on a floor and
                 the closed sphere from inside: TriangleMesh and Bvh<Quad<Triangle>> against
                 obvhs, with node visits and face tests per ray; built with
                 `--features embree` (needs `apt-get install libembree-dev`), against
                 Embree 3 too, with each library's bytes
  --crowd N      bunnies in the triad's crowd, 0 for none [default: 9]
  --only TEXT    with --triad: time only the libraries whose names hold TEXT (for profiles)
  --scene TEXT   with --triad: only the scenes whose names hold TEXT; with --halls, the halls
  --ftz          with --triad: hitkit's rows again with the CPU's flush-to-zero and
                 denormals-are-zero modes on (x86_64), and the answers that change
  --count        with --triad: no tables; each library chosen by --only traces each set
                 once, in functions of their own (`count_primary`, `count_bounce`,
                 `count_shadow`) for callgrind to count (benches/count.sh)
  --rays N       incoherent rays per scene [default: 1000000]
  --side N       camera rays: an N x N grid [default: 1000]
  --runs K       repetitions of every build and trace; the median is reported [default: 3]
  --seed S       seed of the soups (S) and of the incoherent rays (S + 1) [default: 0x5eed]
  --offsets LIST comma-separated distances to move the first scene by (along a fixed
                 direction off the axes), empty for none: a second table of Mrays/s and
                 triangle tests per ray at each [default: 0,1e6,1e9,1e12]
  --offset-rays N rays per set in that table (camera grid and random) [default: 10000]
  -h, --help     this text";

/// The command line.
struct Args {
    obj: PathBuf,
    soups: Vec<usize>,
    sphere: u32,
    mesh_only: bool,
    updates: bool,
    lights: bool,
    halls: bool,
    picks: bool,
    triad: bool,
    crowd: usize,
    /// With `--triad`: time only the libraries, and keep only the scenes, whose names
    /// hold these (for profiles).
    only: Option<String>,
    scene: Option<String>,
    ftz: bool,
    /// With `--triad`: each set once, for an instruction counter (`benches/count.sh`).
    count: bool,
    rays: usize,
    side: usize,
    runs: usize,
    seed: u64,
    offsets: Vec<f64>,
    offset_rays: usize,
}

/// The system allocator, counting the bytes in use and the most in use since the last
/// [`reset_peak`]: how the memory columns are measured, for every library alike.
struct Counting;

static IN_USE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = IN_USE.fetch_add(layout.size(), Relaxed) + layout.size();
            PEAK.fetch_max(now, Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(p, layout) };
        IN_USE.fetch_sub(layout.size(), Relaxed);
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let q = unsafe { System.realloc(p, layout, new_size) };
        if !q.is_null() {
            if new_size >= layout.size() {
                let now =
                    IN_USE.fetch_add(new_size - layout.size(), Relaxed) + new_size - layout.size();
                PEAK.fetch_max(now, Relaxed);
            } else {
                IN_USE.fetch_sub(layout.size() - new_size, Relaxed);
            }
        }
        q
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Starts a new peak at the bytes in use now, and returns them.
fn reset_peak() -> usize {
    let now = IN_USE.load(Relaxed);
    PEAK.store(now, Relaxed);
    now
}

/// Parses the arguments after the program name: `Ok(None)` for `--help`.
fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Option<Args>, String> {
    let mut parsed = Args {
        obj: PathBuf::from("../shared/data/stanford-bunny.obj"),
        soups: vec![1_000, 1_000_000],
        sphere: 8,
        mesh_only: false,
        updates: false,
        lights: false,
        halls: false,
        picks: false,
        triad: false,
        crowd: 9,
        only: None,
        scene: None,
        ftz: false,
        count: false,
        rays: 1_000_000,
        side: 1_000,
        runs: 3,
        seed: 0x5eed,
        offsets: vec![0.0, 1e6, 1e9, 1e12],
        offset_rays: 10_000,
    };
    while let Some(flag) = args.next() {
        if flag == "--help" || flag == "-h" {
            return Ok(None);
        }
        if flag == "--mesh-only" {
            parsed.mesh_only = true;
            continue;
        }
        if flag == "--updates" {
            parsed.updates = true;
            continue;
        }
        if flag == "--lights" {
            parsed.lights = true;
            continue;
        }
        if flag == "--halls" {
            parsed.halls = true;
            continue;
        }
        if flag == "--picks" {
            parsed.picks = true;
            continue;
        }
        if flag == "--triad" {
            parsed.triad = true;
            continue;
        }
        if flag == "--ftz" {
            parsed.ftz = true;
            continue;
        }
        if flag == "--count" {
            parsed.count = true;
            continue;
        }
        if ![
            "--obj",
            "--soups",
            "--sphere",
            "--crowd",
            "--only",
            "--scene",
            "--rays",
            "--side",
            "--runs",
            "--seed",
            "--offsets",
            "--offset-rays",
        ]
        .contains(&flag.as_str())
        {
            return Err(format!("unknown argument `{flag}`"));
        }
        let value = args
            .next()
            .ok_or_else(|| format!("`{flag}` needs a value"))?;
        match flag.as_str() {
            "--obj" => parsed.obj = PathBuf::from(value),
            "--soups" if value.is_empty() => parsed.soups.clear(),
            "--soups" => {
                parsed.soups = value
                    .split(',')
                    .map(|n| count(&flag, n))
                    .collect::<Result<_, _>>()?;
            }
            "--sphere" => {
                parsed.sphere = match value.trim().parse::<u32>() {
                    Ok(l) if l <= 11 => l,
                    _ => return Err(format!("`{flag}`: `{value}` is not a level from 0 to 11")),
                }
            }
            "--rays" => parsed.rays = count(&flag, &value)?,
            "--crowd" => {
                parsed.crowd = usize::try_from(number(&flag, &value)?)
                    .map_err(|_| format!("`{flag}`: `{value}` is too large"))?;
            }
            "--side" => parsed.side = count(&flag, &value)?,
            "--only" => parsed.only = Some(value),
            "--scene" => parsed.scene = Some(value),
            "--runs" => parsed.runs = count(&flag, &value)?,
            "--offsets" if value.is_empty() => parsed.offsets.clear(),
            "--offsets" => {
                parsed.offsets = value
                    .split(',')
                    .map(|x| match x.trim().parse::<f64>() {
                        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
                        _ => Err(format!("`{flag}`: `{x}` is not a finite distance >= 0")),
                    })
                    .collect::<Result<_, _>>()?;
            }
            "--offset-rays" => parsed.offset_rays = count(&flag, &value)?,
            _ => parsed.seed = number(&flag, &value)?,
        }
    }
    if parsed.side.checked_mul(parsed.side).is_none() {
        return Err(format!("`--side`: {} is too large", parsed.side));
    }
    Ok(Some(parsed))
}

/// A `u64`, decimal or `0x` hexadecimal, `_` allowed between digits.
fn number(flag: &str, text: &str) -> Result<u64, String> {
    let digits = text.trim().replace('_', "");
    let parsed = match digits.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16),
        None => digits.parse(),
    };
    parsed.map_err(|_| format!("`{flag}`: `{text}` is not a number"))
}

/// A positive count.
fn count(flag: &str, text: &str) -> Result<usize, String> {
    match usize::try_from(number(flag, text)?) {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(format!("`{flag}`: `{text}` is not a positive count")),
    }
}

/// The closest hit: the triangle's position in the scene's list, and `t`.
type Hit = Option<(usize, f64)>;

/// hitkit's triangle test, the leaf test every library shares: keeps in `best` the closer
/// of its hit and `quad`'s, ties going to the smaller index as in hitkit's [`Bvh`]. Returns
/// the new closest `t` if `quad` became the best.
#[inline(always)]
fn closer(quad: &Quad<Triangle>, index: usize, ray: &Ray, best: &mut Hit) -> Option<f64> {
    let t_max = best.map_or(f64::INFINITY, |(_, t)| t);
    let hit = quad.hit(ray, Interval::new(0.0, t_max))?;
    if hit.t < t_max || best.is_none_or(|(b, _)| index < b) {
        *best = Some((index, hit.t));
        return Some(hit.t);
    }
    None
}

/// One library on one scene: the median build time and, per ray set (camera, random), the
/// median throughput and the hit of every ray from the last run.
struct Measured {
    library: String,
    build: Duration,
    sets: Vec<(f64, Vec<Hit>)>,
    /// The most bytes in use while building (the input the structure takes over included),
    /// and the bytes the built structure holds.
    peak: usize,
    kept: usize,
}

/// The median of `runs` calls of `f`, with `f`'s last result. `prepare` runs untimed
/// before each call (to copy the input a build consumes); results are dropped untimed.
fn median_time<I, T>(
    runs: usize,
    mut prepare: impl FnMut() -> I,
    mut f: impl FnMut(I) -> T,
) -> (Duration, T) {
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        let input = prepare();
        let start = Instant::now();
        let out = black_box(f(black_box(input)));
        times.push(start.elapsed());
        last = Some(out);
    }
    times.sort();
    (times[runs / 2], last.expect("runs > 0"))
}

/// Builds one library's hierarchy `runs` times (`prepare` makes the input untimed, `build`
/// is timed) and traces every ray set `runs` times with `trace`, one ray after another.
fn measure<I, B>(
    library: String,
    runs: usize,
    mut prepare: impl FnMut() -> I,
    mut build: impl FnMut(I) -> B,
    trace: impl Fn(&B, &Ray) -> Hit,
    ray_sets: &[&[Ray]],
) -> Measured {
    eprintln!("  {library}");
    // Memory first, in a pass of its own: everything allocated from before the input is
    // made until the structure is built, and what stays.
    let (peak, kept) = {
        let base = reset_peak();
        let built = black_box(build(prepare()));
        let kept = IN_USE.load(Relaxed) - base;
        let peak = PEAK.load(Relaxed) - base;
        drop(built);
        (peak, kept)
    };
    let (build_time, built) = median_time(runs, prepare, build);
    let sets = ray_sets
        .iter()
        .map(|rays| {
            let (time, hits) = median_time(
                runs,
                || (),
                |()| {
                    rays.iter()
                        .map(|ray| trace(&built, black_box(ray)))
                        .collect::<Vec<Hit>>()
                },
            );
            (rays.len() as f64 / time.as_secs_f64() / 1e6, hits)
        })
        .collect();
    Measured {
        library,
        build: build_time,
        sets,
        peak,
        kept,
    }
}

/// hitkit's own [`Bvh`], through [`Bvh::hit_with_index`].
fn run_hitkit(quads: &[Quad<Triangle>], runs: usize, ray_sets: &[&[Ray]]) -> Measured {
    measure(
        "hitkit".into(),
        runs,
        || quads.to_vec(),
        Bvh::new,
        |bvh, ray| {
            bvh.hit_with_index(ray, Interval::FORWARD)
                .map(|(index, hit)| (index, hit.t))
        },
        ray_sets,
    )
}

/// hitkit's [`TriangleMesh`] (its own tree and watertight test) on the scene's shared
/// vertices and faces; the hit's face is reported as its position among the scene's
/// non-degenerate triangles, as the other rows number them. With `parallel`, built with
/// [`TriangleMesh::new_parallel`] on every core.
fn run_mesh(scene: &Scene, parallel: bool, runs: usize, ray_sets: &[&[Ray]]) -> Measured {
    let position = scene.positions();
    let build = |()| {
        if parallel {
            TriangleMesh::new_parallel(&scene.vertices, &scene.faces)
        } else {
            TriangleMesh::new(&scene.vertices, &scene.faces)
        }
        .expect("a valid mesh")
    };
    measure(
        if parallel {
            "hitkit TriangleMesh (parallel build)".into()
        } else {
            "hitkit TriangleMesh".into()
        },
        runs,
        || (),
        build,
        |mesh, ray| {
            mesh.hit(ray, Interval::FORWARD)
                .map(|hit| (position[hit.primitive.expect("a face") as usize], hit.t))
        },
        ray_sets,
    )
}

/// obvhs on its own terms: its f32 `Triangle`s (48 bytes each: it has no shared
/// vertices), `build_cwbvh_from_tris` (medium preset), the triangles laid out in its
/// primitive order, and its own Möller-Trumbore test (`Triangle::intersect`, not
/// watertight) at the leaves.
fn run_obvhs_native(scene: &Scene, runs: usize, ray_sets: &[&[Ray]]) -> Measured {
    let position = scene.positions();
    let f = |p: DVec3| p.as_vec3a();
    measure(
        "obvhs 0.4 CWBVH medium, own f32 triangles".into(),
        runs,
        || -> Vec<obvhs::triangle::Triangle> {
            scene
                .faces
                .iter()
                .map(|&[a, b, c]| obvhs::triangle::Triangle {
                    v0: f(scene.vertices[a as usize]),
                    v1: f(scene.vertices[b as usize]),
                    v2: f(scene.vertices[c as usize]),
                })
                .collect()
        },
        |tris| {
            let tree = obvhs::cwbvh::builder::build_cwbvh_from_tris(
                &tris,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            );
            let ordered: Vec<obvhs::triangle::Triangle> = tree
                .primitive_indices
                .iter()
                .map(|&i| tris[i as usize])
                .collect();
            drop(tris);
            (tree, ordered)
        },
        |(tree, ordered), ray| {
            let obvhs_ray =
                obvhs::ray::Ray::new_inf(ray.origin.as_vec3a(), ray.direction.as_vec3a());
            let mut hit = RayHit::none();
            tree.ray_traverse(obvhs_ray, &mut hit, |r, id| ordered[id].intersect(r))
                .then(|| {
                    let face = tree.primitive_indices[hit.primitive_id as usize] as usize;
                    (position[face], f64::from(hit.t))
                })
        },
        ray_sets,
    )
}

/// A triangle as the `bvh` crate sees it: hitkit's exact f64 box, and the triangle itself
/// so the leaf test needs no second lookup.
#[derive(Clone)]
struct BvhShape {
    quad: Quad<Triangle>,
    aabb: bvh::aabb::Aabb<f64, 3>,
    index: usize,
    node: usize,
}

impl bvh::aabb::Bounded<f64, 3> for BvhShape {
    fn aabb(&self) -> bvh::aabb::Aabb<f64, 3> {
        self.aabb
    }
}

impl bvh::bounding_hierarchy::BHShape<f64, 3> for BvhShape {
    fn set_bh_node_index(&mut self, node: usize) {
        self.node = node;
    }

    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// The `bvh` crate, in f64: `Bvh::build` (its single-threaded SAH build), then
/// `nearest_traverse_iterator`, which yields leaves by increasing entry distance (a binary
/// heap of nodes). It has no closest-hit query, nor does it hand out the entry distance, so
/// we recompute the leaf box's entry and stop once it lies past the closest hit so far.
fn run_bvh_crate(quads: &[Quad<Triangle>], runs: usize, ray_sets: &[&[Ray]]) -> Measured {
    let point = |p: DVec3| Point3::new(p.x, p.y, p.z);
    let shapes: Vec<BvhShape> = quads
        .iter()
        .enumerate()
        .map(|(index, quad)| {
            let b = quad.bounding_box();
            let aabb = bvh::aabb::Aabb::with_bounds(point(b.min()), point(b.max()));
            BvhShape {
                quad: *quad,
                aabb,
                index,
                node: 0,
            }
        })
        .collect();
    measure(
        "bvh 0.13 (f64)".into(),
        runs,
        || shapes.clone(),
        |mut shapes| (bvh::bvh::Bvh::build(&mut shapes), shapes),
        |(tree, shapes), ray| {
            let d = ray.direction;
            // Its rays have unit directions: its distances are hitkit's t times |d|.
            let scale = d.length() * (1.0 + 1e-9);
            let bvh_ray = bvh::ray::Ray::new(point(ray.origin), Vector3::new(d.x, d.y, d.z));
            let mut best = None;
            for shape in tree.nearest_traverse_iterator(&bvh_ray, shapes) {
                if let Some((_, t)) = best {
                    let entry = bvh_ray.intersection_slice_for_aabb(&shape.aabb);
                    if entry.is_none_or(|(near, _)| near > t * scale) {
                        break;
                    }
                }
                closer(&shape.quad, shape.index, ray, &mut best);
            }
            best
        },
        ray_sets,
    )
}

/// `b` rounded to f32 outward, so that it still holds everything it held.
fn f32_box(b: &Aabb) -> obvhs::aabb::Aabb {
    let down = |x: f64| {
        let f = x as f32;
        if f64::from(f) > x { f.next_down() } else { f }
    };
    let up = |x: f64| -down(-x);
    let (lo, hi) = (b.min(), b.max());
    obvhs::aabb::Aabb::new(
        [down(lo.x), down(lo.y), down(lo.z)].into(),
        [up(hi.x), up(hi.y), up(hi.z)].into(),
    )
}

/// `x` rounded up to f32.
fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

/// obvhs's compressed wide BVH (CWBVH), f32, with build preset `preset`: `build_cwbvh` on
/// hitkit's boxes rounded outward (as `build_cwbvh_from_tris` does without pre-splits),
/// the triangles then laid out in its primitive order (as its examples do), and
/// `CwBvh::ray_traverse`, its closest-hit traversal, around hitkit's test. The `t` handed
/// back is rounded up, so that culling against it never drops a nearer hit. Its node test
/// starts rays at `t = 1e-4` (`cwbvh::node::EPSILON`, absolute, whatever the ray's
/// `tmin`): hits nearer the origin than that are lost, and the hit counts can differ.
fn run_obvhs(
    quads: &[Quad<Triangle>],
    preset: &str,
    params: BvhBuildParams,
    runs: usize,
    ray_sets: &[&[Ray]],
) -> Measured {
    let boxes: Vec<_> = quads.iter().map(|q| f32_box(&q.bounding_box())).collect();
    measure(
        format!("obvhs 0.4 CWBVH {preset}"),
        runs,
        || (),
        |()| {
            let tree = build_cwbvh(&boxes, params, &mut Duration::default());
            let ordered: Vec<(usize, Quad<Triangle>)> = tree
                .primitive_indices
                .iter()
                .map(|&i| (i as usize, quads[i as usize]))
                .collect();
            (tree, ordered)
        },
        |(tree, ordered): &(CwBvh, Vec<(usize, Quad<Triangle>)>), ray| {
            let obvhs_ray =
                obvhs::ray::Ray::new_inf(ray.origin.as_vec3a(), ray.direction.as_vec3a());
            let mut best = None;
            tree.ray_traverse(obvhs_ray, &mut RayHit::none(), |_, id| {
                let (index, quad) = &ordered[id];
                closer(quad, *index, ray, &mut best).map_or(f32::INFINITY, f32_up)
            });
            best
        },
        ray_sets,
    )
}

/// A scene as a mesh: vertices, and faces naming them (shared where the source shares
/// them: the bunny and the sphere; a soup's triangles each own three).
struct Scene {
    name: String,
    vertices: Vec<DVec3>,
    faces: Vec<[u32; 3]>,
}

impl Scene {
    /// A soup: every triangle its own three vertices.
    fn soup(name: String, tris: &[workloads::Tri]) -> Self {
        Self {
            name,
            vertices: tris.iter().flatten().copied().collect(),
            faces: (0..tris.len() as u32)
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect(),
        }
    }

    fn tris(&self) -> Vec<workloads::Tri> {
        self.faces
            .iter()
            .map(|f| f.map(|i| self.vertices[i as usize]))
            .collect()
    }

    /// For each face, its position among the triangles [`quads`] keeps (`usize::MAX` for
    /// one it drops): how the rows on [`TriangleMesh`] and on obvhs's own triangles number
    /// their hits as the other rows do.
    fn positions(&self) -> Vec<usize> {
        let mut next = 0;
        self.tris()
            .iter()
            .map(|&[a, b, c]| {
                if Quad::with_interior(a, b - a, c - a, Triangle).is_ok() {
                    next += 1;
                    next - 1
                } else {
                    usize::MAX
                }
            })
            .collect()
    }
}

/// The OBJ file at `path`, triangulated, its models' vertices and faces merged.
fn load_obj(name: &str, path: &Path) -> Result<Scene, tobj::LoadError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &options)?;
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for model in models {
        let mesh = model.mesh;
        let base = vertices.len() as u32;
        vertices.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0], p[1], p[2])),
        );
        faces.extend(
            mesh.indices
                .chunks_exact(3)
                .map(|f| [f[0] + base, f[1] + base, f[2] + base]),
        );
    }
    Ok(Scene {
        name: name.to_owned(),
        vertices,
        faces,
    })
}

/// The triangles hitkit accepts (the degenerate ones dropped): the one list every library
/// gets.
fn quads(tris: &[workloads::Tri]) -> Vec<Quad<Triangle>> {
    tris.iter()
        .filter_map(|&[a, b, c]| Quad::with_interior(a, b - a, c - a, Triangle).ok())
        .collect()
}

/// Rays that hit, and the sum of their `t`.
fn summary(hits: &[Hit]) -> (usize, f64) {
    hits.iter()
        .flatten()
        .fold((0, 0.0), |(n, sum), &(_, t)| (n + 1, sum + t))
}

/// How `hits` differ from hitkit's `reference`, if they do: the hit counts, the rays whose
/// hit differs, and the largest `t` hitkit found on those rays (obvhs, for one, culls every
/// box the ray leaves before `t = 1e-4`).
fn compare(reference: &[Hit], hits: &[Hit]) -> Option<String> {
    let differ: Vec<&Hit> = reference
        .iter()
        .zip(hits)
        .filter(|(a, b)| a.map(|h| h.0) != b.map(|h| h.0))
        .map(|(a, _)| a)
        .collect();
    if differ.is_empty() {
        return None;
    }
    let t_max = differ
        .iter()
        .filter_map(|h| h.map(|h| h.1))
        .fold(f64::NEG_INFINITY, f64::max);
    Some(format!(
        "{} hits, hitkit {}; {} rays hit another triangle or none (hitkit's hits on them at t <= {t_max:.3e})",
        summary(hits).0,
        summary(reference).0,
        differ.len(),
    ))
}

/// Measures every library on one scene (with `mesh_only`, only hitkit's `TriangleMesh`
/// and obvhs on its own triangles); returns the table rows, the checksum rows, and
/// warnings where a library's hits differ from hitkit's.
fn run_scene(scene: &Scene, args: &Args) -> (Vec<String>, Vec<String>, Vec<String>) {
    let name = scene.name.as_str();
    let tris = scene.tris();
    let quads = quads(&tris);
    let bounds = workloads::bounds(&tris);
    drop(tris);
    let camera = workloads::camera_rays(bounds, args.side);
    let random = workloads::random_rays(bounds, args.rays, args.seed.wrapping_add(1));
    let sets: [&[Ray]; 2] = [&camera, &random];
    eprintln!("{name}: {} triangles", quads.len());
    let mut results = Vec::new();
    if !args.mesh_only {
        results.push(run_hitkit(&quads, args.runs, &sets));
    }
    results.push(run_mesh(scene, false, args.runs, &sets));
    results.push(run_mesh(scene, true, args.runs, &sets));
    if !args.mesh_only {
        results.push(run_bvh_crate(&quads, args.runs, &sets));
        results.push(run_obvhs(
            &quads,
            "fast",
            BvhBuildParams::fast_build(),
            args.runs,
            &sets,
        ));
        results.push(run_obvhs(
            &quads,
            "medium",
            BvhBuildParams::medium_build(),
            args.runs,
            &sets,
        ));
    }
    results.push(run_obvhs_native(scene, args.runs, &sets));
    let faces = scene.faces.len() as f64;
    let (mut rows, mut checks, mut warnings) = (Vec::new(), Vec::new(), Vec::new());
    for m in &results {
        let [(camera_speed, camera_hits), (random_speed, random_hits)] = &m.sets[..] else {
            unreachable!("two ray sets")
        };
        let (cn, csum) = summary(camera_hits);
        let (rn, rsum) = summary(random_hits);
        rows.push(format!(
            "| {name} | {} | {} | {:.1} | {camera_speed:.2} | {random_speed:.2} | {:.0} | {:.0} | {cn} | {rn} |",
            quads.len(),
            m.library,
            m.build.as_secs_f64() * 1e3,
            m.peak as f64 / faces,
            m.kept as f64 / faces,
        ));
        checks.push(format!(
            "| {name} | {} | {csum:.5e} | {rsum:.5e} |",
            m.library
        ));
        for (set, (reference, (_, hits))) in ["camera", "random"]
            .iter()
            .zip(results[0].sets.iter().map(|s| &s.1).zip(&m.sets))
        {
            if let Some(difference) = compare(reference, hits) {
                warnings.push(format!(
                    "WARNING: {name}, {set} rays, {}: {difference}",
                    m.library
                ));
            }
        }
    }
    if quads.len() < scene.faces.len() {
        warnings.push(format!(
            "note: {name}: {} degenerate triangles dropped",
            scene.faces.len() - quads.len()
        ));
    }
    (rows, checks, warnings)
}

/// The direction scenes are moved along (off the axes, so that every coordinate rounds).
const OFFSET_DIRECTION: DVec3 = DVec3::new(0.8, 0.36, -0.48);

/// hitkit and obvhs (its medium preset) on `tris` moved by each offset: Mrays/s (median of
/// `runs`) and triangle tests per ray (counted in a separate, untimed pass), for camera and
/// random rays made from the moved scene's bounds the same way at every offset. Rows of the
/// second table.
fn run_offsets(name: &str, tris: &[workloads::Tri], args: &Args) -> Vec<String> {
    let side = (args.offset_rays as f64).sqrt().ceil() as usize;
    let mut rows = Vec::new();
    for &offset in &args.offsets {
        let shift = offset * OFFSET_DIRECTION;
        let moved: Vec<workloads::Tri> = tris.iter().map(|t| t.map(|p| p + shift)).collect();
        let quads = quads(&moved);
        let bounds = workloads::bounds(&moved);
        let camera = workloads::camera_rays(bounds, side);
        let random = workloads::random_rays(bounds, args.offset_rays, args.seed.wrapping_add(1));
        let sets: [&[Ray]; 2] = [&camera, &random];
        eprintln!("{name} at offset {offset:e}");

        // Triangle tests per ray, counted through a second hierarchy over counting shapes.
        // (Atomic because shapes are Send + Sync; the pass is untimed.)
        let tests = AtomicU64::new(0);
        let counted: Vec<Counted> = quads.iter().map(|q| Counted(*q, &tests)).collect();
        let hitkit_bvh = Bvh::new(counted);
        let obvhs_boxes: Vec<_> = quads.iter().map(|q| f32_box(&q.bounding_box())).collect();
        let obvhs_tree = build_cwbvh(
            &obvhs_boxes,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let per_ray = |trace: &dyn Fn(&Ray)| {
            sets.map(|rays| {
                tests.store(0, Relaxed);
                rays.iter().for_each(trace);
                tests.load(Relaxed) as f64 / rays.len() as f64
            })
        };
        let hitkit_tests = per_ray(&|ray| {
            hitkit_bvh.hit(ray, Interval::FORWARD);
        });
        let obvhs_tests = per_ray(&|ray| {
            let obvhs_ray =
                obvhs::ray::Ray::new_inf(ray.origin.as_vec3a(), ray.direction.as_vec3a());
            let mut best = None;
            obvhs_tree.ray_traverse(obvhs_ray, &mut RayHit::none(), |_, id| {
                let i = obvhs_tree.primitive_indices[id] as usize;
                tests.fetch_add(1, Relaxed);
                closer(&quads[i], i, ray, &mut best).map_or(f32::INFINITY, f32_up)
            });
        });

        let timed = [
            run_hitkit(&quads, args.runs, &sets),
            run_obvhs(
                &quads,
                "medium",
                BvhBuildParams::medium_build(),
                args.runs,
                &sets,
            ),
        ];
        for (m, counts) in timed.iter().zip([hitkit_tests, obvhs_tests]) {
            rows.push(format!(
                "| {name} | {offset:.0e} | {} | {:.2} | {:.2} | {:.1} | {:.1} |",
                m.library, m.sets[0].0, m.sets[1].0, counts[0], counts[1]
            ));
        }
    }
    rows
}

/// A triangle that counts its tests, for the offsets table.
struct Counted<'a>(Quad<Triangle>, &'a AtomicU64);

impl Hittable for Counted<'_> {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<hitkit::HitRecord> {
        self.1.fetch_add(1, Relaxed);
        self.0.hit(ray, ray_t)
    }
    fn bounding_box(&self) -> Aabb {
        self.0.bounding_box()
    }
}

fn main() -> ExitCode {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(Some(args)) => args,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}\n\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let mut scenes = Vec::new();
    match load_obj("bunny", &args.obj) {
        Ok(scene) => scenes.push(scene),
        Err(e) => eprintln!(
            "warning: skipping the bunny: cannot load {}: {e}",
            args.obj.display()
        ),
    }
    if args.triad {
        triad::run(&triad::scenes(scenes.first(), &args), &args);
        return ExitCode::SUCCESS;
    }
    for &n in &args.soups {
        scenes.push(Scene::soup(
            format!("soup {n}"),
            &workloads::triangle_soup(n, args.seed),
        ));
    }
    if args.sphere > 0 {
        let (vertices, faces) = workloads::icosphere(args.sphere);
        scenes.push(Scene {
            name: format!("closed sphere {}", faces.len()),
            vertices,
            faces,
        });
    }
    if args.lights {
        lights::print(&lights::run(&args), &args);
        return ExitCode::SUCCESS;
    }
    if args.halls && args.picks {
        halls::print_picks(&args);
        return ExitCode::SUCCESS;
    }
    if args.halls {
        halls::print(&args);
        return ExitCode::SUCCESS;
    }
    if args.updates {
        let (mut times, mut rows, mut churns) = (Vec::new(), Vec::new(), Vec::new());
        for scene in &scenes {
            let (t, r) = updates::run(scene, &args);
            times.push(t);
            rows.extend(r);
            churns.extend(updates::churn(scene, &args));
        }
        updates::print(&times, &rows, &churns, &args);
        return ExitCode::SUCCESS;
    }
    let (mut rows, mut checks, mut warnings) = (Vec::new(), Vec::new(), Vec::new());
    for scene in &scenes {
        let (r, c, w) = run_scene(scene, &args);
        rows.extend(r);
        checks.extend(c);
        warnings.extend(w);
    }

    println!(
        "{}; single-threaded (but the build of the row marked parallel build, on every core); {} camera rays ({side} x {side}), {} random rays; median of {} runs; seed {:#x}\n",
        workloads::machine(),
        args.side * args.side,
        args.rays,
        args.runs,
        args.seed,
        side = args.side,
    );
    println!(
        "| scene | triangles | library | build ms | camera Mrays/s | random Mrays/s | peak B/tri | kept B/tri | camera hits | random hits |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    rows.iter().for_each(|r| println!("{r}"));
    println!("\nChecksums (sum of t over the hits):\n");
    println!("| scene | library | camera | random |");
    println!("|---|---|---:|---:|");
    checks.iter().for_each(|c| println!("{c}"));
    if !warnings.is_empty() {
        println!();
        warnings.iter().for_each(|w| println!("{w}"));
    }
    if let Some(first) = scenes.first().filter(|_| !args.offsets.is_empty()) {
        let name = &first.name;
        let rows = run_offsets(name, &first.tris(), &args);
        println!(
            "\nThe {name} moved by each offset along {OFFSET_DIRECTION} (every coordinate \
             rounds); {} camera rays and {} random rays from the moved bounds; Mrays/s median \
             of {} runs; triangle tests per ray counted in a separate pass:\n",
            {
                let side = (args.offset_rays as f64).sqrt().ceil() as usize;
                side * side
            },
            args.offset_rays,
            args.runs,
        );
        println!(
            "| scene | offset | library | camera Mrays/s | random Mrays/s | camera tests/ray | random tests/ray |"
        );
        println!("|---|---:|---|---:|---:|---:|---:|");
        rows.iter().for_each(|r| println!("{r}"));
    }
    ExitCode::SUCCESS
}
