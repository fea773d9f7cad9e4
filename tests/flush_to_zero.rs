//! With the CPU's flush-to-zero and denormals-are-zero modes on (x86-64's MXCSR bits 15
//! and 6, as Embree and many renderers set them), every answer is the one given with them
//! off: on the rays a path tracer traces (from a camera, a bounce from each hit, a shadow
//! ray toward a lamp) in rooms whose walls lie on the coordinate planes, where a ray
//! spawned from a wall at zero once started a subnormal number away from it (read as zero
//! with the modes on: back on the wall, which it then found) and every box test of a
//! ray from inside a box computed with a subnormal number.

#![cfg(target_arch = "x86_64")]

mod support;

use hitkit::glam::DVec3;
use hitkit::{Bvh, Cuboid, Hittable, Interval, Quad, Ray, Sphere, TriangleMesh};
use support::{SplitMix, cube_corner, cube_faces};

/// Turns both modes on or off on this thread, returning the register's previous value.
fn flush_to_zero(on: bool) -> u32 {
    let mut old = 0u32;
    // SAFETY: reads and writes the SSE control register of this thread only; every bit
    // but the two modes is kept.
    unsafe {
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut old, options(nostack));
        let new = if on { old | 0x8040 } else { old & !0x8040 };
        core::arch::asm!("ldmxcsr [{}]", in(reg) &new, options(nostack));
    }
    old
}

/// A room `[0, s]^3` of two triangles a wall with a box on its floor, and the same walls
/// and box as quads with two spheres in a tree: what the rays are traced against.
fn scenes(s: f64) -> (TriangleMesh, Bvh<Box<dyn Hittable>>) {
    // The room's corners, then a box's standing on its floor.
    let block =
        |i: u32| (DVec3::new(0.5, 0.0, 0.1) + cube_corner(i) * DVec3::new(0.3, 0.6, 0.3)) * s;
    let vertices: Vec<DVec3> = (0..8)
        .map(|i| cube_corner(i) * s)
        .chain((0..8).map(block))
        .collect();
    let walls = cube_faces();
    let faces: Vec<[u32; 3]> = walls
        .iter()
        .copied()
        .chain(walls.iter().map(|f| f.map(|i| i + 8)))
        .collect();
    let mesh = TriangleMesh::new(&vertices, &faces).unwrap();
    // The walls again as quads: the triangles `[a, b, c]`, `[a, c, d]` of a wall are the
    // parallelogram on `a`, `b` and `d`.
    let mut objects: Vec<Box<dyn Hittable>> = walls
        .chunks_exact(2)
        .map(|pair| {
            let [q, b, d] = [pair[0][0], pair[0][1], pair[1][2]].map(|i| vertices[i as usize]);
            Box::new(Quad::new(q, b - q, d - q).unwrap()) as Box<dyn Hittable>
        })
        .collect();
    objects.push(Box::new(
        Sphere::new(DVec3::splat(0.3 * s), 0.1 * s).unwrap(),
    ));
    objects.push(Box::new(
        Sphere::new(DVec3::new(0.7, 0.2, 0.6) * s, 0.2 * s).unwrap(),
    ));
    objects.push(Box::new(
        Cuboid::new(DVec3::new(0.5, 0.0, 0.1) * s, DVec3::new(0.8, 0.6, 0.4) * s).unwrap(),
    ));
    (mesh, Bvh::new(objects))
}

/// A hit as bits: `t`, the point and the face.
type Bits = [u64; 5];

/// A camera ray's hit, its bounce's hit, and whether its shadow ray is blocked.
type Answer = (Option<Bits>, Option<Bits>, bool);

/// For each camera ray: its hit (`t`, point and face, bit for bit), its bounce's, and
/// whether its shadow ray toward a point of the lamp is blocked.
fn trace(scene: &dyn Hittable, s: f64, seed: u64) -> Vec<Answer> {
    let key = |h: &hitkit::HitRecord| {
        [
            h.t.to_bits(),
            h.point.x.to_bits(),
            h.point.y.to_bits(),
            h.point.z.to_bits(),
            u64::from(h.primitive.unwrap_or(u32::MAX)),
        ]
    };
    let mut rng = SplitMix::new(seed);
    let eye = DVec3::new(0.5, 0.5, 0.9) * s;
    (0..3000)
        .map(|_| {
            let ray = Ray::new(eye, rng.direction());
            let Some(hit) = scene.hit(&ray, Interval::FORWARD) else {
                return (None, None, false);
            };
            let into = if hit.normal.dot(ray.direction) < 0.0 {
                hit.normal
            } else {
                -hit.normal
            };
            let bounce = scene.hit(&hit.spawn_ray(into + rng.direction()), Interval::FORWARD);
            let lamp = DVec3::new(0.3 + 0.4 * rng.next_f64(), 0.99, 0.3 + 0.4 * rng.next_f64()) * s;
            let shadow = scene.occluded(&hit.spawn_ray(lamp - hit.point), Interval::new(0.0, 1.0));
            (Some(key(&hit)), bounce.as_ref().map(key), shadow)
        })
        .collect()
}

#[test]
fn answers_do_not_change_with_flush_to_zero() {
    for s in [1e-3, 1.0, 555.0, 1e6] {
        let (mesh, tree) = scenes(s);
        for (name, scene) in [("mesh", &mesh as &dyn Hittable), ("tree", &tree)] {
            let plain = trace(scene, s, 7);
            let old = flush_to_zero(true);
            let flushed = trace(scene, s, 7);
            flush_to_zero(old & 0x8040 != 0);
            let differ = plain.iter().zip(&flushed).filter(|(a, b)| a != b).count();
            assert_eq!(
                differ,
                0,
                "{name} at size {s}: {differ} of {} rays differ",
                plain.len()
            );
            // And the rays did what the scene asks of them.
            assert!(
                plain.iter().all(|p| p.0.is_some()),
                "{name}: a camera ray escaped"
            );
            assert!(plain.iter().filter(|p| p.2).count() > 0);
            assert!(plain.iter().filter(|p| !p.2).count() > 0);
        }
    }
}
