//! Bad input gets a clear `GeometryError`, a bad ray hits nothing, and no `f64` input
//! panics or yields NaN.

use hitkit::glam::{DVec2, DVec3};
use hitkit::{
    Aabb, Disk, GeometryError, Hittable, Interval, Mixture, PdfHittable, Plane, Quad, Ray, Ring,
    Sphere, Triangle,
};
use proptest::prelude::*;

#[test]
fn every_error_variant_is_reached_with_a_message() {
    let cases: [(Result<Plane, GeometryError>, GeometryError, &str); 7] = [
        (
            Plane::new(DVec3::new(0.0, f64::NAN, 0.0), DVec3::X, DVec3::Y),
            GeometryError::NonFinite { what: "q" },
            "q is not finite",
        ),
        (
            Plane::new(DVec3::ZERO, DVec3::new(f64::INFINITY, 0.0, 0.0), DVec3::Y),
            GeometryError::NonFinite { what: "u" },
            "u is not finite",
        ),
        (
            Plane::new(DVec3::ZERO, DVec3::X, DVec3::ZERO),
            GeometryError::ZeroVector { what: "v" },
            "v is the zero vector",
        ),
        (
            Plane::new(DVec3::ZERO, DVec3::X, DVec3::new(-3.0, 0.0, 0.0)),
            GeometryError::ParallelEdges,
            "parallel",
        ),
        // Parallel to within rounding: 1e-17 radians apart.
        (
            Plane::new(DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1e-17, 0.0)),
            GeometryError::ParallelEdges,
            "parallel",
        ),
        (
            Plane::new(DVec3::ZERO, DVec3::X * 1e-160, DVec3::Y * 1e-160),
            GeometryError::OutOfRange,
            "underflows",
        ),
        (
            Plane::new(DVec3::ZERO, DVec3::X * 1e155, DVec3::Y * 1e155),
            GeometryError::OutOfRange,
            "overflows",
        ),
    ];
    for (got, want, message) in cases {
        let err = got.unwrap_err();
        assert_eq!(err, want);
        assert!(err.to_string().contains(message), "{err}");
    }
    let lights = vec![Quad::new(DVec3::Y, DVec3::X, DVec3::Z).unwrap(); 3];
    let mismatch = Mixture::new(lights, &[1.0, 2.0]).unwrap_err();
    assert_eq!(
        mismatch,
        GeometryError::LengthMismatch {
            what: "weights",
            expected: 3,
            found: 2
        }
    );
    assert_eq!(
        mismatch.to_string(),
        "weights has 2 elements where 3 are needed"
    );
    let ring = Ring::new(1.0).unwrap_err();
    assert!(matches!(
        ring,
        GeometryError::InvalidParameter {
            what: "ring inner radius",
            ..
        }
    ));
    assert_eq!(
        ring.to_string(),
        "ring inner radius = 1 lies outside [0, 1)"
    );
    for bad in [-0.1, 1.5, f64::NAN, f64::INFINITY] {
        assert!(Ring::new(bad).is_err(), "{bad}");
    }
    // Errors are std errors, usable with `?` into `Box<dyn Error>`.
    let boxed: Box<dyn core::error::Error> = Box::new(GeometryError::ParallelEdges);
    assert!(!boxed.to_string().is_empty());
}

#[test]
fn the_quad_constructors_report_the_planes_errors() {
    assert_eq!(
        Quad::new(DVec3::ZERO, DVec3::ZERO, DVec3::Y).unwrap_err(),
        GeometryError::ZeroVector { what: "u" }
    );
    assert_eq!(
        Quad::with_interior(DVec3::splat(f64::NAN), DVec3::X, DVec3::Y, Disk).unwrap_err(),
        GeometryError::NonFinite { what: "q" }
    );
}

#[test]
fn skinny_but_valid_frames_are_accepted() {
    // 1e-7 radians apart: far from rounding noise (about 1e-16).
    let quad = Quad::new(DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1e-7, 0.0)).unwrap();
    // Small and large but representable edges.
    assert!(Quad::new(DVec3::ZERO, DVec3::X * 1e-100, DVec3::Y * 1e-100).is_ok());
    assert!(Quad::new(DVec3::ZERO, DVec3::X * 1e100, DVec3::Y * 1e100).is_ok());
    // A ray at (0.5, 0.5e-7) lands inside the sliver.
    let ray = Ray::new(DVec3::new(0.75, 0.5e-7, 1.0), DVec3::NEG_Z);
    assert!(quad.hit(&ray, Interval::UNIVERSE).is_some());
    let beside = Ray::new(DVec3::new(0.25, 0.5e-7, 1.0), DVec3::NEG_Z);
    assert!(quad.hit(&beside, Interval::UNIVERSE).is_none());
}

#[test]
fn invalid_rays_hit_nothing() {
    let quad = Quad::new(DVec3::new(-1.0, -1.0, 0.0), DVec3::X * 2.0, DVec3::Y * 2.0).unwrap();
    let plane = *quad.plane();
    let list: Vec<Box<dyn Hittable>> = vec![Box::new(quad), Box::new(plane)];
    let bad = [
        Ray::new(DVec3::new(f64::NAN, 0.0, 1.0), DVec3::NEG_Z),
        Ray::new(DVec3::new(0.0, 0.0, f64::INFINITY), DVec3::NEG_Z),
        Ray::new(DVec3::Z, DVec3::new(0.0, 0.0, f64::NEG_INFINITY)),
        Ray::new(DVec3::Z, DVec3::new(0.0, f64::NAN, -1.0)),
        Ray::new(DVec3::Z, DVec3::ZERO),
        Ray::new(DVec3::Z, DVec3::new(-0.0, 0.0, -0.0)),
    ];
    for ray in bad {
        assert!(!ray.is_valid());
        assert!(quad.hit(&ray, Interval::UNIVERSE).is_none(), "{ray:?}");
        assert!(
            plane.intersect(&ray, Interval::UNIVERSE).is_none(),
            "{ray:?}"
        );
        assert!(list.hit(&ray, Interval::UNIVERSE).is_none(), "{ray:?}");
        assert!(!list.occluded(&ray, Interval::UNIVERSE), "{ray:?}");
    }
    // A NaN interval contains nothing.
    let good = Ray::new(DVec3::Z, DVec3::NEG_Z);
    assert!(quad.hit(&good, Interval::new(f64::NAN, 2.0)).is_none());
    assert!(quad.hit(&good, Interval::EMPTY).is_none());
}

/// Any f64 at all: NaN, infinities, subnormals, zeros of both signs, huge and tiny.
fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => any::<f64>(),
        2 => -10.0f64..10.0,
        1 => Just(0.0), 1 => Just(-0.0), 1 => Just(f64::NAN), 1 => Just(f64::INFINITY),
        1 => Just(f64::MIN_POSITIVE), 1 => Just(f64::MAX), 1 => Just(5e-324),
    ]
}

fn any_vec3() -> impl Strategy<Value = DVec3> {
    (any_f64(), any_f64(), any_f64()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    #[test]
    fn no_input_panics_and_no_hit_carries_nan(
        q in any_vec3(), u in any_vec3(), v in any_vec3(), o in any_vec3(), d in any_vec3(),
        t0 in any_f64(), t1 in any_f64(), inner in any_f64(),
    ) {
        let ray = Ray::new(o, d);
        let interval = Interval::new(t0, t1);
        let _ = Aabb::new(q, u).hit(&ray, interval);
        let _ = Ring::new(inner);
        if let Ok(plane) = Plane::new(q, u, v) {
            prop_assert!(plane.normal().is_finite());
            let _ = plane.bounding_box();
            if let Some(hit) = plane.intersect(&ray, interval) {
                prop_assert!(hit.t.is_finite() && hit.alpha.is_finite() && hit.beta.is_finite());
                prop_assert!(interval.contains(hit.t));
            }
            for quad in [Quad::new(q, u, v).map(|x| Box::new(x) as Box<dyn Hittable>), Quad::with_interior(q, u, v, Disk).map(|x| Box::new(x) as Box<dyn Hittable>)] {
                let quad = quad.unwrap();
                if let Some(hit) = quad.hit(&ray, interval) {
                    prop_assert!(hit.t.is_finite() && !hit.point.is_nan() && hit.normal.is_finite() && hit.uv.is_finite());
                    prop_assert!(ray.is_valid());
                    let spawned = hit.spawn_ray(DVec3::new(0.0, 1.0, 0.0));
                    prop_assert!(!spawned.origin.is_nan());
                }
            }
        }
        prop_assert!(DVec2::ZERO.is_finite());
    }

    /// Light sampling on any input: densities finite and non-negative, samples of finite
    /// origins finite, for rectangles and triangles (sampled by solid angle near them),
    /// spheres and weighted mixtures of them, from any origin and with any `u`.
    #[test]
    fn no_light_input_panics_and_no_density_is_nan(
        q in any_vec3(), a in any_f64(), b in any_f64(), o in any_vec3(), d in any_vec3(),
        ux in any_f64(), uy in any_f64(), w0 in any_f64(), w1 in any_f64(), radius in any_f64(),
    ) {
        let make = || {
            let mut lights: Vec<Box<dyn PdfHittable>> = Vec::new();
            if let Ok(rectangle) = Quad::new(q, a * DVec3::X, b * DVec3::Y) {
                lights.push(Box::new(rectangle));
            }
            if let Ok(triangle) = Quad::with_interior(q, a * DVec3::X, b * DVec3::Z, Triangle) {
                lights.push(Box::new(triangle));
            }
            if let Ok(sphere) = Sphere::new(q, radius) {
                lights.push(Box::new(sphere));
            }
            lights
        };
        let mut lights = make();
        let n = lights.len();
        // Weights w0, w1, 1, ...: valid or not.
        let weights: Vec<f64> = [w0, w1].into_iter().chain(core::iter::repeat(1.0)).take(n).collect();
        if let Ok(mixture) = Mixture::new(make(), &weights) {
            lights.push(Box::new(mixture));
        }
        for light in &lights {
            let pdf = light.pdf_value(o, d);
            prop_assert!(pdf.is_finite() && pdf >= 0.0, "pdf {}", pdf);
            let sampled = light.sample_direction(o, DVec2::new(ux, uy));
            if o.is_finite() {
                prop_assert!(!sampled.is_nan(), "sample {}", sampled);
            }
            let pdf = light.pdf_value(o, sampled);
            prop_assert!(pdf.is_finite() && pdf >= 0.0, "pdf {} of the sample", pdf);
        }
    }
}
