//! The sphere: accurate roots for small spheres far away, conservative boxes, spawned rays,
//! and a cone-sampling density that integrates to 1 and agrees with its samples.

mod support;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{GeometryError, Hittable, Interval, PdfHittable, Ray, Sphere};
use support::SplitMix;

const FORWARD: Interval = Interval::FORWARD;

/// A sphere of radius 1e-3 seen from 1e6 away (and the same scene shifted by 1e9), rays
/// aimed 0.99 of the radius off centre: the textbook discriminant `b^2 - ac` (half-b form)
/// subtracts two numbers near 1e24 that differ by about 2e4, 20 digits down, more than an
/// f64 holds, so it returns noise and loses such rays; the vector form keeps every one of
/// them, at the right distance.
#[test]
fn a_small_far_sphere_is_hit_near_its_rim_at_the_right_distance() {
    for shift in [0.0, 1e3, 1e9] {
        let center = DVec3::new(shift, shift, shift - 1e6);
        let sphere = Sphere::new(center, 1e-3).unwrap();
        let mut rng = SplitMix::new(1);
        for _ in 0..200 {
            let angle = std::f64::consts::TAU * rng.next_f64();
            let off = DVec3::new(angle.cos(), angle.sin(), 0.0) * 0.99e-3;
            let origin = DVec3::splat(shift);
            let ray = Ray::new(origin, (center + off) - origin);
            let hit = sphere.hit(&ray, FORWARD).expect("aimed inside the rim");
            // The exact near root: 1 - sqrt(r^2 - 0.99^2 r^2) / |d|, to first order.
            let expected = 1.0 - (1e-3f64 * 1e-3 - 0.99e-3 * 0.99e-3).sqrt() / 1e6;
            assert!(
                (hit.t - expected).abs() < 1e-12,
                "t {} vs {expected} at shift {shift}",
                hit.t
            );
            let on_surface = ((hit.point - center).length() - 1e-3).abs();
            assert!(
                on_surface <= 4.0 * hit.point_error.max_element(),
                "{on_surface} off the surface"
            );
        }
    }
}

#[test]
fn rays_from_inside_hit_the_far_side_and_spawned_rays_do_not_rehit() {
    let sphere = Sphere::new(DVec3::new(1e6, -2e6, 3e6), 2.5).unwrap();
    let mut rng = SplitMix::new(2);
    for _ in 0..500 {
        let from_inside = Ray::new(sphere.center() + 0.5 * rng.direction(), rng.direction());
        let hit = sphere
            .hit(&from_inside, FORWARD)
            .expect("every ray from inside leaves");
        assert!(!hit.front_face);
        // Outward from the hit: never the same sphere again.
        let out = hit.spawn_ray(-hit.normal + 0.5 * rng.direction());
        assert!(sphere.hit(&out, FORWARD).is_none() || out.direction.dot(hit.normal) > 0.0);
        // Back in: the far side, a chord away, never the point it left.
        let back = hit.spawn_ray(hit.normal + 0.2 * rng.direction());
        if let Some(again) = sphere.hit(&back, FORWARD) {
            assert!(
                again.t * back.direction.length() > 1e-6,
                "re-hit at t {}",
                again.t
            );
        }
    }
}

#[test]
fn the_box_holds_the_sphere() {
    for (center, radius) in [
        (DVec3::ZERO, 1.0),
        (DVec3::splat(1e12), 1e-3),
        (DVec3::new(-5.0, 3.0, 1e8), 1e4),
    ] {
        let sphere = Sphere::new(center, radius).unwrap();
        let b = sphere.bounding_box();
        let mut rng = SplitMix::new(3);
        for _ in 0..1000 {
            let direction = rng.direction();
            let ray = Ray::new(center + direction * radius * 3.0, -direction);
            let hit = sphere.hit(&ray, FORWARD).unwrap();
            assert!(
                b.hit(&ray, FORWARD) && b.contains(hit.point),
                "{:?} outside {b:?}",
                hit.point
            );
        }
    }
}

/// The density integrates to 1 over the sphere of directions (Monte Carlo over uniform
/// directions: mean of 4 pi pdf, within 5 standard errors from the sample variance), and
/// every sampled direction hits with a positive density; near, far, and from inside.
#[test]
fn the_cone_density_integrates_to_one_and_its_samples_hit() {
    let sphere = Sphere::new(DVec3::new(0.0, 0.0, -3.0), 1.0).unwrap();
    let mut rng = SplitMix::new(4);
    // Integrating by uniform directions needs a wide cone: the far origin only samples.
    let far = DVec3::new(0.0, 0.0, 30.0);
    for origin in [
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, -1.5),
        DVec3::new(0.3, 0.2, -3.1),
        DVec3::new(0.5, 0.0, 1.0),
        far,
    ] {
        let n = if origin == far { 0 } else { 200_000 };
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let x = 4.0 * std::f64::consts::PI * sphere.pdf_value(origin, rng.direction());
            sum += x;
            sum2 += x * x;
        }
        if n > 0 {
            let mean = sum / f64::from(n);
            let se = ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt();
            assert!(
                (mean - 1.0).abs() <= 5.0 * se,
                "from {origin}: {mean} +- {se}"
            );
            assert!(se < 0.05, "too few samples to tell: {se}");
        }
        for _ in 0..500 {
            let d = sphere.sample_direction(origin, DVec2::new(rng.next_f64(), rng.next_f64()));
            let pdf = sphere.pdf_value(origin, d);
            assert!(
                pdf > 0.0 && pdf.is_finite(),
                "from {origin}: sampled {d} has density {pdf}"
            );
            assert!(sphere.hit(&Ray::new(origin, d), FORWARD).is_some());
        }
    }
}

#[test]
fn bad_spheres_are_refused() {
    assert_eq!(
        Sphere::new(DVec3::splat(f64::NAN), 1.0).unwrap_err(),
        GeometryError::NonFinite { what: "center" }
    );
    assert_eq!(
        Sphere::new(DVec3::ZERO, f64::INFINITY).unwrap_err(),
        GeometryError::NonFinite { what: "radius" }
    );
    for r in [0.0, -1.0, 1e-170, 1e170] {
        assert!(
            matches!(
                Sphere::new(DVec3::ZERO, r),
                Err(GeometryError::InvalidParameter { .. })
            ),
            "{r}"
        );
    }
    let s = Sphere::new(DVec3::ZERO, 1.0).unwrap();
    assert!(
        s.hit(&Ray::new(DVec3::splat(f64::NAN), DVec3::X), FORWARD)
            .is_none()
    );
    assert!(
        s.hit(&Ray::new(DVec3::Z * 5.0, DVec3::ZERO), FORWARD)
            .is_none()
    );
    assert_eq!(s.pdf_value(DVec3::Z * 5.0, DVec3::Z), 0.0);
}
