//! Runs the same scenes and the same rays through hitkit, the `bvh` crate and `obvhs`,
//! single-threaded, in one process, and prints a Markdown table.
//!
//! Every library finds the closest hit with hitkit's own f64 triangle test at its leaves, so
//! the hits must agree and the timings compare hierarchies and traversals.
//!
//! `cargo run --release -p hitkit-peers -- --help`

#[path = "../../../tests/support/scene.rs"]
mod scene;

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicU64;
use std::sync::atomic::Ordering::Relaxed;
use std::time::{Duration, Instant};

use hitkit::glam::DVec3;
use hitkit::{Aabb, Bvh, Hittable, Interval, Quad, Ray, Triangle};
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
    rays: usize,
    side: usize,
    runs: usize,
    seed: u64,
    offsets: Vec<f64>,
    offset_rays: usize,
}

/// Parses the arguments after the program name: `Ok(None)` for `--help`.
fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Option<Args>, String> {
    let mut parsed = Args {
        obj: PathBuf::from("../shared/data/stanford-bunny.obj"),
        soups: vec![1_000, 1_000_000],
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
        if ![
            "--obj",
            "--soups",
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
            "--rays" => parsed.rays = count(&flag, &value)?,
            "--side" => parsed.side = count(&flag, &value)?,
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
    prepare: impl FnMut() -> I,
    build: impl FnMut(I) -> B,
    trace: impl Fn(&B, &Ray) -> Hit,
    ray_sets: &[&[Ray]],
) -> Measured {
    eprintln!("  {library}");
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

/// The triangles of the OBJ file at `path`, triangulated.
fn load_obj(path: &Path) -> Result<Vec<scene::Tri>, tobj::LoadError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &options)?;
    let mut tris = Vec::new();
    for model in models {
        let mesh = model.mesh;
        let vertex = |i: u32| {
            let p = &mesh.positions[3 * i as usize..][..3];
            DVec3::new(p[0], p[1], p[2])
        };
        tris.extend(
            mesh.indices
                .chunks_exact(3)
                .map(|f| [vertex(f[0]), vertex(f[1]), vertex(f[2])]),
        );
    }
    Ok(tris)
}

/// The triangles hitkit accepts (the degenerate ones dropped): the one list every library
/// gets.
fn quads(tris: &[scene::Tri]) -> Vec<Quad<Triangle>> {
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

/// Measures every library on one scene; returns the table rows, the checksum rows, and
/// warnings where a library's hits differ from hitkit's.
fn run_scene(
    name: &str,
    tris: &[scene::Tri],
    args: &Args,
) -> (Vec<String>, Vec<String>, Vec<String>) {
    let quads = quads(tris);
    let bounds = scene::bounds(tris);
    let camera = scene::camera_rays(bounds, args.side);
    let random = scene::random_rays(bounds, args.rays, args.seed.wrapping_add(1));
    let sets: [&[Ray]; 2] = [&camera, &random];
    eprintln!("{name}: {} triangles", quads.len());
    let results = [
        run_hitkit(&quads, args.runs, &sets),
        run_bvh_crate(&quads, args.runs, &sets),
        run_obvhs(
            &quads,
            "fast",
            BvhBuildParams::fast_build(),
            args.runs,
            &sets,
        ),
        run_obvhs(
            &quads,
            "medium",
            BvhBuildParams::medium_build(),
            args.runs,
            &sets,
        ),
    ];
    let (mut rows, mut checks, mut warnings) = (Vec::new(), Vec::new(), Vec::new());
    for m in &results {
        let [(camera_speed, camera_hits), (random_speed, random_hits)] = &m.sets[..] else {
            unreachable!("two ray sets")
        };
        let (cn, csum) = summary(camera_hits);
        let (rn, rsum) = summary(random_hits);
        rows.push(format!(
            "| {name} | {} | {} | {:.1} | {camera_speed:.2} | {random_speed:.2} | {cn} | {rn} |",
            quads.len(),
            m.library,
            m.build.as_secs_f64() * 1e3,
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
    if quads.len() < tris.len() {
        warnings.push(format!(
            "note: {name}: {} degenerate triangles dropped",
            tris.len() - quads.len()
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
fn run_offsets(name: &str, tris: &[scene::Tri], args: &Args) -> Vec<String> {
    let side = (args.offset_rays as f64).sqrt().ceil() as usize;
    let mut rows = Vec::new();
    for &offset in &args.offsets {
        let shift = offset * OFFSET_DIRECTION;
        let moved: Vec<scene::Tri> = tris.iter().map(|t| t.map(|p| p + shift)).collect();
        let quads = quads(&moved);
        let bounds = scene::bounds(&moved);
        let camera = scene::camera_rays(bounds, side);
        let random = scene::random_rays(bounds, args.offset_rays, args.seed.wrapping_add(1));
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
    match load_obj(&args.obj) {
        Ok(tris) => scenes.push(("bunny".to_owned(), tris)),
        Err(e) => eprintln!(
            "warning: skipping the bunny: cannot load {}: {e}",
            args.obj.display()
        ),
    }
    for &n in &args.soups {
        scenes.push((format!("soup {n}"), scene::triangle_soup(n, args.seed)));
    }
    let (mut rows, mut checks, mut warnings) = (Vec::new(), Vec::new(), Vec::new());
    for (name, tris) in &scenes {
        let (r, c, w) = run_scene(name, tris, &args);
        rows.extend(r);
        checks.extend(c);
        warnings.extend(w);
    }

    println!(
        "{}; single-threaded; {} camera rays ({side} x {side}), {} random rays; median of {} runs; seed {:#x}\n",
        scene::machine(),
        args.side * args.side,
        args.rays,
        args.runs,
        args.seed,
        side = args.side,
    );
    println!(
        "| scene | triangles | library | build ms | camera Mrays/s | random Mrays/s | camera hits | random hits |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|");
    rows.iter().for_each(|r| println!("{r}"));
    println!("\nChecksums (sum of t over the hits):\n");
    println!("| scene | library | camera | random |");
    println!("|---|---|---:|---:|");
    checks.iter().for_each(|c| println!("{c}"));
    if !warnings.is_empty() {
        println!();
        warnings.iter().for_each(|w| println!("{w}"));
    }
    if let Some((name, tris)) = scenes.first().filter(|_| !args.offsets.is_empty()) {
        let rows = run_offsets(name, tris, &args);
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
