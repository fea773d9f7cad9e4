//! `load::load_gltf` (the `gltf` feature): every mesh primitive once, every node as an
//! instance under its composed transform, the materials' alpha modes and emission, the
//! instances as a tree and the emitters as a light tree; bad files as errors naming the
//! file and what is wrong. The files are written here, not kept in the repository.
#![cfg(feature = "gltf")]

mod support;

use std::path::{Path, PathBuf};

use hitkit::glam::{DVec2, DVec3};
use hitkit::load::{Alpha, LeftOut, LoadErrorKind, load_gltf, load_gltf_slice};
use hitkit::{Bvh, GeometryError, Hittable, Interval, PdfHittable, Ray};

fn dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hitkit-gltf-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The buffer: a unit square's four corners, their texture coordinates, and its two
/// triangles' indices.
fn square_bytes(last_index: u16) -> Vec<u8> {
    let corners: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let uvs: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let mut bytes = Vec::new();
    corners
        .iter()
        .flatten()
        .for_each(|x| bytes.extend(x.to_le_bytes()));
    uvs.iter()
        .flatten()
        .for_each(|x| bytes.extend(x.to_le_bytes()));
    [0u16, 1, 2, 0, 2, last_index]
        .iter()
        .for_each(|i| bytes.extend(i.to_le_bytes()));
    bytes
}

/// A scene: a parent node scaled by 2 and moved to z = -5 with two leaves (one moved
/// along x, one stretched 1:3:0.5), both of a cut-out square; and a lamp square turned to
/// face down at y = 10. `mode` is the primitives' mode (4: triangles).
fn scene_json(mode: u32) -> String {
    scene_json_with(mode, "[1, 1, 1]")
}

/// [`scene_json`] with the lamp's node scaled by `lamp_scale` (a JSON array).
fn scene_json_with(mode: u32, lamp_scale: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "buffers": [{{"uri": "scene.bin", "byteLength": 92}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ],
  "materials": [
    {{"name": "leaf", "alphaMode": "MASK", "alphaCutoff": 0.25, "doubleSided": true,
      "pbrMetallicRoughness": {{"baseColorFactor": [0.2, 0.6, 0.1, 1.0], "baseColorTexture": {{"index": 1}}}}}},
    {{"name": "lamp", "emissiveFactor": [1.0, 1.0, 1.0], "emissiveTexture": {{"index": 0, "texCoord": 1}}}}
  ],
  "images": [{{"uri": "glow.png"}}, {{"uri": "leaf.png"}}],
  "textures": [{{"source": 0}}, {{"source": 1}}],
  "meshes": [
    {{"name": "leaf", "primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0, "mode": {mode}}}]}},
    {{"name": "lamp", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 2, "material": 1, "mode": {mode}}}]}}
  ],
  "nodes": [
    {{"name": "branch", "scale": [2, 2, 2], "translation": [0, 0, -5], "children": [1, 2]}},
    {{"name": "leaf a", "mesh": 0, "translation": [1, 0, 0]}},
    {{"name": "leaf b", "mesh": 0, "scale": [1, 3, 0.5], "translation": [-2, 0, 0]}},
    {{"name": "lamp", "mesh": 1, "translation": [0, 10, 0], "rotation": [0.7071067811865476, 0, 0, 0.7071067811865476], "scale": {lamp_scale}}}
  ],
  "scenes": [{{"nodes": [0, 3]}}],
  "scene": 0
}}"#
    )
}

fn write(dir: &Path, json: &str, bytes: &[u8]) -> PathBuf {
    std::fs::write(dir.join("scene.bin"), bytes).unwrap();
    // The leaf's cut-out: its left half transparent; the lamp's glow: dark but for its
    // right column.
    support::write_png(
        &dir.join("leaf.png"),
        2,
        1,
        &[[0, 255, 0, 0], [0, 255, 0, 255]],
    );
    support::write_png(
        &dir.join("glow.png"),
        2,
        2,
        &[
            [0, 0, 0, 255],
            [255, 255, 255, 255],
            [0, 0, 0, 255],
            [255, 255, 255, 255],
        ],
    );
    let path = dir.join("scene.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn meshes_nodes_and_materials_come_as_the_file_gives_them() {
    let dir = dir("scene");
    let path = write(&dir, &scene_json(4), &square_bytes(3));
    let scene = load_gltf(&path).unwrap();
    assert_eq!(scene.meshes.len(), 2);
    assert_eq!(
        (scene.meshes[0].name.as_str(), scene.meshes[0].material),
        ("leaf#0", 0)
    );
    let (leaf, lamp) = (&scene.materials[0], &scene.materials[1]);
    assert_eq!(leaf.alpha, Alpha::Mask { cutoff: 0.25 });
    assert!(leaf.double_sided && leaf.emissive == DVec3::ZERO);
    assert_eq!((lamp.alpha, lamp.emissive), (Alpha::Opaque, DVec3::ONE));
    // Textures by the file's indices (the images are not read).
    let texture =
        |t: Option<hitkit::load::GltfTexture>| t.map(|t| (t.texture, t.image, t.tex_coord));
    assert_eq!(texture(leaf.base_color_texture), Some((1, 1, 0)));
    assert_eq!(texture(lamp.emissive_texture), Some((0, 0, 1)));
    assert_eq!((leaf.emissive_texture, leaf.normal_texture), (None, None));
    let nodes: Vec<_> = scene
        .instances
        .iter()
        .map(|i| (i.node.as_str(), i.mesh))
        .collect();
    assert_eq!(nodes, [("leaf a", 0), ("leaf b", 0), ("lamp", 1)]);
    // Composed: the branch's scale and move after the leaf's own.
    let a = scene.instances[0].transform;
    assert_eq!(a.transform_point3(DVec3::ZERO), DVec3::new(2.0, 0.0, -5.0));
    assert_eq!(a.transform_point3(DVec3::ONE), DVec3::new(4.0, 2.0, -3.0));
    let b = scene.instances[1].transform;
    assert_eq!(
        b.transform_point3(DVec3::new(1.0, 1.0, 0.0)),
        DVec3::new(-2.0, 6.0, -5.0)
    );

    // As a tree: a ray down the z axis through leaf a's middle, and one through leaf b.
    let tree = Bvh::new(scene.transformed().unwrap());
    let ray = Ray::new(DVec3::new(3.0, 1.0, 10.0), DVec3::NEG_Z);
    let hit = tree.hit(&ray, Interval::FORWARD).unwrap();
    assert_eq!((hit.t, hit.instance), (15.0, Some(0)));
    assert!(
        (hit.uv - DVec2::new(0.5, 0.5)).length() < 1e-12,
        "{:?}",
        hit.uv
    );
    let hit = tree
        .hit(
            &Ray::new(DVec3::new(-3.0, 5.0, 10.0), DVec3::NEG_Z),
            Interval::FORWARD,
        )
        .unwrap();
    assert_eq!(hit.instance, Some(1));
    // The lamp: turned a quarter about x, its square lies in y = 10 facing down.
    let lights = scene.lights().unwrap().unwrap();
    assert_eq!(lights.lights().len(), 2);
    let below = DVec3::new(0.5, 0.0, -0.5);
    let toward = lights.sample_direction(below, DVec2::new(0.3, 0.6));
    assert!(toward.y > 0.0 && lights.pdf_value(below, toward) > 0.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_files_are_errors_naming_the_file_and_what_is_wrong() {
    let dir = dir("bad");
    let missing = dir.join("missing.gltf");
    let err = load_gltf(&missing).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Io(_)) && err.to_string().contains("missing.gltf"));

    let path = dir.join("scene.gltf");
    std::fs::write(&path, "{ not json").unwrap();
    let err = load_gltf(&path).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Parse(_)), "{err:?}");
    assert!(err.to_string().contains("scene.gltf"), "{err}");

    // Its buffer file gone: the file cannot be read whole (it was a parse error).
    std::fs::write(&path, scene_json(4)).unwrap();
    let err = load_gltf(&path).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Io(_)), "{err:?}");

    // Points only, not triangles: nothing to trace.
    let path = write(&dir, &scene_json(0), &square_bytes(3));
    let err = load_gltf(&path).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Empty), "{err:?}");

    // An index past the four corners.
    let path = write(&dir, &scene_json(4), &square_bytes(9));
    let err = load_gltf(&path).unwrap_err();
    match err.kind {
        LoadErrorKind::Geometry {
            ref mesh,
            error: GeometryError::IndexOutOfRange { index: 9, .. },
        } => {
            assert_eq!(mesh, "leaf#0");
        }
        _ => panic!("{err:?}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A single-sided lamp under a mirroring node (`scale [-1, 1, 1]`) keeps its front side,
/// as glTF says: it lights the floor below it as the unmirrored lamp does (the two are
/// mirror images about `x = 0`, and the point lit lies on that plane), and shows its back
/// above it. Its faces were turned around by their corners' winding after the mirror:
/// their backs below, where a renderer's `front_face` check then found no light.
#[test]
fn a_mirrored_lamp_keeps_its_front_side() {
    use hitkit::ShadingContext;
    let dir = dir("mirror");
    let mut irradiance = Vec::new();
    for scale in ["[1, 1, 1]", "[-1, 1, 1]"] {
        let path = write(&dir, &scene_json_with(4, scale), &square_bytes(3));
        let lights = load_gltf(&path).unwrap().lights().unwrap().unwrap();
        let below = ShadingContext::on_surface(DVec3::new(0.0, 0.0, 0.5), DVec3::Y);
        let above = ShadingContext::on_surface(DVec3::new(0.0, 20.0, 0.5), DVec3::NEG_Y);
        let mut rng = support::SplitMix::new(49);
        let mut values = Vec::new();
        for _ in 0..4000 {
            let u = DVec2::new(rng.next_f64(), rng.next_f64());
            let sample = lights
                .sample_light(&below, u)
                .expect("the lamp faces the floor");
            assert!(sample.record.front_face, "{scale}: lit from behind");
            values.push(sample.direction.y / sample.pdf);
            // The tree may still pick a lamp that faces away (by power, where none faces
            // the point), but what it finds is the lamp's back, which emits nothing.
            if let Some(back) = lights.sample_light(&above, u) {
                assert!(!back.record.front_face, "{scale}: lit above");
            }
        }
        irradiance.push(support::mean_and_error(&values));
    }
    support::assert_same_mean(irradiance[0], irradiance[1], "mirrored against unmirrored");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Strips and fans are triangles in another order (their winding kept: every face's front
/// is toward +z, as the list's); points and lines are left out and listed, and the file
/// loads. A file with a points primitive was refused whole.
#[test]
fn strips_and_fans_are_triangles_and_points_and_lines_are_left_out() {
    let dir = dir("modes");
    let mut bytes = square_bytes(3);
    [0u16, 1, 3, 2, 0, 1, 2, 3]
        .iter()
        .for_each(|i| bytes.extend(i.to_le_bytes()));
    let json = scene_json(4)
        .replace(r#""byteLength": 92"#, r#""byteLength": 108"#)
        .replace(
            r#"{"buffer": 0, "byteOffset": 80, "byteLength": 12}"#,
            r#"{"buffer": 0, "byteOffset": 80, "byteLength": 12},
    {"buffer": 0, "byteOffset": 92, "byteLength": 8},
    {"buffer": 0, "byteOffset": 100, "byteLength": 8}"#,
        )
        .replace(
            r#"{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}"#,
            r#"{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 3, "componentType": 5123, "count": 4, "type": "SCALAR"},
    {"bufferView": 4, "componentType": 5123, "count": 4, "type": "SCALAR"}"#,
        )
        .replace(
            r#"{"name": "lamp", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 1, "mode": 4}]}"#,
            r#"{"name": "lamp", "primitives": [
      {"attributes": {"POSITION": 0}, "indices": 3, "material": 1, "mode": 5},
      {"attributes": {"POSITION": 0}, "indices": 4, "material": 1, "mode": 6},
      {"attributes": {"POSITION": 0}, "mode": 0},
      {"attributes": {"POSITION": 0}, "indices": 2, "mode": 1}]}"#,
        );
    let path = write(&dir, &json, &bytes);
    let scene = load_gltf(&path).unwrap();
    let names: Vec<_> = scene.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["leaf#0", "lamp#0", "lamp#1"]);
    assert_eq!(
        scene.left_out,
        [
            LeftOut::Primitive {
                mesh: "lamp#2".into(),
                mode: "POINTS"
            },
            LeftOut::Primitive {
                mesh: "lamp#3".into(),
                mode: "LINES"
            },
        ]
    );
    for mesh in &scene.meshes[1..] {
        assert_eq!(mesh.mesh.face_count(), 2, "{}", mesh.name);
        // Both halves of the square, from the front.
        for x in [0.25, 0.75] {
            let ray = Ray::new(DVec3::new(x, 1.0 - x + 0.1, 1.0), DVec3::NEG_Z);
            let hit = mesh.mesh.hit(&ray, Interval::FORWARD).unwrap();
            assert!(hit.front_face, "{}: {hit:?}", mesh.name);
        }
    }
    // The lamp node holds the strip and the fan; the leaves the list.
    assert_eq!(scene.instances.len(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A node scaled to zero (which files use to hide a part) is left out and named; the
/// rest of the file, its children included, loads and `transformed` succeeds. It failed
/// `transformed` with an error naming neither the node nor the file.
#[test]
fn a_node_scaled_to_zero_is_left_out_and_named() {
    let dir = dir("zero");
    let json = scene_json(4).replace(
        r#"{"name": "leaf b", "mesh": 0, "scale": [1, 3, 0.5]"#,
        r#"{"name": "leaf b", "mesh": 0, "scale": [0, 0, 0]"#,
    );
    let path = write(&dir, &json, &square_bytes(3));
    let scene = load_gltf(&path).unwrap();
    let nodes: Vec<_> = scene.instances.iter().map(|i| i.node.as_str()).collect();
    assert_eq!(nodes, ["leaf a", "lamp"]);
    assert!(
        matches!(&scene.left_out[..], [LeftOut::Node { node, .. }] if node == "leaf b"),
        "{:?}",
        scene.left_out
    );
    assert_eq!(scene.transformed().unwrap().len(), 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A required extension that changes only textures or shading loads, listed as left out
/// (a file requiring `KHR_texture_transform` was refused); one that changes geometry and
/// is not read is refused by name.
#[test]
fn required_extensions_that_change_only_shading_load() {
    let dir = dir("extensions");
    let with = |names: &str| {
        scene_json(4).replace(
            r#""asset": {"version": "2.0"},"#,
            &format!(
                r#""asset": {{"version": "2.0"}}, "extensionsUsed": [{names}], "extensionsRequired": [{names}],"#
            ),
        )
    };
    let path = write(
        &dir,
        &with(r#""KHR_texture_transform", "KHR_materials_clearcoat""#),
        &square_bytes(3),
    );
    // The texture transform is read (not left out); the clearcoat is not.
    let scene = load_gltf(&path).unwrap();
    assert_eq!(
        scene.left_out,
        [LeftOut::Extension("KHR_materials_clearcoat".into())]
    );
    for geometry in ["KHR_draco_mesh_compression", "EXT_meshopt_compression"] {
        let path = write(&dir, &with(&format!("\"{geometry}\"")), &square_bytes(3));
        let err = load_gltf(&path).unwrap_err();
        assert!(matches!(err.kind, LoadErrorKind::Unsupported(_)), "{err:?}");
        assert!(err.to_string().contains(geometry), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Malformed accessors are errors naming the file, the mesh and the accessor, never a
/// panic inside the `gltf` crate or a mesh read wrong: an accessor that does not exist
/// (it panicked), a stride shorter than the element (it panicked), indices of count 0 (it
/// panicked), indices or positions past their buffer view (they loaded as no indices, or
/// an empty mesh), indices that are not whole triangles (truncated).
#[test]
fn malformed_accessors_are_errors_naming_the_mesh_and_the_accessor() {
    let dir = dir("malformed");
    let positions = r#"{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}"#;
    let indices = r#"{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}"#;
    let cases: [(&str, String, usize, &str); 6] = [
        (
            "no such accessor",
            scene_json(4).replace(
                r#""POSITION": 0, "TEXCOORD_0""#,
                r#""POSITION": 7, "TEXCOORD_0""#,
            ),
            7,
            "no such accessor",
        ),
        (
            "a short stride",
            scene_json(4).replace(
                r#"{"buffer": 0, "byteOffset": 0, "byteLength": 48}"#,
                r#"{"buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 4}"#,
            ),
            0,
            "stride",
        ),
        (
            "no indices",
            scene_json(4).replace(indices, &indices.replace(r#""count": 6"#, r#""count": 0"#)),
            2,
            "no elements",
        ),
        (
            "indices past their view",
            scene_json(4).replace(
                indices,
                &indices.replace(r#""count": 6"#, r#""count": 600"#),
            ),
            2,
            "past its buffer view",
        ),
        (
            "positions past their view",
            scene_json(4).replace(
                positions,
                &positions.replace(r#""count": 4"#, r#""count": 40"#),
            ),
            0,
            "past its buffer view",
        ),
        (
            "indices of no whole triangle",
            scene_json(4).replace(indices, &indices.replace(r#""count": 6"#, r#""count": 5"#)),
            2,
            "not whole triangles",
        ),
    ];
    for (what, json, accessor, says) in cases {
        let path = write(&dir, &json, &square_bytes(3));
        let err = load_gltf(&path).unwrap_err();
        match &err.kind {
            LoadErrorKind::Malformed {
                mesh,
                accessor: named,
                problem,
            } => {
                assert_eq!(
                    (mesh.as_str(), *named),
                    ("leaf#0", accessor),
                    "{what}: {err}"
                );
                assert!(problem.contains(says), "{what}: {err}");
            }
            _ => panic!("{what}: {err:?}"),
        }
        assert!(err.to_string().contains("scene.gltf"), "{what}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file held in memory: a `.gltf` with its buffer inline loads as from a file; one whose
/// buffer is in another file is an I/O error.
#[test]
fn a_file_in_memory_loads_as_from_disk() {
    use base64_inline::encode;
    let inline = scene_json(4).replace(
        r#""uri": "scene.bin""#,
        &format!(
            r#""uri": "data:application/octet-stream;base64,{}""#,
            encode(&square_bytes(3))
        ),
    );
    let scene = load_gltf_slice(inline.as_bytes()).unwrap();
    assert_eq!((scene.meshes.len(), scene.instances.len()), (2, 3));
    let err = load_gltf_slice(scene_json(4).as_bytes()).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Io(_)), "{err:?}");
}

/// Standard base64, for inline buffers (the tests add no dependency for it).
mod base64_inline {
    pub fn encode(bytes: &[u8]) -> String {
        const TABLE: &[u8; 64] =
            b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut out = String::new();
        for chunk in bytes.chunks(3) {
            let b = [
                chunk[0],
                *chunk.get(1).unwrap_or(&0),
                *chunk.get(2).unwrap_or(&0),
            ];
            let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
            for i in 0..4 {
                if i <= chunk.len() {
                    out.push(TABLE[(n >> (18 - 6 * i) & 63) as usize] as char);
                } else {
                    out.push('=');
                }
            }
        }
        out
    }
}

/// `EXT_mesh_gpu_instancing`: a node's instances (translations, rotations, scales, after
/// the node's own transform) are instances of the scene; one scaled to zero is left out
/// and named. They were dropped: the file loaded as the node's one mesh.
#[test]
fn gpu_instances_are_instances() {
    let dir = dir("instancing");
    let mut bytes = square_bytes(3);
    let translations: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [6.0, 0.0, 0.0]];
    // A quarter turn about z for the second; the third scaled to zero.
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let rotations: [[f32; 4]; 3] = [
        [0.0, 0.0, 0.0, 1.0],
        [0.0, 0.0, half, half],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let scales: [[f32; 3]; 3] = [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [0.0, 0.0, 0.0]];
    translations
        .iter()
        .flatten()
        .chain(rotations.iter().flatten())
        .chain(scales.iter().flatten())
        .for_each(|x| bytes.extend(x.to_le_bytes()));
    let json = scene_json(4)
        .replace(r#""asset": {"version": "2.0"},"#, r#""asset": {"version": "2.0"}, "extensionsUsed": ["EXT_mesh_gpu_instancing"],"#)
        .replace(r#""byteLength": 92"#, r#""byteLength": 212"#)
        .replace(
            r#"{"buffer": 0, "byteOffset": 80, "byteLength": 12}"#,
            r#"{"buffer": 0, "byteOffset": 80, "byteLength": 12},
    {"buffer": 0, "byteOffset": 92, "byteLength": 36},
    {"buffer": 0, "byteOffset": 128, "byteLength": 48},
    {"buffer": 0, "byteOffset": 176, "byteLength": 36}"#,
        )
        .replace(
            r#"{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}"#,
            r#"{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC3"},
    {"bufferView": 4, "componentType": 5126, "count": 3, "type": "VEC4"},
    {"bufferView": 5, "componentType": 5126, "count": 3, "type": "VEC3"}"#,
        )
        .replace(
            r#"{"name": "leaf a", "mesh": 0, "translation": [1, 0, 0]}"#,
            r#"{"name": "leaf a", "mesh": 0, "translation": [1, 0, 0], "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 3, "ROTATION": 4, "SCALE": 5}}}}"#,
        );
    let path = write(&dir, &json, &bytes);
    let scene = load_gltf(&path).unwrap();
    let nodes: Vec<_> = scene.instances.iter().map(|i| i.node.as_str()).collect();
    assert_eq!(nodes, ["leaf a#0", "leaf a#1", "leaf b", "lamp"]);
    assert!(
        matches!(&scene.left_out[..], [LeftOut::Node { node, .. }] if node == "leaf a#2"),
        "{:?}",
        scene.left_out
    );
    // Under the branch (scale 2, moved to z = -5) and the node's own move along x: the
    // second instance's corner (1, 0, 0) is turned to (0, 2, 0), then moved by 3 + 1.
    let second = scene.instances[1].transform;
    let corner = second.transform_point3(DVec3::X);
    assert!(
        (corner - DVec3::new(8.0, 4.0, -5.0)).length() < 1e-6,
        "{corner}"
    );
    assert_eq!(scene.transformed().unwrap().len(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `lights_with` weighs each emitting face (a textured emitter's texture, read by the
/// renderer): a face of weight 0 is no light, and each light says which instance and
/// face it is, for the texture lookup at a sampled point. `lights` reads the factor alone.
#[test]
fn emitters_are_weighed_by_what_the_renderer_reads() {
    let dir = dir("weighed");
    let path = write(&dir, &scene_json(4), &square_bytes(3));
    let scene = load_gltf(&path).unwrap();
    let lamp = scene
        .instances
        .iter()
        .position(|i| i.node == "lamp")
        .unwrap();
    let mut asked = Vec::new();
    let lights = scene
        .lights_with(|face| {
            assert_eq!(face.material.emissive_texture.map(|t| t.image), Some(0));
            asked.push((face.instance, face.face, face.uvs));
            if face.face == 0 { 0.0 } else { 3.0 }
        })
        .unwrap()
        .unwrap();
    // Both faces asked (the lamp has no uvs), only the second kept.
    assert_eq!(asked, [(lamp, 0, None), (lamp, 1, None)]);
    assert_eq!(lights.tree.lights().len(), 1);
    assert_eq!(lights.sources, [(lamp, 1)]);
    assert!(scene.lights_with(|_| 0.0).unwrap().is_none());
    assert_eq!(scene.lights().unwrap().unwrap().lights().len(), 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file's cameras: where their nodes put them (looking along the node's `-z`), and their
/// projections.
#[test]
fn cameras_come_with_their_place_and_projection() {
    use hitkit::load::Projection;
    let dir = dir("cameras");
    let json = scene_json(4)
        .replace(
            r#""scenes": [{"nodes": [0, 3]}],"#,
            r#""cameras": [{"type": "perspective", "perspective": {"yfov": 0.75, "znear": 0.1, "aspectRatio": 1.5}}],
  "scenes": [{"nodes": [0, 3, 4]}],"#,
        )
        .replace(
            r#""scale": [1, 1, 1]}"#,
            r#""scale": [1, 1, 1]},
    {"name": "eye", "camera": 0, "translation": [0, 1, 5], "rotation": [0, 0.7071067811865476, 0, 0.7071067811865476]}"#,
        );
    let path = write(&dir, &json, &square_bytes(3));
    let scene = load_gltf(&path).unwrap();
    let [camera] = &scene.cameras[..] else {
        panic!("{:?}", scene.cameras)
    };
    assert_eq!(camera.node, "eye");
    assert_eq!(camera.position(), DVec3::new(0.0, 1.0, 5.0));
    // A quarter turn about y takes -z to -x.
    assert!(
        (camera.forward() - DVec3::NEG_X).length() < 1e-6,
        "{}",
        camera.forward()
    );
    assert!((camera.up() - DVec3::Y).length() < 1e-6);
    assert_eq!(
        camera.projection,
        Projection::Perspective {
            yfov: 0.75,
            aspect_ratio: Some(1.5)
        }
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A GLB file whose header gives a length shorter than the header (0 here) is a parse
/// error: the `gltf` crate's own split subtracted the header's size from it unchecked
/// (a panic with overflow checks on, as in tests). Found by the `gltf` fuzz target.
#[test]
fn a_glb_header_shorter_than_itself_is_an_error() {
    let mut bytes = b"glTF".to_vec();
    bytes.extend(2u32.to_le_bytes());
    bytes.extend(0u32.to_le_bytes());
    bytes.extend(8u32.to_le_bytes());
    bytes.extend(b"JSON{}  ");
    let err = load_gltf_slice(&bytes).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Parse(_)), "{err:?}");
    // And chunks past the file's end, or a first chunk that is not JSON.
    for (length, chunk, kind) in [(28u32, 1000u32, *b"JSON"), (28, 8, *b"BIN\0")] {
        let mut bytes = b"glTF".to_vec();
        bytes.extend(2u32.to_le_bytes());
        bytes.extend(length.to_le_bytes());
        bytes.extend(chunk.to_le_bytes());
        bytes.extend(kind);
        bytes.extend(b"{}      ");
        let err = load_gltf_slice(&bytes).unwrap_err();
        assert!(matches!(err.kind, LoadErrorKind::Parse(_)), "{err:?}");
    }
}

/// A buffer whose file name's percent escapes decode to bytes that are not UTF-8 is a parse
/// error (the `gltf` crate unwrapped the decoding and panicked). Found by the `gltf` fuzz
/// target.
#[test]
fn a_buffer_name_that_is_not_utf8_is_an_error() {
    let json = scene_json(4).replace(r#""uri": "scene.bin""#, r#""uri": "scene%AA.bin""#);
    let err = load_gltf_slice(json.as_bytes()).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Parse(_)), "{err:?}");
    assert!(err.to_string().contains("buffer 0"), "{err}");
}
