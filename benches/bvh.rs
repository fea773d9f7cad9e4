//! BVH build time and closest-hit throughput on random triangle soups (fixed seed), with
//! incoherent and coherent rays, and the same scene behind static and dynamic dispatch;
//! and instancing: a thousand moved instances of one shared mesh against the same
//! triangles flattened into one mesh.
//!
//! `cargo bench --bench bvh`; the scenes and rays are those of `benches/peers`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use hitkit::glam::DVec3;
use hitkit::{Bvh, Hittable, Interval, Quad, Ray, Triangle, TriangleMesh};

use hitkit_render::workloads;

const SEED: u64 = 0x5eed;
/// Rays traced per measured iteration.
const RAYS: usize = 10_000;

fn triangles(n: usize) -> Vec<Quad<Triangle>> {
    workloads::triangle_soup(n, SEED)
        .into_iter()
        .filter_map(|[a, b, c]| Quad::with_interior(a, b - a, c - a, Triangle).ok())
        .collect()
}

fn trace<H: Hittable + ?Sized>(scene: &H, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|r| black_box(scene.hit(r, Interval::FORWARD)).is_some())
        .count()
}

fn build(c: &mut Criterion) {
    let mut group = c.benchmark_group("build");
    group.sample_size(10);
    for n in [1_000, 10_000, 100_000, 1_000_000] {
        let tris = triangles(n);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &tris, |b, tris| {
            b.iter_batched(
                || tris.clone(),
                |t| Bvh::new(black_box(t)),
                criterion::BatchSize::LargeInput,
            );
        });
    }
    group.finish();
}

fn closest_hit(c: &mut Criterion) {
    let mut group = c.benchmark_group("closest_hit");
    group.throughput(Throughput::Elements(RAYS as u64));
    for n in [1_000, 100_000, 1_000_000] {
        let tris = triangles(n);
        let bounds = workloads::bounds(&workloads::triangle_soup(n, SEED));
        let incoherent = workloads::random_rays(bounds, RAYS, SEED + 1);
        let coherent = workloads::camera_rays(bounds, 100);
        let fixed = Bvh::new(tris.clone());
        let boxed: Bvh<Box<dyn Hittable>> = Bvh::new(
            tris.into_iter()
                .map(|t| Box::new(t) as Box<dyn Hittable>)
                .collect(),
        );
        for (kind, rays) in [("random", &incoherent), ("camera", &coherent)] {
            group.bench_with_input(
                BenchmarkId::new(format!("static/{kind}"), n),
                rays,
                |b, rays| b.iter(|| trace(&fixed, rays)),
            );
            group.bench_with_input(
                BenchmarkId::new(format!("dyn/{kind}"), n),
                rays,
                |b, rays| b.iter(|| trace(&boxed, rays)),
            );
        }
    }
    group.finish();
}

/// A thousand instances of an icosphere of 1,280 faces, each turned and moved at random
/// within a cube 60 wide (they overlap, as instances in a scene do), in a top-level `Bvh`;
/// and the same 1.28 million triangles moved one by one into one `TriangleMesh`. Prints the
/// bytes each holds.
fn instancing(c: &mut Criterion) {
    let mut rng = workloads::SplitMix::new(SEED);
    let (instances, vertices, flat_faces) = workloads::instances(3, 1000, 0.0, 60.0, &mut rng);
    let shared = instances[0].object().clone();
    let instanced = Bvh::new(instances);
    let flat = TriangleMesh::new(&vertices, &flat_faces).unwrap();
    eprintln!(
        "instancing: shared mesh {} bytes, flattened mesh {} bytes",
        shared.heap_bytes(),
        flat.heap_bytes()
    );
    let bounds = (DVec3::splat(-61.0), DVec3::splat(61.0));
    let camera = workloads::camera_rays(bounds, 100);
    let random = workloads::random_rays(bounds, RAYS, SEED + 1);
    let mut group = c.benchmark_group("instancing");
    group.throughput(Throughput::Elements(RAYS as u64));
    for (kind, rays) in [("camera", &camera), ("random", &random)] {
        group.bench_with_input(BenchmarkId::new("instanced", kind), rays, |b, rays| {
            b.iter(|| trace(&instanced, rays))
        });
        group.bench_with_input(BenchmarkId::new("flattened", kind), rays, |b, rays| {
            b.iter(|| trace(&flat, rays))
        });
    }
    group.finish();
}

criterion_group!(benches, build, closest_hit, instancing);
criterion_main!(benches);
