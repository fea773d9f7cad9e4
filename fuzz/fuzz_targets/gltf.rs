//! A glTF file of arbitrary bytes (JSON or GLB, its buffers and images inline) loads or is
//! a `LoadError`, never a panic; a scene that loads gives its instances as `Transformed`
//! and as `objects` (the loader left out every node that places nothing), every face by
//! its number, its lights (the faces' and the punctual ones), and the surface at a hit
//! and at a light's sample (with a texture lookup there), without a panic.

#![no_main]

use hitkit::glam::{DVec2, DVec3};
use hitkit::load::load_gltf_slice;
use hitkit::{Bvh, Hittable, Interval, PdfHittable, Ray, ShadingContext};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(scene) = load_gltf_slice(data) else {
        return;
    };
    let placed = scene
        .transformed()
        .expect("every instance the loader keeps can be placed");
    assert_eq!(placed.len(), scene.instances.len());
    let objects = scene.objects().expect("as the instances can be placed");
    for mesh in &scene.meshes {
        assert!(mesh.material < scene.materials.len());
        for n in 0..mesh.mesh.face_count() as u32 {
            if let Some(face) = mesh.face(n) {
                assert_eq!(face.index(), n);
            }
        }
    }
    // The surface at a hit through each instance's box, and its textures there.
    let world = Bvh::new(objects);
    for object in &placed {
        let (lo, hi) = (object.bounding_box().min(), object.bounding_box().max());
        let centre = 0.5 * lo + 0.5 * hi;
        let ray = Ray::new(
            centre + DVec3::new(0.1, 0.2, 1.0),
            DVec3::new(-0.1, -0.2, -1.0),
        );
        if let Some(hit) = world.hit(&ray, Interval::FORWARD) {
            let at = scene
                .surface(&hit)
                .expect("a hit names its instance and face");
            for texture in [at.material.base_color_texture, at.material.emissive_texture]
                .into_iter()
                .flatten()
            {
                assert!(!scene.texture_at(&texture, &at).is_nan());
            }
        }
    }
    if let Ok(Some(lights)) = scene.textured_lights() {
        let at = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
        for u in [DVec2::new(0.3, 0.6), DVec2::new(0.9, 0.1)] {
            let Some(sample) = lights.sample_light(&at, u) else {
                continue;
            };
            if sample.delta {
                // A punctual light's, named by its place after the faces.
                let k = sample.light - lights.sources.len();
                assert_eq!(sample.record.material, scene.punctual[k].light.material());
            } else {
                assert!(scene.surface(&sample.record).is_some());
            }
        }
    }
});
