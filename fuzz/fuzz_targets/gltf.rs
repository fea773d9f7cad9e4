//! A glTF file of arbitrary bytes (JSON or GLB, its buffers inline) loads or is a
//! `LoadError`, never a panic; a scene that loads gives its instances as `Transformed`
//! (the loader left out every node that places nothing) and its lights without a panic.

#![no_main]

use hitkit::load::load_gltf_slice;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(scene) = load_gltf_slice(data) {
        let placed = scene
            .transformed()
            .expect("every instance the loader keeps can be placed");
        assert_eq!(placed.len(), scene.instances.len());
        let _ = scene.lights();
    }
});
