//! A scene from a glTF file, traced as the file says: a grove of one tree model at many
//! sizes and stretches (scaled instances of one shared mesh), leaves that are cards with a
//! leaf-shaped cut-out (a `Filtered` mesh: the alpha test inside the search), and a lamp
//! the camera does not see (a `Masked` object) that lights the grove by next-event
//! estimation: it hangs in view above the trees, and the image shows its light, not it.
//!
//! `cargo run --release --example scene_file --features gltf` writes the grove's glTF file
//! (and its buffer) to a temporary directory, loads it as any glTF file is loaded, and
//! renders `scene_file.png`; `-- --scene PATH` renders another glTF file's meshes with the
//! same camera and lamp handling; `-- --help` lists the rest.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::load::{Alpha, GltfScene, load_gltf};
use hitkit::{Bvh, Candidate, Filtered, Hittable, Masked, PdfHittable, Transformed};
use hitkit_render::cli::{Options, run_with};
use hitkit_render::{Background, CameraSettings, Color, Material, Scene};

/// The camera's rays carry this bit alone; everything but a lamp has it.
const CAMERA: u32 = 1;

const EXTRA: &str = "\n  \
--scene PATH  a glTF file to render instead of the grove written to a temporary directory";

fn main() -> ExitCode {
    let defaults = Options {
        width: 480,
        samples: 64,
        depth: 8,
        roulette: true,
        seed: 0,
        output: "scene_file.png".into(),
        threads: 0,
    };
    let (mut path, mut rest, mut args) = (None, Vec::new(), std::env::args().skip(1));
    while let Some(arg) = args.next() {
        if arg == "--scene" {
            path = args.next().map(PathBuf::from);
            if path.is_none() {
                eprintln!("error: --scene needs a path");
                return ExitCode::from(2);
            }
        } else {
            rest.push(arg);
        }
    }
    run_with("scene_file", defaults, rest, EXTRA, |o| {
        let grove = path.is_none();
        let path = match path {
            Some(path) => path,
            None => write_grove().map_err(|e| format!("cannot write the grove's file: {e}"))?,
        };
        let file = load_gltf(&path).map_err(|e| e.to_string())?;
        let mut scene = scene(&file, o.width).map_err(|e| format!("{}: {e}", path.display()))?;
        if grove {
            // Among the trees rather than over the whole ground, with the lamp in view
            // above them (where the camera sees nothing).
            scene.camera.lookfrom = DVec3::new(0.5, 2.2, 7.5);
            scene.camera.lookat = DVec3::new(0.0, 3.0, -2.0);
            scene.camera.vfov = 55.0;
            scene.camera.focus_dist = 9.5;
        }
        Ok(scene)
    })
}

/// The leaves' texture: opaque inside a leaf's outline (a pointed oval along the card's
/// `v`, with a notch cut at its stem), nothing outside. A renderer would read this from
/// the material's image; the grove's file has none.
fn leaf_alpha(uv: DVec2) -> f64 {
    let (x, y) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    let half_width = 0.6 * (1.0 - y * y);
    let notch = y < -0.8 && x.abs() < 0.1;
    if x.abs() <= half_width && !notch {
        1.0
    } else {
        0.0
    }
}

/// The scene the file describes, for the examples' renderer: every instance into one
/// tree (a cut-out material's mesh behind a filter, a lamp hidden from the camera), the
/// materials by their base colour and emission, the lamps as a light tree.
fn scene(file: &GltfScene, width: usize) -> Result<Scene<Bvh<Box<dyn Hittable>>>, String> {
    let mut objects: Vec<Box<dyn Hittable>> = Vec::new();
    let placed = file.transformed().map_err(|e| e.to_string())?;
    for (moved, instance) in placed.into_iter().zip(&file.instances) {
        let mesh = &file.meshes[instance.mesh];
        let material = mesh.material.map(|m| &file.materials[m]);
        let lamp = material.is_some_and(|m| m.emissive != DVec3::ZERO);
        let object: Box<dyn Hittable> = match material.map(|m| m.alpha) {
            Some(Alpha::Mask { cutoff }) => {
                let cut = Filtered::new(mesh.mesh.clone(), move |c: &Candidate| {
                    leaf_alpha(c.uv()) >= cutoff
                });
                let moved = Transformed::affine(Arc::new(cut), instance.transform)
                    .map_err(|e| e.to_string())?;
                Box::new(moved)
            }
            _ => Box::new(moved),
        };
        let mask = if lamp { !CAMERA } else { u32::MAX };
        objects.push(Box::new(Masked::new(object, mask)));
    }
    let materials = file
        .materials
        .iter()
        .map(|m| {
            if m.emissive != DVec3::ZERO {
                Material::Light(m.emissive)
            } else {
                let [r, g, b, _] = m.base_color;
                Material::Lambertian(Color::new(r, g, b))
            }
        })
        .collect::<Vec<_>>();
    let lights = file
        .lights()
        .map_err(|e| e.to_string())?
        .map(|tree| Box::new(tree) as Box<dyn PdfHittable>);
    let world = Bvh::new(objects);
    // Looking at the scene's box from the front, a little above.
    let bbox = world.bounding_box();
    let (lo, hi) = (bbox.min(), bbox.max());
    let centre = 0.5 * (lo + hi);
    let extent = (hi - lo).max_element();
    Ok(Scene {
        world,
        materials: if materials.is_empty() {
            vec![Material::Lambertian(Color::splat(0.7))]
        } else {
            materials
        },
        lights,
        next_event: true,
        background: Background::Solid(Color::new(0.05, 0.06, 0.09)),
        camera: CameraSettings {
            width,
            height: width * 9 / 16,
            vfov: 40.0,
            lookfrom: centre + extent * DVec3::new(0.1, 0.35, 1.1),
            lookat: centre - DVec3::new(0.0, 0.15 * extent, 0.0),
            vup: DVec3::Y,
            defocus_angle: 0.0,
            focus_dist: extent,
            shutter: false,
            mask: CAMERA,
        },
    })
}

/// A mesh of the grove's file: its name, corners and triangles' indices.
type Model<'a> = (&'a str, Vec<[f32; 3]>, &'a [u16]);

/// Writes the grove: a ground square, one tree model (a trunk box and three crossed leaf
/// cards) placed eleven times at other sizes, stretches and turns (some mirrored), and a
/// lamp panel facing down over them; as `grove.gltf` and `grove.bin` in a temporary
/// directory. Returns the `.gltf` file's path.
fn write_grove() -> std::io::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("hitkit-grove-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    // Four meshes in one buffer: positions (f32 x 3), uvs (f32 x 2) and u16 indices each.
    let square_xz = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ];
    let card = [
        [-0.5, 0.0, 0.0],
        [0.5, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [-0.5, 1.0, 0.0],
    ];
    let cube: Vec<[f32; 3]> = (0..8)
        .map(|i| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32])
        .collect();
    let cube_faces: [u16; 36] = [
        0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2,
        1, 3, 7, 1, 7, 5,
    ];
    let quad = [0u16, 1, 2, 0, 2, 3];
    let meshes: [Model; 4] = [
        ("ground", square_xz.to_vec(), &quad),
        ("trunk", cube, &cube_faces),
        ("leaf card", card.to_vec(), &quad),
        // Facing down: wound clockwise seen from above.
        ("lamp", square_xz.to_vec(), &quad),
    ];
    let mut bytes = Vec::new();
    let (mut views, mut accessors, mut json_meshes) = (Vec::new(), Vec::new(), Vec::new());
    for (m, (name, positions, indices)) in meshes.iter().enumerate() {
        let (start, n) = (bytes.len(), positions.len());
        positions
            .iter()
            .flatten()
            .for_each(|x| bytes.extend(x.to_le_bytes()));
        let lo = (0..3).map(|k| positions.iter().map(|p| p[k]).fold(f32::MAX, f32::min));
        let hi = (0..3).map(|k| positions.iter().map(|p| p[k]).fold(f32::MIN, f32::max));
        let list = |v: Vec<f32>| v.iter().map(f32::to_string).collect::<Vec<_>>().join(", ");
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {start}, "byteLength": {}}}"#,
            12 * n
        ));
        accessors.push(format!(
            r#"{{"bufferView": {}, "componentType": 5126, "count": {n}, "type": "VEC3", "min": [{}], "max": [{}]}}"#,
            views.len() - 1,
            list(lo.collect()),
            list(hi.collect())
        ));
        // Texture coordinates: the x and y (or z) of each corner, for the card's cut-out.
        let start = bytes.len();
        for p in positions {
            bytes.extend((p[0] + 0.5).to_le_bytes());
            bytes.extend((p[1] + p[2]).to_le_bytes());
        }
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {start}, "byteLength": {}}}"#,
            8 * n
        ));
        accessors.push(format!(
            r#"{{"bufferView": {}, "componentType": 5126, "count": {n}, "type": "VEC2"}}"#,
            views.len() - 1
        ));
        let start = bytes.len();
        indices.iter().for_each(|i| bytes.extend(i.to_le_bytes()));
        while bytes.len() % 4 != 0 {
            bytes.push(0);
        }
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {start}, "byteLength": {}}}"#,
            2 * indices.len()
        ));
        accessors.push(format!(
            r#"{{"bufferView": {}, "componentType": 5123, "count": {}, "type": "SCALAR"}}"#,
            views.len() - 1,
            indices.len()
        ));
        let a = 3 * m;
        json_meshes.push(format!(
            r#"{{"name": "{name}", "primitives": [{{"attributes": {{"POSITION": {a}, "TEXCOORD_0": {}}}, "indices": {}, "material": {m}}}]}}"#,
            a + 1,
            a + 2
        ));
    }
    let materials = [
        r#"{"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.45, 0.42, 0.35, 1]}}"#,
        r#"{"name": "bark", "pbrMetallicRoughness": {"baseColorFactor": [0.35, 0.22, 0.12, 1]}}"#,
        r#"{"name": "leaves", "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": true, "pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.55, 0.15, 1]}}"#,
        r#"{"name": "lamp", "emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12}}}"#,
    ];
    // Nodes: the ground, the lamp, then for each tree a parent and its four children.
    let mut nodes = vec![
        r#"{"name": "ground", "mesh": 0, "translation": [-12, 0, -12], "scale": [24, 1, 24]}"#.to_string(),
        r#"{"name": "lamp", "mesh": 3, "translation": [-1.5, 6, 0], "scale": [3, 1, 3], "rotation": [1, 0, 0, 0]}"#.to_string(),
    ];
    let mut roots = vec![0, 1];
    for t in 0..11 {
        let f = f64::from(t);
        let size = 0.7 + 0.9 * ((f * 0.37).sin() * 0.5 + 0.5);
        let stretch = [
            1.0 + 0.3 * (f * 1.3).cos(),
            size * (1.0 + 0.25 * (f * 2.1).sin()),
            1.0,
        ];
        let mirror = if t % 3 == 0 { -1.0 } else { 1.0 };
        let at = [
            6.0 * (f * 2.4).cos() * (0.3 + 0.07 * f),
            0.0,
            6.0 * (f * 2.4).sin() * (0.3 + 0.07 * f) - 2.0,
        ];
        let turn = DQuat::from_rotation_y(0.7 * f);
        let parent = nodes.len();
        roots.push(parent);
        nodes.push(format!(
            r#"{{"name": "tree {t}", "translation": [{}, {}, {}], "rotation": [{}, {}, {}, {}], "scale": [{}, {}, {}], "children": [{}, {}, {}, {}]}}"#,
            at[0], at[1], at[2], turn.x, turn.y, turn.z, turn.w,
            mirror * size * stretch[0], stretch[1], size * stretch[2],
            parent + 1, parent + 2, parent + 3, parent + 4
        ));
        nodes.push(r#"{"name": "trunk", "mesh": 1, "translation": [-0.1, 0, -0.1], "scale": [0.2, 1.6, 0.2]}"#.into());
        for k in 0..3 {
            let card = DQuat::from_rotation_y(f64::from(k) * std::f64::consts::PI / 3.0);
            nodes.push(format!(
                r#"{{"name": "leaves {k}", "mesh": 2, "translation": [0, 1.2, 0], "rotation": [{}, {}, {}, {}], "scale": [1.8, 2.2, 1]}}"#,
                card.x, card.y, card.z, card.w
            ));
        }
    }
    let list = |v: &[usize]| {
        v.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let json = format!(
        r#"{{"asset": {{"version": "2.0", "generator": "hitkit's scene_file example"}},
"extensionsUsed": ["KHR_materials_emissive_strength"],
"buffers": [{{"uri": "grove.bin", "byteLength": {}}}],
"bufferViews": [{}],
"accessors": [{}],
"materials": [{}],
"meshes": [{}],
"nodes": [{}],
"scenes": [{{"nodes": [{}]}}],
"scene": 0}}"#,
        bytes.len(),
        views.join(",\n"),
        accessors.join(",\n"),
        materials.join(",\n"),
        json_meshes.join(",\n"),
        nodes.join(",\n"),
        list(&roots)
    );
    std::fs::write(dir.join("grove.bin"), &bytes)?;
    let path = dir.join("grove.gltf");
    std::fs::write(&path, json)?;
    Ok(path)
}
