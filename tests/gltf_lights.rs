//! glTF's `KHR_lights_punctual`: each light where its node puts it (its world transform;
//! glTF's lights shine down their local `-z`, scale ignored), its colour, intensity and
//! range as the file gives them, its material numbered after the scene's; the three kinds
//! in `GltfLights` beside the emitting faces, sampled as delta lights; a light that cannot
//! be placed left out and named. The file is written here.
#![cfg(feature = "gltf")]

use std::path::PathBuf;

use hitkit::glam::{DVec2, DVec3};
use hitkit::load::{LeftOut, load_gltf};
use hitkit::{Light, MaterialId, PdfHittable, ShadingContext};

/// A unit square in the `xz` plane, facing up (+Y), whose material emits; a point light at
/// (1, 2, 3); a spot under a parent moved to x = 10, itself at y = 4, turned to shine down
/// and scaled by 2; a sun turned the same way; a spot whose cone is wider than glTF allows.
const JSON: &str = r#"{
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {"KHR_lights_punctual": {"lights": [
    {"type": "point", "name": "bulb", "color": [1.0, 0.5, 0.25], "intensity": 10.0, "range": 5.0},
    {"type": "spot", "intensity": 80.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
    {"type": "directional", "intensity": 3.0},
    {"type": "spot", "intensity": 1.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 2.0}}
  ]}},
  "buffers": [{"uri": "lights.bin", "byteLength": 60}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 12}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]},
    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}
  ],
  "materials": [{"emissiveFactor": [1.0, 1.0, 1.0]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
  "nodes": [
    {"mesh": 0},
    {"name": "bulb node", "translation": [1, 2, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    {"name": "spot node", "translation": [0, 4, 0], "rotation": [-0.7071067811865476, 0, 0, 0.7071067811865476],
     "scale": [2, 2, 2], "extensions": {"KHR_lights_punctual": {"light": 1}}},
    {"name": "parent", "translation": [10, 0, 0], "children": [2]},
    {"name": "sun node", "rotation": [-0.7071067811865476, 0, 0, 0.7071067811865476],
     "extensions": {"KHR_lights_punctual": {"light": 2}}},
    {"name": "too wide", "extensions": {"KHR_lights_punctual": {"light": 3}}}
  ],
  "scenes": [{"nodes": [0, 1, 3, 4, 5]}]
}"#;

/// The file, written to a folder of `test`'s own (the tests run at once).
fn write(test: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("hitkit-gltf-lights-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut b = Vec::new();
    // Counterclockwise seen from +Y: (0,0,0), (0,0,1), (1,0,1), (1,0,0).
    for x in [0f32, 0., 0., 0., 0., 1., 1., 0., 1., 1., 0., 0.] {
        b.extend(x.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    std::fs::write(dir.join("lights.bin"), b).unwrap();
    let path = dir.join("lights.gltf");
    std::fs::write(&path, JSON).unwrap();
    path
}

#[test]
fn punctual_lights_load_where_their_nodes_put_them() {
    let scene = load_gltf(write("placed")).unwrap();
    let [bulb, spot, sun] = scene.punctual.as_slice() else {
        panic!("{:?}", scene.punctual);
    };
    // Positions and directions (the rotation turns -Z to -Y; the scale changes nothing).
    assert_eq!(bulb.light.position(), Some(DVec3::new(1.0, 2.0, 3.0)));
    assert_eq!(bulb.light.direction(), None);
    let s = spot.light.position().unwrap();
    assert!((s - DVec3::new(10.0, 4.0, 0.0)).length() < 1e-12, "{s}");
    let d = spot.light.direction().unwrap();
    assert!(
        (d - DVec3::NEG_Y).length() < 1e-12 && (d.length() - 1.0).abs() < 1e-15,
        "{d}"
    );
    assert_eq!(sun.light.position(), None);
    assert!((sun.light.direction().unwrap() - DVec3::NEG_Y).length() < 1e-12);
    // What the file says of them; white where it names no colour.
    assert_eq!(
        (bulb.name.as_str(), bulb.node.as_str()),
        ("bulb", "bulb node")
    );
    assert_eq!(
        (bulb.color, bulb.intensity, bulb.range),
        (DVec3::new(1.0, 0.5, 0.25), 10.0, Some(5.0))
    );
    assert_eq!(bulb.emitted(), DVec3::new(10.0, 5.0, 2.5));
    assert_eq!(
        (spot.color, spot.intensity, spot.range),
        (DVec3::ONE, 80.0, None)
    );
    assert_eq!((sun.name.as_str(), sun.intensity), ("light 2", 3.0));
    // The spot's cone: full within 0.2 rad of straight down, none past 0.6.
    let at = |angle: f64| DVec3::new(angle.sin(), -angle.cos(), 0.0);
    assert_eq!(
        (spot.light.falloff(at(0.15)), spot.light.falloff(at(0.65))),
        (1.0, 0.0)
    );
    assert!(spot.light.falloff(at(0.4)) > 0.0 && spot.light.falloff(at(0.4)) < 1.0);
    // Materials numbered after the scene's.
    let first = scene.materials.len() as u32;
    let ids: Vec<MaterialId> = scene.punctual.iter().map(|p| p.light.material()).collect();
    assert_eq!(
        ids,
        [
            MaterialId(first),
            MaterialId(first + 1),
            MaterialId(first + 2)
        ]
    );
    // The light glTF bounds its cone to a right angle is left out, named.
    let wide = scene.left_out.iter().find_map(|l| match l {
        LeftOut::Light { node, .. } => Some(node.as_str()),
        _ => None,
    });
    assert_eq!(wide, Some("too wide"));
    assert!(
        !scene
            .left_out
            .contains(&LeftOut::Extension("KHR_lights_punctual".into()))
    );
}

#[test]
fn the_three_kinds_light_beside_the_emitting_faces() {
    let scene = load_gltf(write("beside")).unwrap();
    let lights = scene.textured_lights().unwrap().unwrap();
    let faces = lights.sources.len();
    assert_eq!(faces, 2);
    let kinds: Vec<bool> = lights
        .tree
        .lights()
        .iter()
        .map(|l| matches!(l, Light::Punctual(_)))
        .collect();
    assert_eq!(kinds, [false, false, true, true, true]);
    // From a floor under the spot, every kind is sampled: the faces by their density,
    // the punctual lights as deltas, named by their place after the faces.
    let floor = ShadingContext::on_surface(DVec3::new(10.0, 0.0, 0.0), DVec3::Y);
    let mut seen = [0usize; 5];
    for k in 0..2000 {
        let u = DVec2::new((f64::from(k) + 0.5) / 2000.0, 0.37);
        let Some(s) = lights.sample_light(&floor, u) else {
            continue;
        };
        seen[s.light] += 1;
        assert_eq!(s.delta, s.light >= faces, "{s:?}");
        if s.delta {
            let p = &scene.punctual[s.light - faces];
            assert_eq!(s.record.material, p.light.material());
            // The tree's probability of the pick times the light's own `d^2 / falloff`.
            let own = p.light.sample_light(&floor, u).unwrap();
            let probability = lights.tree.probability(&floor, s.light);
            assert!((s.pdf - own.pdf * probability).abs() <= 1e-15 * s.pdf);
        } else {
            assert!((lights.light_pdf(&floor, s.direction) - s.pdf).abs() <= 1e-12 * s.pdf);
        }
    }
    // The bulb is far and dim from here, but picked; the spot above most of all.
    assert!(seen[2] > 0 && seen[3] > seen[2] && seen[4] > 0, "{seen:?}");
    // The faces' own tree leaves the punctual lights out.
    assert_eq!(scene.lights().unwrap().unwrap().lights().len(), faces);
}

#[test]
fn a_scene_lit_by_punctual_lights_alone_has_lights() {
    let json = JSON.replace(
        r#""emissiveFactor": [1.0, 1.0, 1.0]"#,
        r#""emissiveFactor": [0.0, 0.0, 0.0]"#,
    );
    let dir = write("alone").parent().unwrap().to_path_buf();
    let path = dir.join("dark.gltf");
    std::fs::write(&path, &json).unwrap();
    let scene = load_gltf(&path).unwrap();
    assert!(scene.lights().unwrap().is_none());
    let lights = scene.textured_lights().unwrap().unwrap();
    assert_eq!((lights.sources.len(), lights.tree.lights().len()), (0, 3));
    let s = lights
        .sample_light(
            &ShadingContext::at(DVec3::new(0.0, -1.0, 0.0)),
            DVec2::new(0.1, 0.5),
        )
        .unwrap();
    assert!(s.delta);
    // Lights of intensity 0 too (valid glTF): nothing lights the scene, and that is no error.
    let unlit = json
        .replace(r#""intensity": 10.0"#, r#""intensity": 0.0"#)
        .replace(r#""intensity": 80.0"#, r#""intensity": 0.0"#)
        .replace(r#""intensity": 3.0"#, r#""intensity": 0.0"#);
    let path = dir.join("unlit.gltf");
    std::fs::write(&path, unlit).unwrap();
    let scene = load_gltf(&path).unwrap();
    assert_eq!(scene.punctual.len(), 3);
    assert!(scene.textured_lights().unwrap().is_none());
}
