//! What a crate depending on hitkit writes, using only the names in DESIGN.md: a quad, a
//! disk and a plane behind `Box<dyn Hittable>`, and every container the traits are
//! implemented for.

use std::sync::Arc;

use hitkit::glam::DVec3;
use hitkit::{Disk, HitRecord, Hittable, Interval, MaterialId, Plane, Quad, Ray};

fn scene() -> Vec<Box<dyn Hittable>> {
    vec![
        Box::new(
            Quad::new(DVec3::new(-1.0, -1.0, -3.0), DVec3::X * 2.0, DVec3::Y * 2.0)
                .unwrap()
                .with_material(MaterialId(1)),
        ),
        Box::new(
            Quad::with_interior(
                DVec3::new(0.0, 0.0, -2.0),
                DVec3::X * 0.5,
                DVec3::Y * 0.5,
                Disk,
            )
            .unwrap()
            .with_material(MaterialId(2)),
        ),
        Box::new(
            Plane::new(DVec3::new(0.0, -1.0, 0.0), DVec3::Z, DVec3::X)
                .unwrap()
                .with_material(MaterialId(3)),
        ),
    ]
}

fn first(objects: &dyn Hittable, ray: &Ray) -> Option<HitRecord> {
    objects.hit(ray, Interval::FORWARD)
}

#[test]
fn a_list_of_boxed_shapes_returns_the_closest_hit() {
    let scene = scene();
    let toward = |p: DVec3| Ray::new(DVec3::ZERO, p);
    assert_eq!(
        first(&scene, &toward(DVec3::new(0.1, 0.1, -1.0)))
            .unwrap()
            .material,
        MaterialId(2)
    );
    assert_eq!(
        first(&scene, &toward(DVec3::new(0.8, 0.8, -3.0)))
            .unwrap()
            .material,
        MaterialId(1)
    );
    assert_eq!(
        first(&scene, &toward(DVec3::new(0.0, -1.0, 0.0)))
            .unwrap()
            .material,
        MaterialId(3)
    );
    assert!(first(&scene, &toward(DVec3::new(0.0, 1.0, 0.0))).is_none());
    // Bounding box: the union, unbounded because of the plane.
    assert!(!scene.bounding_box().is_bounded());
    assert!(scene[..2].bounding_box().is_bounded());
}

#[test]
fn every_container_answers_the_same() {
    let ray = Ray::new(DVec3::new(0.1, 0.1, 0.0), DVec3::NEG_Z);
    let expect = first(&scene(), &ray).unwrap();
    let boxed: Box<dyn Hittable> = Box::new(scene());
    let shared: Arc<dyn Hittable> = Arc::new(scene());
    let slice: &[Box<dyn Hittable>] = &scene();
    let owned = scene();
    let by_ref: &dyn Hittable = &owned;
    let arcs: Vec<Arc<dyn Hittable>> = scene().into_iter().map(Arc::from).collect();
    for h in [&boxed as &dyn Hittable, &shared, &slice, &by_ref, &arcs] {
        assert_eq!(first(h, &ray), Some(expect));
        assert!(h.occluded(&ray, Interval::new(0.0, 2.5)));
        assert!(!h.occluded(&ray, Interval::new(0.0, 1.5)));
    }
    // The empty list hits nothing and has an empty box.
    let none: Vec<Box<dyn Hittable>> = Vec::new();
    assert!(first(&none, &ray).is_none());
    assert!(none.bounding_box().is_empty());
}

#[test]
fn the_normal_faces_against_the_ray_from_either_side() {
    let quad = Quad::new(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap(); // u x v = +z
    let from_front = first(&quad, &Ray::new(DVec3::new(0.5, 0.5, 1.0), DVec3::NEG_Z)).unwrap();
    let from_back = first(&quad, &Ray::new(DVec3::new(0.5, 0.5, -1.0), DVec3::Z)).unwrap();
    assert!(from_front.front_face && !from_back.front_face);
    assert_eq!(
        (from_front.normal, from_back.normal),
        (DVec3::Z, DVec3::NEG_Z)
    );
    assert_eq!(from_front.uv, hitkit::glam::DVec2::new(0.5, 0.5));
}
