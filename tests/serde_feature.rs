//! The `serde` feature: values round-trip exactly, and shapes deserialize through their
//! constructors, so input a constructor refuses is an error, never a shape that yields NaN.
#![cfg(feature = "serde")]

use hitkit::glam::{DVec2, DVec3};
use hitkit::{
    Aabb, Disk, Exact, HitRecord, Hittable, Interval, MaterialId, Plane, Quad, Ray, Ring, Sampling,
    Sphere, Triangle,
};
use serde::Serialize;
use serde::de::DeserializeOwned;

fn round_trip<T: Serialize + DeserializeOwned>(value: &T) -> T {
    let text = serde_json::to_string(value).expect("serializes");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

#[test]
fn values_round_trip_bit_for_bit() {
    // Numbers that a decimal round trip would lose if it were not exact.
    let ray = Ray::new(
        DVec3::new(0.1, -1e-300, 1e12 + 0.3),
        DVec3::new(1.0 / 3.0, 0.0, -2.0),
    );
    assert_eq!(round_trip(&ray), ray);
    let interval = Interval::new(1e-9, 0.7);
    assert_eq!(round_trip(&interval), interval);
    let bbox = Aabb::new(DVec3::new(0.1, 0.2, 0.3), DVec3::new(-5.0, 7.0, 1e9));
    assert_eq!(round_trip(&bbox), bbox);
    assert_eq!(round_trip(&MaterialId(7)), MaterialId(7));
    assert_eq!(serde_json::to_string(&MaterialId(7)).unwrap(), "7");
    let hit = HitRecord::new(&ray, 0.25, DVec3::new(1.0, 2.0, 3.0), DVec3::Z)
        .with_point_error(DVec3::splat(1e-16))
        .with_uv(DVec2::new(0.5, 0.125))
        .with_material(MaterialId(2));
    assert_eq!(round_trip(&hit), hit);
    assert_eq!(round_trip(&Sampling::Area), Sampling::Area);
}

#[test]
fn shapes_round_trip_and_hit_the_same() {
    let q = DVec3::new(1e6 + 0.1, -2.0, 0.3);
    let (u, v) = (DVec3::new(0.7, 0.1, -0.2), DVec3::new(-0.1, 0.9, 0.4));
    let ray = Ray::new(
        q + 0.3 * u + 0.4 * v + DVec3::new(0.5, 0.2, 3.0),
        DVec3::new(-0.5, -0.2, -3.0),
    );
    let quad = Quad::new(q, u, v)
        .unwrap()
        .with_material(MaterialId(3))
        .with_sampling(Sampling::Area);
    let back: Quad = round_trip(&quad);
    assert_eq!(back, quad);
    assert_eq!(
        back.hit(&ray, Interval::FORWARD),
        quad.hit(&ray, Interval::FORWARD)
    );
    assert!(back.hit(&ray, Interval::FORWARD).is_some());

    let ring = Quad::with_interior(q, u, v, Ring::new(0.25).unwrap()).unwrap();
    assert_eq!(round_trip(&ring), ring);
    let tri = Quad::with_interior(q, u, v, Exact(Triangle)).unwrap();
    assert_eq!(round_trip(&tri), tri);
    let disk = Quad::with_interior(q, u, v, Disk).unwrap();
    assert_eq!(round_trip(&disk), disk);
    let plane = Plane::new(q, u, v).unwrap().with_material(MaterialId(1));
    assert_eq!(round_trip(&plane), plane);
    let sphere = Sphere::new(q, 0.5).unwrap().with_material(MaterialId(4));
    assert_eq!(round_trip(&sphere), sphere);
}

#[test]
fn scene_files_with_defaults_read() {
    let quad: Quad =
        serde_json::from_str(r#"{"q": [0, 0, -1], "u": [1, 0, 0], "v": [0, 1, 0], "shape": null}"#)
            .unwrap();
    assert_eq!(quad, Quad::new(-DVec3::Z, DVec3::X, DVec3::Y).unwrap());
}

#[test]
fn bad_shapes_are_errors_naming_the_fault() {
    let error = |text: &str, parse: fn(&str) -> Result<(), serde_json::Error>| {
        parse(text).expect_err(text).to_string()
    };
    let quad = |t: &str| serde_json::from_str::<Quad>(t).map(drop);
    let ring = |t: &str| serde_json::from_str::<Ring>(t).map(drop);
    let sphere = |t: &str| serde_json::from_str::<Sphere>(t).map(drop);
    let aabb = |t: &str| serde_json::from_str::<Aabb>(t).map(drop);
    let parallel = error(
        r#"{"q": [0, 0, 0], "u": [1, 0, 0], "v": [2, 0, 0], "shape": null}"#,
        quad,
    );
    assert!(parallel.contains("parallel"), "{parallel}");
    let zero = error(
        r#"{"q": [0, 0, 0], "u": [0, 0, 0], "v": [0, 1, 0], "shape": null}"#,
        quad,
    );
    assert!(zero.contains("zero vector"), "{zero}");
    let hole = error(r#"{"inner": 1.5}"#, ring);
    assert!(hole.contains("ring inner radius"), "{hole}");
    let radius = error(r#"{"center": [0, 0, 0], "radius": -1}"#, sphere);
    assert!(radius.contains("radius"), "{radius}");
    // JSON has no NaN; a null corner is a type error, not a NaN box.
    assert!(aabb(r#"{"min": [null, 0, 0], "max": [1, 1, 1]}"#).is_err());
    // min above max on an axis: an empty box, as `Aabb::is_empty` says.
    let inverted: Aabb = serde_json::from_str(r#"{"min": [0, 0, 0], "max": [1, -1, 1]}"#).unwrap();
    assert!(inverted.is_empty());
}
