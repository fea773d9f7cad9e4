//! Next-event estimation without epsilons: a shadow ray from a hit to a point sampled on a
//! light (`HitRecord::spawn_ray_to` of `PdfHittable::sample_light`'s record) finds neither
//! the surface it leaves nor the light's own surface at the far end, and finds what lies
//! between; for lights of every kind, placed as users place them (turned, from 1e-3 to 1e3
//! across, up to 1e9 from the origin), seen from points anywhere on a turned floor.

mod support;

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::{
    Disk, Emission, Hittable, Interval, LightTree, Mixture, PdfHittable, Quad, Ray, ShadingContext,
    Sphere, Transformed, Triangle, TriangleMesh,
};
use proptest::prelude::*;
use support::icosphere;

/// A light of kind `kind`, `size` across, centred at `centre`, turned by `turn`.
fn light(kind: u8, centre: DVec3, size: f64, turn: DQuat) -> Box<dyn PdfHittable> {
    let (u, v) = (turn * DVec3::X * size, turn * DVec3::Z * size);
    let corner = centre - 0.5 * (u + v);
    let panel = || Quad::new(corner, u, v).unwrap();
    let ball = || Sphere::new(centre, 0.5 * size).unwrap();
    match kind % 8 {
        0 => Box::new(panel()),
        1 => Box::new(Quad::with_interior(corner, u, v, Triangle).unwrap()),
        2 => Box::new(Quad::with_interior(centre, 0.5 * u, 0.5 * v, Disk).unwrap()),
        3 => Box::new(ball()),
        4 => {
            let (points, faces) = icosphere(1);
            let points: Vec<DVec3> = points
                .iter()
                .map(|&p| centre + turn * p * 0.5 * size)
                .collect();
            Box::new(TriangleMesh::new(&points, &faces).unwrap())
        }
        5 => Box::new(
            Transformed::new(Quad::new(-0.5 * (u + v), u, v).unwrap(), turn, centre).unwrap(),
        ),
        6 => {
            let lights: Vec<Box<dyn PdfHittable>> = vec![Box::new(panel()), Box::new(ball())];
            let emission = [Emission::BothSides(u.cross(v)), Emission::Everywhere];
            Box::new(LightTree::new(lights, &[1.0, 2.0], &emission).unwrap())
        }
        _ => Box::new(Mixture::uniform(vec![
            panel(),
            Quad::new(corner + u, v, u).unwrap(),
        ])),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn shadow_rays_find_neither_end_and_what_lies_between(
        kind in 0u8..8,
        offset in (0i32..=9, prop::array::uniform3(-1.0f64..1.0)),
        size_exp in -3i32..=3,
        axis in prop::array::uniform3(-1.0f64..1.0),
        angle in 0.0f64..6.3,
        light_turn in 0.0f64..6.3,
        place in prop::array::uniform3(-1.0f64..1.0),
        spot in prop::array::uniform2(-1.5f64..1.5),
        from in prop::array::uniform3(-1.0f64..1.0),
        u in prop::array::uniform2(0.0f64..1.0),
    ) {
        let size = 10f64.powi(size_exp);
        // Up to 1e9 from the origin, but no further than 1e9 sizes: a shape smaller than
        // 2^20 ulps of its offset is not one a user places (`support::meaningful`).
        let centre = DVec3::from(offset.1) * 10f64.powi(offset.0.min(size_exp + 9));
        prop_assert!(support::meaningful(centre.abs().max_element(), size));
        let turn = DQuat::from_axis_angle(DVec3::from(axis).normalize_or(DVec3::Y), angle);
        // A floor four sizes across, and a light above it, tilted.
        let floor = Quad::new(
            centre - turn * DVec3::new(2.0, 0.0, 2.0) * size,
            turn * DVec3::X * 4.0 * size,
            turn * DVec3::Z * 4.0 * size,
        ).unwrap();
        let place = DVec3::from(place);
        let lamp_at = centre + turn * DVec3::new(place.x, 1.5 + place.y, place.z) * size;
        let tilt = turn * DQuat::from_rotation_x(0.5 * light_turn.sin());
        let lamp = light(kind, lamp_at, 0.5 * size, tilt);
        // A ray down onto the floor, as a camera or a bounce sends one.
        let target = centre + turn * DVec3::new(spot[0], 0.0, spot[1]) * size;
        let from = DVec3::from(from);
        let start = target + (turn * DVec3::new(from.x, 0.2 + from.y.abs(), from.z)) * size;
        let Some(hit) = floor.hit(&Ray::new(start, target - start), Interval::FORWARD) else {
            return Err(TestCaseError::fail("the ray aimed at the floor misses it"));
        };
        let at = ShadingContext::from(&hit);
        // Every light gives a sample from the floor, the tree too: its normal is a line, and
        // a light below the horizon is picked as one above it would be.
        let Some(sample) = lamp.sample_light(&at, DVec2::from(u)) else {
            return Err(TestCaseError::fail(format!("light {} gave no sample", kind % 8)));
        };
        prop_assert!((sample.direction.length() - 1.0).abs() <= 4.0 * f64::EPSILON);
        prop_assert_eq!(sample.pdf, lamp.light_pdf(&at, sample.direction));
        // The distance is that to the record's point, to within the point's own rounding.
        let between = (sample.record.point - hit.point).length();
        prop_assert!((sample.distance - between).abs() <= 1e-12 * (between + centre.abs().max_element()));

        let (shadow, range) = hit.spawn_ray_to(&sample.record);
        prop_assert!(!floor.occluded(&shadow, range), "the floor occludes its own shadow ray");
        prop_assert!(floor.hit(&shadow, range).is_none());
        prop_assert!(!lamp.occluded(&shadow, range), "the light occludes itself");
        prop_assert!(lamp.hit(&shadow, range).is_none());
        // A card across the middle of the segment, a tenth of it wide, is found.
        let across = shadow.direction.normalize().any_orthonormal_pair();
        let width = 0.1 * sample.distance;
        let (a, b) = (across.0 * width, across.1 * width);
        let card = Quad::new(shadow.at(0.5) - 0.5 * (a + b), a, b).unwrap();
        prop_assert!(card.occluded(&shadow, range), "the card between is not found");
    }
}

/// The case: a lamp in a closed room, sampled from points on the floor. With
/// `spawn_ray(d)` and `0..1`, every shadow ray found the lamp itself; with
/// `spawn_ray_to`, none is occluded.
#[test]
fn a_lamp_in_an_empty_room_lights_every_point_of_its_floor() {
    let side = 555.0;
    let (x, y, z) = (DVec3::X * side, DVec3::Y * side, DVec3::Z * side);
    let lamp = Quad::new(
        DVec3::new(213.0, 554.0, 227.0),
        DVec3::X * 130.0,
        DVec3::Z * 105.0,
    )
    .unwrap();
    let room = vec![
        Quad::new(DVec3::ZERO, x, z).unwrap(),
        Quad::new(y, x, z).unwrap(),
        Quad::new(DVec3::ZERO, y, z).unwrap(),
        Quad::new(x, y, z).unwrap(),
        Quad::new(z, x, y).unwrap(),
        lamp,
    ];
    let mut rng = support::SplitMix::new(3);
    let mut occluded = 0;
    for _ in 0..10_000 {
        let spot = DVec3::new(rng.next_f64() * side, 300.0, rng.next_f64() * side);
        let hit = room
            .hit(&Ray::new(spot, DVec3::NEG_Y), Interval::FORWARD)
            .unwrap();
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        let sample = lamp.sample_light(&ShadingContext::from(&hit), u).unwrap();
        let (shadow, range) = hit.spawn_ray_to(&sample.record);
        occluded += usize::from(room.occluded(&shadow, range));
    }
    assert_eq!(occluded, 0, "of 10,000 samples");
}
