//! The mesh example's scene: instances of one shared mesh take their colours from the ids
//! their hits carry, a missing OBJ file is an error naming it, and motion blur renders
//! without NaN.

use std::path::Path;

use hitkit::glam::DVec3;
use hitkit::{Hittable, Interval, Ray};
use hitkit_render::Material;
use hitkit_render::render::{Settings, render};
use hitkit_render::scenes::{load_obj, mesh_scene};

/// Rays down onto the instances' centres' row find instances, each hit coloured by the
/// palette entry its instance id picks (the `ByInstance` wrapper), and different
/// instances show different colours.
#[test]
fn instances_are_coloured_by_their_ids() {
    let scene = mesh_scene(64, None);
    let mut seen = std::collections::BTreeSet::new();
    for x in -8..=8 {
        let ray = Ray::new(DVec3::new(1.5 * f64::from(x), 10.0, -0.1), DVec3::NEG_Y);
        let Some(hit) = scene.world.hit(&ray, Interval::FORWARD) else {
            continue;
        };
        if let Some(id) = hit.instance {
            let first = scene.materials.len() as u32 - 6;
            assert_eq!(hit.material.0, first + id % 6);
            assert!(matches!(
                scene.materials[hit.material.0 as usize],
                Material::Lambertian(_)
            ));
            seen.insert(hit.material.0);
        }
    }
    assert!(seen.len() >= 3, "{seen:?}");
}

#[test]
fn a_missing_obj_file_is_an_error_naming_it() {
    let error = load_obj(Path::new("/nonexistent/bunny.obj")).unwrap_err();
    assert!(error.contains("/nonexistent/bunny.obj"), "{error}");
}

/// With the shutter open, every camera ray has its own time: the image renders, finite.
#[test]
fn motion_blur_renders_finite_pixels() {
    let scene = mesh_scene(32, None);
    assert!(scene.camera.shutter);
    let settings = Settings {
        samples: 2,
        max_depth: 8,
        roulette: true,
        seed: 3,
        threads: 1,
        progress: false,
    };
    let image = render(&scene, &settings, scene.effects()).unwrap();
    assert_eq!((image.width, image.height), (32, 18));
    assert!(image.pixels.iter().all(|p| p.is_finite()));
}
