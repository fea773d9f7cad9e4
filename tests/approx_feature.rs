//! The `approx` feature: the value types compare with tolerances.
#![cfg(feature = "approx")]

use approx::{assert_abs_diff_eq, assert_relative_eq, assert_relative_ne, assert_ulps_eq};
use hitkit::glam::DVec3;
use hitkit::{Aabb, Interval, Plane, Ray};

#[test]
fn value_types_compare_approximately() {
    let ray = Ray::new(DVec3::ZERO, DVec3::X);
    let nudged = Ray::new(
        DVec3::splat(1e-17),
        DVec3::new(1.0 + f64::EPSILON, 0.0, 0.0),
    );
    assert_abs_diff_eq!(ray, nudged, epsilon = 1e-15);
    assert_ulps_eq!(
        Interval::new(0.0, 1.0),
        Interval::new(0.0, 1.0 + f64::EPSILON)
    );
    let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
    assert_relative_eq!(
        b,
        b.union(&Aabb::new(DVec3::ONE, DVec3::ONE * (1.0 + 1e-15))),
        max_relative = 1e-12
    );
    assert_relative_ne!(b, Aabb::new(DVec3::ZERO, DVec3::splat(2.0)));

    let plane = Plane::new(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let hit = |x: f64| {
        plane
            .intersect(
                &Ray::new(DVec3::new(x, 0.5, 1.0), DVec3::NEG_Z),
                Interval::UNIVERSE,
            )
            .unwrap()
    };
    assert_relative_eq!(hit(0.3), hit(0.3 + 1e-16), max_relative = 1e-15);
    assert_relative_ne!(hit(0.3), hit(0.4));
}
