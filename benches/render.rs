//! What unused effects cost: the quads scene rendered small with the effects it calls for
//! (the sky) and with every effect forced on (emission lookups, light sampling machinery,
//! lens sampling), single-threaded. `cargo bench --bench render`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};

use hitkit_render::Effects;
use hitkit_render::render::{Settings, render};
use hitkit_render::scenes::quads_scene;

fn effects(c: &mut Criterion) {
    let scene = quads_scene(64);
    let settings = Settings {
        samples: 8,
        max_depth: 50,
        roulette: true,
        seed: 1,
        threads: 1,
        progress: false,
    };
    let mut group = c.benchmark_group("quads_64x64_8spp");
    group.sample_size(20);
    group.bench_function("scene_effects", |b| {
        b.iter(|| black_box(render(&scene, &settings, scene.effects()).unwrap()))
    });
    group.bench_function("all_effects", |b| {
        b.iter(|| black_box(render(&scene, &settings, Effects::ALL).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, effects);
criterion_main!(benches);
