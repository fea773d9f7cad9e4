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

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::load::{Alpha, GltfLights, GltfScene, GltfTexture, Projection, load_gltf};
use hitkit::{
    Aabb, Bvh, Candidate, Filtered, HitRecord, Hittable, Interval, LightSample, Masked,
    PdfHittable, Ray, ShadingContext, Transformed,
};
use hitkit_render::cli::{Options, run_with};
use hitkit_render::texture::Texture;
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
        let start = std::time::Instant::now();
        let file = load_gltf(&path).map_err(|e| e.to_string())?;
        let loaded = start.elapsed();
        for left in &file.left_out {
            eprintln!("note: left out of {}: {left:?}", path.display());
        }
        let textures = images(&path);
        let mut scene = scene(&file, &textures, o.width, grove)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!(
            "{}: loaded in {:.3} s ({} instances of {} meshes, {} faces placed), scene in {:.3} s",
            path.display(),
            loaded.as_secs_f64(),
            file.instances.len(),
            file.meshes.len(),
            file.instances
                .iter()
                .map(|i| file.meshes[i.mesh].mesh.face_count())
                .sum::<usize>(),
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

/// The images of the glTF file at `path`, by their index in the file, decoded (PNG, JPEG)
/// as colour (sRGB) textures; `None` for one that cannot be read (a warning says which).
fn images(path: &Path) -> Vec<Option<Arc<Texture>>> {
    let read = || -> Result<Vec<Option<Arc<Texture>>>, String> {
        let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
        let file = gltf::Gltf::from_slice_without_validation(&bytes).map_err(|e| e.to_string())?;
        let base = path.parent();
        let buffers = gltf::import_buffers(&file.document, base, file.blob.clone())
            .map_err(|e| e.to_string())?;
        Ok(file
            .document
            .images()
            .map(|image| {
                let index = image.index();
                let decoded = gltf::image::Data::from_source(image.source(), base, &buffers)
                    .map_err(|e| e.to_string())
                    .and_then(|d| {
                        let channels = match d.format {
                            gltf::image::Format::R8 => 1,
                            gltf::image::Format::R8G8 => 2,
                            gltf::image::Format::R8G8B8 => 3,
                            gltf::image::Format::R8G8B8A8 => 4,
                            other => return Err(format!("{other:?} texels are not read")),
                        };
                        Texture::from_pixels(d.width, d.height, channels, &d.pixels, true)
                            .ok_or_else(|| "a short image".to_string())
                    });
                decoded
                    .map_err(|e| eprintln!("warning: image {index} of {}: {e}", path.display()))
                    .ok()
                    .map(Arc::new)
            })
            .collect())
    };
    read().unwrap_or_else(|e| {
        eprintln!("warning: no textures from {}: {e}", path.display());
        Vec::new()
    })
}

/// The scene's emitters as the renderer samples them: `lights` (from
/// [`GltfScene::lights_with`], each face weighed by its emissive texture's mean over it),
/// with each sample's `uv` made the mesh's texture coordinates at the sampled point, so
/// that a textured emitter's material looks its texture up there as it does at a hit.
struct TexturedLights {
    lights: GltfLights,
    /// For each light: its face's corner uvs, in the order the light's corners were given
    /// (a mirroring instance's two last swapped), where its mesh has them.
    uvs: Vec<Option<[DVec2; 3]>>,
}

impl Hittable for TexturedLights {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.lights.tree.hit(ray, ray_t)
    }
    fn bounding_box(&self) -> Aabb {
        self.lights.tree.bounding_box()
    }
}

impl PdfHittable for TexturedLights {
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.lights.tree.pdf_value(origin, direction)
    }
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.lights.tree.sample_direction(origin, u)
    }
    fn light_pdf(&self, at: &ShadingContext, direction: DVec3) -> f64 {
        self.lights.tree.light_pdf(at, direction)
    }
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        let mut sample = self.lights.tree.sample_light(at, u)?;
        if let Some([a, b, c]) = self.uvs[sample.light] {
            // A triangle light's `uv` is its `(alpha, beta)`: the weights of its second and
            // third corners.
            let (alpha, beta) = (sample.record.uv.x, sample.record.uv.y);
            sample.record.uv = a * (1.0 - alpha - beta) + b * alpha + c * beta;
        }
        Some(sample)
    }
}

/// The scene the file describes, for the examples' renderer: every instance into one
/// tree (cut-outs and single-sided surfaces behind a filter; for the grove, its lamp
/// hidden from the camera), the materials by their base colour and emission (textured
/// where the file says, from `textures`), the emitters as a light tree weighed by their
/// textures, the file's own camera where it has one, and a sky where nothing emits.
fn scene(
    file: &GltfScene,
    textures: &[Option<Arc<Texture>>],
    width: usize,
    grove: bool,
) -> Result<Scene<Bvh<Box<dyn Hittable>>>, String> {
    let texture = |t: Option<GltfTexture>| t.and_then(|t| textures.get(t.image).cloned().flatten());
    let mut objects: Vec<Box<dyn Hittable>> = Vec::new();
    let placed = file.transformed().map_err(|e| e.to_string())?;
    for (moved, instance) in placed.into_iter().zip(&file.instances) {
        let mesh = &file.meshes[instance.mesh];
        let material = mesh.material.map(|m| &file.materials[m]);
        let lamp = material.is_some_and(|m| m.emissive != DVec3::ZERO);
        // What glTF asks a renderer to cut: below the alpha cutoff (the base colour's
        // alpha times its texture's), and the back of a single-sided surface.
        let cutoff = match material.map(|m| m.alpha) {
            Some(Alpha::Mask { cutoff }) => Some(cutoff),
            _ => None,
        };
        let single_sided = material.is_some_and(|m| !m.double_sided) && !grove;
        let object: Box<dyn Hittable> = if cutoff.is_some() || single_sided {
            let alpha_texture = material.and_then(|m| texture(m.base_color_texture));
            let factor = material.map_or(1.0, |m| m.base_color[3]);
            let cut = Filtered::new(mesh.mesh.clone(), move |c: &Candidate| {
                if single_sided && !c.front_face() {
                    return false;
                }
                let Some(cutoff) = cutoff else { return true };
                let alpha = match &alpha_texture {
                    Some(t) => factor * t.sample(c.uv()).w,
                    None if grove => leaf_alpha(c.uv()),
                    None => factor,
                };
                alpha >= cutoff
            });
            let moved = Transformed::affine(Arc::new(cut), instance.transform)
                .map_err(|e| e.to_string())?;
            Box::new(moved)
        } else {
            Box::new(moved)
        };
        let mask = if lamp && grove { !CAMERA } else { u32::MAX };
        objects.push(Box::new(Masked::new(object, mask)));
    }
    let materials = file
        .materials
        .iter()
        .map(|m| {
            let [r, g, b, _] = m.base_color;
            match (
                m.emissive != DVec3::ZERO,
                texture(m.emissive_texture),
                texture(m.base_color_texture),
            ) {
                (true, Some(t), _) => Material::TexturedLight(m.emissive, t),
                (true, None, _) => Material::Light(m.emissive),
                (false, _, Some(t)) => Material::TexturedLambertian(Color::new(r, g, b), t),
                (false, _, None) => Material::Lambertian(Color::new(r, g, b)),
            }
        })
        .collect::<Vec<_>>();
    // Each emitting face weighed by its texture's mean luminance over it (a face the
    // texture leaves dark is no light); its corner uvs kept for the lookup at a sample.
    let mut corner_uvs = std::collections::HashMap::new();
    let weighed = file
        .lights_with(|face| {
            let uvs = face.uvs;
            corner_uvs.insert((face.instance, face.face), uvs);
            match (texture(face.material.emissive_texture), uvs) {
                (Some(t), Some(uvs)) => t.mean_luminance(uvs),
                _ => 1.0,
            }
        })
        .map_err(|e| e.to_string())?;
    let lights = weighed.map(|lights| {
        let uvs = lights
            .sources
            .iter()
            .map(|&(instance, face)| {
                let mirrored = file.instances[instance].transform.matrix3.determinant() < 0.0;
                corner_uvs
                    .get(&(instance, face))
                    .copied()
                    .flatten()
                    .map(|[a, b, c]| if mirrored { [a, c, b] } else { [a, b, c] })
            })
            .collect();
        Box::new(TexturedLights { lights, uvs }) as Box<dyn PdfHittable>
    });
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
    let nothing_emits = lights.is_none();
    Ok(Scene {
        world,
        materials: if materials.is_empty() {
            vec![Material::Lambertian(Color::splat(0.7))]
        } else {
            materials
        },
        lights,
        next_event: true,
        background: if nothing_emits {
            Background::Sky
        } else {
            Background::Solid(Color::new(0.05, 0.06, 0.09))
        },
        camera,
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
