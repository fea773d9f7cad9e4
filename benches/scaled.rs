//! What tracing through a scaled instance costs: one mesh (the icosphere of 81,920 faces)
//! under a scale that is not a power of two, non-uniform (3.1 : 0.7 : 1.3) and turned, as
//! a `Transformed<_, Affine>` of the unit mesh, against the same mesh built at that size
//! (its vertices mapped), and the unit mesh under the rotation alone (a rigid
//! `Transformed`, for scale). Timed in alternation, nine rounds, medians: all rays (from
//! a camera and random ones in the box, most of which miss) and the rays that hit.
//!
//! `cargo bench --bench scaled`

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use hitkit::glam::{DAffine3, DQuat, DVec3};
use hitkit::{Hittable, Interval, Ray, Transformed, TriangleMesh};

use hitkit_render::workloads;

const ROUNDS: usize = 9;

fn trace<H: Hittable + ?Sized>(scene: &H, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|r| black_box(scene.hit(r, Interval::FORWARD)).is_some())
        .count()
}

/// The median time per ray, in nanoseconds, of each scene, timed in turn round by round.
fn alternate(scenes: &[&dyn Hittable], rays: &[Ray]) -> Vec<f64> {
    let mut times = vec![Vec::with_capacity(ROUNDS); scenes.len()];
    for _ in 0..ROUNDS {
        for (scene, times) in scenes.iter().zip(&mut times) {
            let start = Instant::now();
            black_box(trace(*scene, rays));
            times.push(start.elapsed().as_secs_f64());
        }
    }
    times
        .into_iter()
        .map(|mut t| {
            t.sort_by(f64::total_cmp);
            t[ROUNDS / 2] / rays.len() as f64 * 1e9
        })
        .collect()
}

fn main() {
    let (unit, faces) = workloads::icosphere(6);
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.7);
    let map = DAffine3::from_scale_rotation_translation(
        DVec3::new(3.1, 0.7, 1.3),
        turn,
        DVec3::new(10.0, -2.0, 5.0),
    );
    let shared = Arc::new(TriangleMesh::new(&unit, &faces).unwrap());
    let affine = Transformed::affine(shared.clone(), map).unwrap();
    let rigid = Transformed::new(shared, turn, map.translation).unwrap();
    let mapped: Vec<DVec3> = unit.iter().map(|&p| map.transform_point3(p)).collect();
    let built = TriangleMesh::new(&mapped, &faces).unwrap();
    let bbox = built.bounding_box();
    let bounds = (bbox.min() - 1.0, bbox.max() + 1.0);
    let mut rays = workloads::camera_rays(bounds, 300);
    rays.extend(workloads::random_rays(bounds, 90_000, 7));
    assert_eq!(trace(&built, &rays), trace(&affine, &rays));
    let hitting: Vec<Ray> = rays
        .iter()
        .filter(|r| built.hit(r, Interval::FORWARD).is_some())
        .copied()
        .collect();
    println!(
        "{} faces, {} rays, {} of them hit",
        faces.len(),
        rays.len(),
        hitting.len()
    );
    println!("| rays | built at its size (ns/ray) | affine instance | ratio | rigid, unscaled |");
    println!("|---|---:|---:|---:|---:|");
    for (what, rays) in [("all", &rays), ("hitting", &hitting)] {
        let t = alternate(&[&built, &affine, &rigid], rays);
        println!(
            "| {what} | {:.1} | {:.1} | {:.3}x | {:.1} |",
            t[0],
            t[1],
            t[1] / t[0],
            t[2]
        );
    }
}
