//! A scene from a glTF file, traced as the file says: a grove of one tree model at many
//! sizes and stretches (scaled instances of one shared mesh), leaves that are cards with a
//! leaf-shaped cut-out (the alpha of their texture, tested inside the search), and a lamp
//! the camera does not see (a `Masked` object) that lights the grove by next-event
//! estimation: it hangs in view above the trees, and the image shows its light, not it.
//!
//! `cargo run --release --example scene_file --features gltf-images` writes the grove's
//! glTF file (its buffer and its leaf image beside it) to a temporary directory, loads it
//! as any glTF file is loaded, and renders `scene_file.png`; `-- --scene PATH` renders
//! another glTF file as a viewer would: its textures (every set, transformed as the file
//! says), its emitters as lights, and a sky around it (`--no-sky` turns it off); `--help`
//! lists the rest.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use hitkit::glam::{DQuat, DVec3};
use hitkit::load::{GltfOptions, GltfScene, Projection, load_gltf_with};
use hitkit::{Bvh, HitRecord, Hittable, Masked, PdfHittable};
use hitkit_render::cli::{Options, run_with};
use hitkit_render::texture::Textures;
use hitkit_render::{Background, CameraSettings, Color, Material, Scene};

/// The camera's rays carry this bit alone; everything but a lamp has it.
const CAMERA: u32 = 1;

const EXTRA: &str = "\n  \
--scene PATH     a glTF file to render instead of the grove written to a temporary directory\n  \
--scene-index N  which of the file's scenes (its default scene, else its first, if not given)\n  \
--no-sky         light the file by its own emitters alone (else a sky lights it too)";

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
    let (mut path, mut sky, mut options) = (None, true, GltfOptions::default());
    let (mut rest, mut args) = (Vec::new(), std::env::args().skip(1));
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--scene" => match args.next() {
                Some(p) => path = Some(PathBuf::from(p)),
                None => {
                    eprintln!("error: --scene needs a path");
                    return ExitCode::from(2);
                }
            },
            "--scene-index" => match args.next().and_then(|n| n.parse().ok()) {
                Some(n) => options = options.with_scene(n),
                None => {
                    eprintln!("error: --scene-index needs a number");
                    return ExitCode::from(2);
                }
            },
            "--no-sky" => sky = false,
            _ => rest.push(arg),
        }
    }
    run_with("scene_file", defaults, rest, EXTRA, |o| {
        let grove = path.is_none();
        let path = match path {
            Some(path) => path,
            None => write_grove().map_err(|e| format!("cannot write the grove's file: {e}"))?,
        };
        let start = Instant::now();
        let file = load_gltf_with(&path, options).map_err(|e| e.to_string())?;
        let loaded = start.elapsed();
        for left in &file.left_out {
            eprintln!("note: left out of {}: {left:?}", path.display());
        }
        let file = Arc::new(file);
        let mut scene =
            scene(&file, o.width, grove, sky).map_err(|e| format!("{}: {e}", path.display()))?;
        let textures: usize = file.images.iter().flatten().map(|i| i.heap_bytes()).sum();
        let meshes: usize = file.meshes.iter().map(|m| m.mesh.heap_bytes()).sum();
        eprintln!(
            "{}: loaded in {:.3} s ({} instances of {} meshes, {} faces placed; {} images decoded, \
             {:.1} MB of texels, {:.1} MB of meshes), scene in {:.3} s",
            path.display(),
            loaded.as_secs_f64(),
            file.instances.len(),
            file.meshes.len(),
            file.instances
                .iter()
                .map(|i| file.meshes[i.mesh].mesh.face_count())
                .sum::<usize>(),
            file.images.iter().flatten().count(),
            textures as f64 / 1e6,
            meshes as f64 / 1e6,
            (start.elapsed() - loaded).as_secs_f64(),
        );
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

/// A glTF material as the renderer shades it: its base colour and emission, each its
/// factor times its texture where it has one, looked up at the hit's surface.
#[derive(Debug)]
struct GltfLook {
    file: Arc<GltfScene>,
    material: usize,
}

impl Textures for GltfLook {
    fn albedo(&self, hit: &HitRecord) -> Color {
        let material = &self.file.materials[self.material];
        let [r, g, b, _] = material.base_color;
        let factor = Color::new(r, g, b);
        match (material.base_color_texture, self.file.surface(hit)) {
            (Some(t), Some(at)) => factor * self.file.texture_at(&t, &at).truncate(),
            _ => factor,
        }
    }

    fn emission(&self, hit: &HitRecord) -> Color {
        let material = &self.file.materials[self.material];
        if material.emissive == DVec3::ZERO || !(hit.front_face || material.double_sided) {
            return Color::ZERO;
        }
        match (material.emissive_texture, self.file.surface(hit)) {
            (Some(t), Some(at)) => material.emissive * self.file.texture_at(&t, &at).truncate(),
            _ => material.emissive,
        }
    }

    fn emits(&self) -> bool {
        self.file.materials[self.material].emissive != DVec3::ZERO
    }
}

/// The scene the file describes, for the examples' renderer: every instance into one tree
/// as glTF asks it drawn (cut-outs and single-sided surfaces inside the search; for the
/// grove, its lamp hidden from the camera), each material by its base colour and emission
/// (textured where the file says), the emitters as a light tree weighed by their textures,
/// the file's own camera where it has one, and a sky (unless `sky` is false, or the grove).
fn scene(
    file: &Arc<GltfScene>,
    width: usize,
    grove: bool,
    sky: bool,
) -> Result<Scene<Bvh<Box<dyn Hittable>>>, String> {
    let objects = file
        .objects()
        .map_err(|e| e.to_string())?
        .into_iter()
        .zip(&file.instances)
        .map(|(object, instance)| {
            let material = &file.materials[file.meshes[instance.mesh].material];
            let lamp = grove && material.emissive != DVec3::ZERO;
            let mask = if lamp { !CAMERA } else { u32::MAX };
            Box::new(Masked::new(object, mask)) as Box<dyn Hittable>
        })
        .collect();
    let materials = file
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let [r, g, b, _] = m.base_color;
            let plain = m.emissive == DVec3::ZERO
                && m.base_color_texture.is_none()
                && m.emissive_texture.is_none();
            if plain {
                Material::Lambertian(Color::new(r, g, b))
            } else {
                Material::Textured(Arc::new(GltfLook {
                    file: file.clone(),
                    material: i,
                }))
            }
        })
        // Each punctual light's emitter follows, as its material id says.
        .chain(file.punctual.iter().map(|p| Material::Light(p.emitted())))
        .collect::<Vec<_>>();
    let lights = file
        .textured_lights()
        .map_err(|e| e.to_string())?
        .map(|lights| Box::new(lights) as Box<dyn PdfHittable>);
    let world = Bvh::new(objects);
    // The file's own camera; else looking at the scene's box from the front, a little
    // above and to the right, from where its bounding sphere fills the view's height.
    let bbox = world.bounding_box();
    let (lo, hi) = (bbox.min(), bbox.max());
    let centre = 0.5 * (lo + hi);
    let extent = (hi - lo).max_element();
    let radius = 0.5 * (hi - lo).length();
    let vfov: f64 = 40.0;
    let distance = 1.05 * radius / (0.5 * vfov.to_radians()).sin();
    let mut camera = CameraSettings {
        width,
        height: width * 9 / 16,
        vfov,
        lookfrom: centre + distance * DVec3::new(0.25, 0.3, 1.0).normalize(),
        lookat: centre,
        vup: DVec3::Y,
        defocus_angle: 0.0,
        focus_dist: extent,
        shutter: false,
        mask: CAMERA,
    };
    if let Some(eye) = file.cameras.first() {
        camera.lookfrom = eye.position();
        camera.lookat = eye.position() + eye.forward();
        camera.vup = eye.up();
        camera.focus_dist = 1.0;
        if let Projection::Perspective { yfov, aspect_ratio } = eye.projection {
            camera.vfov = yfov.to_degrees();
            if let Some(aspect) = aspect_ratio.filter(|a| *a > 0.0 && a.is_finite()) {
                camera.height = ((width as f64 / aspect).round() as usize).max(1);
            }
        }
    }
    // A viewer lights a model by its surroundings as well as by what it emits; the grove
    // is lit by its lamp under a night sky.
    let background = if grove || (!sky && lights.is_some()) {
        Background::Solid(Color::new(0.05, 0.06, 0.09))
    } else if !sky {
        Background::Solid(Color::ZERO)
    } else {
        Background::Sky
    };
    Ok(Scene {
        world,
        materials,
        lights,
        next_event: true,
        background,
        camera,
    })
}

/// A mesh of the grove's file: its name, corners and triangles' indices.
type Model<'a> = (&'a str, Vec<[f32; 3]>, &'a [u16]);

/// The leaves' image: green, opaque inside a leaf's outline (a pointed oval along the
/// card's `v`, with a notch cut at its stem), transparent outside; `n` x `n` texels.
fn leaf_image(n: usize) -> Vec<u8> {
    let mut texels = Vec::with_capacity(4 * n * n);
    for j in 0..n {
        for i in 0..n {
            let (u, v) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let (x, y) = (2.0 * u - 1.0, 2.0 * v - 1.0);
            let half_width = 0.6 * (1.0 - y * y);
            let notch = y < -0.8 && x.abs() < 0.1;
            let alpha = if x.abs() <= half_width && !notch {
                255
            } else {
                0
            };
            texels.extend([255, 255, 255, alpha]);
        }
    }
    texels
}

/// Writes the grove: a ground square, one tree model (a trunk box and three crossed leaf
/// cards, their cut-out an image's alpha) placed eleven times at other sizes, stretches and
/// turns (some mirrored), and a lamp panel facing down over them; as `grove.gltf`,
/// `grove.bin` and `leaf.png` in a temporary directory. Returns the `.gltf` file's path.
fn write_grove() -> std::io::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("hitkit-grove-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let leaf = std::io::BufWriter::new(std::fs::File::create(dir.join("leaf.png"))?);
    let mut encoder = png::Encoder::new(leaf, 64, 64);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(&leaf_image(64)))
        .map_err(std::io::Error::other)?;
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
        r#"{"name": "ground", "doubleSided": true, "pbrMetallicRoughness": {"baseColorFactor": [0.45, 0.42, 0.35, 1]}}"#,
        r#"{"name": "bark", "doubleSided": true, "pbrMetallicRoughness": {"baseColorFactor": [0.35, 0.22, 0.12, 1]}}"#,
        r#"{"name": "leaves", "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": true, "pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.55, 0.15, 1], "baseColorTexture": {"index": 0}}}"#,
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
"images": [{{"uri": "leaf.png"}}],
"textures": [{{"source": 0}}],
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
