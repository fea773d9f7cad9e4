//! Whatever a shape's own test accepts, its bounding box's test accepts too: the property a
//! BVH needs so that culling by boxes never loses a hit.

use hitkit::glam::DVec3;
use hitkit::{Disk, Hittable, Interior, Interval, Quad, Ray, Ring, Triangle};
use proptest::prelude::*;

fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

prop_compose! {
    /// A shape frame (q, u, v) at a random scale and offset, and a ray from near or far,
    /// aimed at a random point of the frame's parallelogram, some of them grazing.
    fn frame_and_ray()(
        log_scale in -6.0f64..6.0, log_offset in -6.0f64..12.0,
        q in vec3(1.0), u in vec3(1.0), v in vec3(1.0), o in vec3(1.0),
        a in -0.2f64..1.2, b in -0.2f64..1.2, lift in prop_oneof![Just(0.0), -1.0f64..1.0, -1e-9f64..1e-9],
        log_dist in -2.0f64..3.0,
    ) -> (DVec3, DVec3, DVec3, Ray) {
        let scale = 10f64.powf(log_scale);
        let offset = 10f64.powf(log_offset);
        let (q, u, v) = (q * offset + q.signum() * offset, u * scale, v * scale);
        let n = u.cross(v).normalize_or_zero();
        let target = q + (a * u + b * v);
        // The origin: a random direction, pulled toward the plane by `lift` (0 = in it).
        let away = (o.normalize_or(DVec3::X) + n * lift).normalize_or(DVec3::X);
        let origin = target + away * scale * 10f64.powf(log_dist);
        (q, u, v, Ray::new(origin, target - origin))
    }
}

fn check<S: Interior>(
    q: DVec3,
    u: DVec3,
    v: DVec3,
    ray: &Ray,
    shape: S,
) -> Result<(), TestCaseError> {
    let Ok(quad) = Quad::with_interior(q, u, v, shape) else {
        return Ok(()); // degenerate random frames are refused; nothing to check
    };
    let bbox = quad.bounding_box();
    for interval in [Interval::FORWARD, Interval::UNIVERSE] {
        if let Some(hit) = quad.hit(ray, interval) {
            prop_assert!(
                bbox.hit(ray, interval),
                "box misses hit at t {} ({:?})",
                hit.t,
                bbox
            );
            // As a BVH narrows the interval to the closest hit so far.
            prop_assert!(
                bbox.hit(ray, Interval::new(interval.min, hit.t)),
                "box misses hit at end of interval t {}",
                hit.t
            );
            prop_assert!(
                bbox.hit(ray, Interval::new(hit.t, hit.t)),
                "box misses degenerate interval at t {}",
                hit.t
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    #[test]
    fn every_shape_hit_is_inside_its_bounding_box_hit((q, u, v, ray) in frame_and_ray()) {
        check(q, u, v, &ray, hitkit::Parallelogram)?;
        check(q, u, v, &ray, Triangle)?;
        check(q, u, v, &ray, Disk)?;
        check(q, u, v, &ray, Ring::new(0.3).unwrap())?;
    }
}
