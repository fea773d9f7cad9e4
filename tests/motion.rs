//! Motion: a moving object's box covers every time of its motion, and a ray sent at a time
//! hits the object where it is then, not where it was or will be.

mod support;

use std::sync::Arc;

use hitkit::glam::{DQuat, DVec3};
use hitkit::{Hittable, Interval, Moving, Ray, Sphere, Transformed, TriangleMesh};
use support::{SplitMix, icosphere, placements};

const FORWARD: Interval = Interval::FORWARD;

/// Times to look at: both ends of the motion and random ones between.
fn times(rng: &mut SplitMix) -> Vec<f64> {
    let mut t = vec![0.0, 1.0];
    t.extend((0..8).map(|_| rng.next_f64()));
    t
}

#[test]
fn a_moving_spheres_box_covers_its_whole_motion_and_rays_hit_it_where_it_is() {
    let mut rng = SplitMix::new(41);
    let mut checked = 0;
    for (offset, size) in placements() {
        let start = DVec3::new(offset, -0.3 * offset, 0.8 * offset);
        let radius = size;
        // Far enough that the sphere at one end is clear of where it is at the other.
        let displacement = 6.0 * size * (rng.direction() + DVec3::splat(0.01));
        let moving = Moving::new(Sphere::new(start, radius).unwrap(), displacement).unwrap();
        let bbox = moving.bounding_box();
        for tau in times(&mut rng) {
            let centre = start + tau * displacement;
            let still = Sphere::new(centre, radius).unwrap().bounding_box();
            assert!(
                bbox.min().cmple(still.min()).all() && bbox.max().cmpge(still.max()).all(),
                "the box misses the sphere at time {tau}"
            );
            // Aimed at the centre of where it is at tau, from 10 radii away.
            let d = rng.direction();
            let ray = Ray::new(centre - 10.0 * size * d, d).at_time(tau);
            let hit = moving
                .hit(&ray, FORWARD)
                .expect("missed the sphere where it is");
            assert_eq!(hit.time, tau);
            // On the sphere at tau: within its own error bound (and the rounding of the
            // centre, a few ulps of the coordinates).
            let off = ((hit.point - centre).length() - radius).abs();
            let slack = hit.point_error.length()
                + 8.0 * f64::EPSILON * (centre.abs().max_element() + radius);
            assert!(
                off <= slack,
                "{off:e} off the sphere at time {tau} (allowed {slack:e})"
            );
            assert!(bbox.contains(hit.point));
            // The same ray at the other end of the motion finds nothing there.
            let other = if tau < 0.5 { 1.0 } else { 0.0 };
            assert!(moving.hit(&ray.at_time(other), FORWARD).is_none_or(|h| {
                (h.point - (start + other * displacement)).length() <= 1.01 * radius
            }));
            // Spawned rays keep the time.
            assert_eq!(hit.spawn_ray(d).time, tau);
            checked += 1;
        }
    }
    assert!(checked > 100);
}

/// A moving instance of a mesh is hit where the same instance stands, not moving, at the
/// ray's time: the same instance, at the same point to within the hits' error bounds and
/// the roundings of taking the ray into the mesh's space two ways (a few ulps of the
/// coordinates involved, over the cosine of incidence: the rays pass within 0.43 of the
/// unit sphere's centre, so the cosine is at least 0.9).
#[test]
fn a_moving_instance_is_hit_where_it_is_at_the_rays_time() {
    let mut rng = SplitMix::new(42);
    let (unit, faces) = icosphere(2);
    let mesh = Arc::new(TriangleMesh::new(&unit, &faces).unwrap());
    let turn = DQuat::from_axis_angle(rng.direction(), 1.0);
    let at = DVec3::new(5.0, 1.0, -3.0);
    let displacement = DVec3::new(0.0, 4.0, 1.0);
    let moving = Moving::new(
        Transformed::new(mesh.clone(), turn, at)
            .unwrap()
            .with_instance_id(9),
        displacement,
    )
    .unwrap();
    for tau in times(&mut rng) {
        let there = Transformed::new(mesh.clone(), turn, at + tau * displacement)
            .unwrap()
            .with_instance_id(9);
        for _ in 0..50 {
            let origin = at + tau * displacement + 5.0 * rng.direction();
            let aim = at + tau * displacement + 0.5 * (rng.vec3() - 0.5);
            let ray = Ray::new(origin, aim - origin).at_time(tau);
            let (a, b) = (
                moving.hit(&ray, FORWARD).unwrap(),
                there.hit(&ray, FORWARD).unwrap(),
            );
            assert_eq!((a.instance, a.time), (Some(9), tau));
            let apart = (a.point - b.point).length();
            let magnitude = origin.abs().max_element()
                + at.abs().max_element()
                + displacement.abs().max_element();
            let allowed =
                (a.point_error + b.point_error).length() + 8.0 * f64::EPSILON * magnitude / 0.9;
            assert!(apart <= allowed, "{apart:e} apart at time {tau}");
        }
    }
}
