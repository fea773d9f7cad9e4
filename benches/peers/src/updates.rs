//! `--updates`: what moving a mesh costs. A refit of hitkit's `TriangleMesh`
//! (`set_vertices`) against its rebuild and against obvhs's refit of its own binary tree on
//! the same triangles; then the rays a refitted tree traces per second as the deformation
//! grows, against a tree built afresh on the deformed mesh, with the cost the tree reports;
//! and a `Bvh` of the same triangles after a run of inserts and removes, against a rebuild.

use hitkit_render::workloads;
use std::hint::black_box;
use std::time::{Duration, Instant};

use hitkit::glam::DVec3;
use hitkit::{Bvh, Hittable, Interval, Quad, Ray, Triangle, TriangleMesh};
use obvhs::BvhBuildParams;
use obvhs::bvh2::builder::build_bvh2_from_tris;

use super::{Args, Scene, median_time, quads};

/// How far the deformation goes, as the largest twist at the mesh's top and bottom: a
/// point at the top turns by `amount * 90` degrees about the vertical axis through the
/// mesh's centre, one at the bottom by as much the other way, one between in proportion.
const AMOUNTS: [f64; 5] = [0.0, 0.1, 0.25, 0.5, 1.0];

/// The vertices twisted by `amount` (see [`AMOUNTS`]).
fn twist(vertices: &[DVec3], amount: f64) -> Vec<DVec3> {
    let (lo, hi) = vertices
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let centre = 0.5 * (lo + hi);
    let height = (hi.y - lo.y).max(f64::MIN_POSITIVE);
    vertices
        .iter()
        .map(|&p| {
            let angle = amount * std::f64::consts::PI * (p.y - centre.y) / height;
            let (s, c) = angle.sin_cos();
            let (x, z) = (p.x - centre.x, p.z - centre.z);
            DVec3::new(centre.x + c * x - s * z, p.y, centre.z + s * x + c * z)
        })
        .collect()
}

/// The largest distance a vertex moved, relative to the diagonal of the mesh's box.
fn moved(from: &[DVec3], to: &[DVec3]) -> f64 {
    let (lo, hi) = from
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let most = from
        .iter()
        .zip(to)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    most / (hi - lo).length()
}

/// Mrays/s of closest hits through `mesh`, median of `runs`, and every ray's hit (face and
/// `t`) from the last run.
fn trace(mesh: &TriangleMesh, rays: &[Ray], runs: usize) -> (f64, Vec<Option<(u32, f64)>>) {
    let (time, hits) = median_time(
        runs,
        || (),
        |()| {
            rays.iter()
                .map(|ray| {
                    mesh.hit(black_box(ray), Interval::FORWARD)
                        .map(|h| (h.primitive.unwrap_or(u32::MAX), h.t))
                })
                .collect::<Vec<_>>()
        },
    );
    (rays.len() as f64 / time.as_secs_f64() / 1e6, hits)
}

fn ms(d: Duration) -> String {
    format!("{:.1}", d.as_secs_f64() * 1e3)
}

/// The two tables' rows for one scene.
pub(super) fn run(scene: &Scene, args: &Args) -> (String, Vec<String>) {
    let name = &scene.name;
    eprintln!("{name}: updates");
    let faces = &scene.faces;
    let twisted = twist(&scene.vertices, AMOUNTS[1]);
    // obvhs: its binary tree (medium preset) over its f32 triangles; a refit sets every
    // leaf's box to the union of its triangles' boxes, then `refit_all` the inner ones.
    let to_tris = |v: &[DVec3]| -> Vec<obvhs::triangle::Triangle> {
        faces
            .iter()
            .map(|&[a, b, c]| obvhs::triangle::Triangle {
                v0: v[a as usize].as_vec3a(),
                v1: v[b as usize].as_vec3a(),
                v2: v[c as usize].as_vec3a(),
            })
            .collect()
    };
    let (original, moved_tris) = (to_tris(&scene.vertices), to_tris(&twisted));
    let mut bvh2 = build_bvh2_from_tris(
        &original,
        BvhBuildParams::medium_build(),
        &mut Duration::default(),
    );
    let mut mesh = TriangleMesh::new(&scene.vertices, faces).expect("a valid mesh");
    // In alternation, run after run: hitkit's rebuild, its refit, obvhs's refit, each to
    // the twisted mesh and back on every other run.
    let (mut rebuilds, mut refits, mut obvhs_refits) = (Vec::new(), Vec::new(), Vec::new());
    for run in 0..args.runs {
        let (v, tris) = if run % 2 == 0 {
            (&twisted, &moved_tris)
        } else {
            (&scene.vertices, &original)
        };
        let start = Instant::now();
        let rebuilt = black_box(TriangleMesh::new(black_box(v), faces).expect("a valid mesh"));
        rebuilds.push(start.elapsed());
        drop(rebuilt);
        let start = Instant::now();
        mesh.set_vertices(black_box(v)).expect("valid vertices");
        refits.push(start.elapsed());
        let start = Instant::now();
        for i in 0..bvh2.nodes.len() {
            let node = bvh2.nodes[i];
            if node.is_leaf() {
                let first = node.first_index as usize;
                let mut aabb = obvhs::aabb::Aabb::INVALID;
                for &p in &bvh2.primitive_indices[first..first + node.prim_count as usize] {
                    aabb = aabb.union(&tris[p as usize].aabb());
                }
                bvh2.nodes[i].set_aabb(aabb);
            }
        }
        bvh2.refit_all();
        black_box(&bvh2);
        obvhs_refits.push(start.elapsed());
    }
    let median = |mut times: Vec<Duration>| {
        times.sort();
        times[times.len() / 2]
    };
    let (rebuild, refit, obvhs_refit) = (median(rebuilds), median(refits), median(obvhs_refits));
    let times = format!(
        "| {name} | {} | {} | {} | {} | {:.1}x | {:.2}x |",
        faces.len(),
        ms(rebuild),
        ms(refit),
        ms(obvhs_refit),
        rebuild.as_secs_f64() / refit.as_secs_f64(),
        obvhs_refit.as_secs_f64() / refit.as_secs_f64(),
    );

    // Throughput as the deformation grows: the tree built on the undeformed mesh and
    // refitted, against one built on the deformed mesh; the same rays for both.
    let mut rows = Vec::new();
    let base = TriangleMesh::new(&scene.vertices, faces).expect("a valid mesh");
    for amount in AMOUNTS {
        let v = twist(&scene.vertices, amount);
        let mut refitted = base.clone();
        refitted.set_vertices(&v).expect("valid vertices");
        let fresh = TriangleMesh::new(&v, faces).expect("a valid mesh");
        let tris: Vec<workloads::Tri> = faces.iter().map(|f| f.map(|i| v[i as usize])).collect();
        let bounds = workloads::bounds(&tris);
        drop(tris);
        let camera = workloads::camera_rays(bounds, args.side);
        let random = workloads::random_rays(bounds, args.rays, args.seed.wrapping_add(1));
        let mut speeds = Vec::new();
        for rays in [&camera, &random] {
            let (a, hits_a) = trace(&refitted, rays, args.runs);
            let (b, hits_b) = trace(&fresh, rays, args.runs);
            // Both answer as the loop over the faces: the same face at the same t.
            assert!(hits_a == hits_b, "the refitted and the fresh mesh disagree");
            speeds.push((a, b));
        }
        let cost = refitted.cost();
        rows.push(format!(
            "| {name} | {:.0}° | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
            amount * 90.0,
            moved(&scene.vertices, &v),
            speeds[0].0,
            speeds[0].1,
            speeds[1].0,
            speeds[1].1,
            cost.ratio(),
            fresh.cost().now / cost.built,
        ));
    }
    (times, rows)
}

/// How many changes the churn row makes: half removals, half insertions.
const CHURN: usize = 10_000;

/// The shares of the lanes that `Bvh::optimize` reinserts in the churn table: none (the
/// boxes only shrunk), the one its docs suggest, and all.
const SHARES: [f64; 3] = [0.0, 0.1, 1.0];

/// A `Bvh<Quad<Triangle>>` of the scene's triangles after [`CHURN`] changes in turn:
/// a random live triangle removed, then a triangle inserted (the one removed, moved to a
/// random place in the scene's box); then `Bvh::optimize` of the changed tree at each of
/// [`SHARES`], and a rebuild of the changed set: for each tree, the time it took (median of
/// `runs`, each on a copy of the tree before), its rays per second and its cost. A row each.
pub(super) fn churn(scene: &Scene, args: &Args) -> Vec<String> {
    let name = &scene.name;
    eprintln!("{name}: {CHURN} inserts and removes");
    let triangles = quads(&scene.tris());
    let built = Bvh::new(triangles.clone());
    let bounds = workloads::bounds(&scene.tris());
    let (lo, hi) = bounds;
    let changes = |mut bvh: Bvh<Quad<Triangle>>| {
        let mut rng = workloads::SplitMix::new(args.seed.wrapping_add(2));
        let mut live: Vec<usize> = (0..bvh.len()).collect();
        for _ in 0..CHURN / 2 {
            let pick = rng.next_u64() as usize % live.len();
            let number = live.swap_remove(pick);
            let quad = bvh.remove(number).expect("a live number");
            let (u, v) = (quad.plane().u(), quad.plane().v());
            let to = lo + (hi - lo) * rng.vec3();
            let moved =
                Quad::with_interior(to - (u + v) / 3.0, u, v, Triangle).expect("a moved triangle");
            live.push(bvh.insert(moved));
        }
        bvh
    };
    let (time, changed) = median_time(args.runs, || built.clone(), changes);
    let mut trees = vec![(format!("{CHURN} changes"), time, changed.clone())];
    for share in SHARES {
        let (time, optimized) = median_time(
            args.runs,
            || changed.clone(),
            |mut bvh| {
                bvh.optimize(share);
                bvh
            },
        );
        trees.push((format!("then `optimize({share})`"), time, optimized));
    }
    let set: Vec<Quad<Triangle>> = changed.objects().to_vec();
    let (rebuild, fresh) = median_time(args.runs, || set.clone(), Bvh::new);
    trees.push(("`Bvh::new` of the changed set".into(), rebuild, fresh));
    let camera = workloads::camera_rays(bounds, args.side);
    let random = workloads::random_rays(bounds, args.rays, args.seed.wrapping_add(1));
    let mut speeds = vec![Vec::new(); trees.len()];
    for rays in [&camera, &random] {
        let mut hits = Vec::new();
        for ((_, _, bvh), speeds) in trees.iter().zip(&mut speeds) {
            let (t, h) = median_time(
                args.runs,
                || (),
                |()| {
                    rays.iter()
                        .map(|ray| {
                            bvh.hit_with_index(black_box(ray), Interval::FORWARD)
                                .map(|(_, hit)| hit.t)
                        })
                        .collect::<Vec<_>>()
                },
            );
            speeds.push(rays.len() as f64 / t.as_secs_f64() / 1e6);
            hits.push(h);
        }
        // The same objects in every tree: the same hits (of equal `t`; which object of a
        // tie is named depends on the numbers, which differ between the rebuilt tree and
        // the others).
        assert!(
            hits.iter().all(|h| *h == hits[0]),
            "the changed, optimized and rebuilt trees disagree"
        );
    }
    let built_cost = changed.cost().built;
    trees
        .iter()
        .zip(&speeds)
        .map(|((tree, time, bvh), speeds)| {
            format!(
                "| {name} | {} | {tree} | {:.1} | {:.2} | {:.2} | {:.2} |",
                triangles.len(),
                time.as_secs_f64() * 1e3,
                speeds[0],
                speeds[1],
                bvh.cost().now / built_cost,
            )
        })
        .collect()
}

/// Prints both tables' headers and rows.
pub(super) fn print(times: &[String], rows: &[String], churns: &[String], args: &Args) {
    println!(
        "{}; single-threaded; median of {} runs, taken in alternation (hitkit's rebuild, its refit, obvhs's refit; to the mesh twisted by 9 degrees and back)\n",
        workloads::machine(),
        args.runs
    );
    println!(
        "| scene | triangles | hitkit rebuild ms | hitkit refit ms | obvhs 0.4 refit ms (bvh2, medium) | rebuild / refit | obvhs refit / hitkit refit |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    times.iter().for_each(|r| println!("{r}"));
    println!(
        "\nThe mesh twisted about its vertical axis (its top by the angle, its bottom by as much the other way): Mrays/s of the tree refitted from the untwisted mesh and of one built afresh; {} camera rays, {} random rays; the refitted tree's cost by the surface area heuristic against its cost at build, and the fresh tree's:\n",
        args.side * args.side,
        args.rays,
    );
    println!(
        "| scene | twist | moved / size | refit camera | fresh camera | refit random | fresh random | refit cost ratio | fresh cost ratio |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    rows.iter().for_each(|r| println!("{r}"));
    println!(
        "\nA `Bvh<Quad<Triangle>>` of the same triangles after {CHURN} changes in turn (a random live triangle removed, then that triangle inserted again at a random place in the scene's box); that tree mended by `Bvh::optimize` (every box shrunk to what it holds, then the given share of its lanes, leaves and subtrees, taken out and put back where the heuristic places them), and rebuilt from scratch. The time each took (the changes, the optimization of the changed tree, the rebuild), Mrays/s on the same rays as above, and each tree's cost against the cost of the tree first built:\n"
    );
    println!("| scene | triangles | tree | ms | camera | random | cost ratio |");
    println!("|---|---:|---|---:|---:|---:|---:|");
    churns.iter().for_each(|r| println!("{r}"));
}
