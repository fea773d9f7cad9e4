//! What a glTF viewer asks of `load::load_gltf` beyond the geometry: sparse accessors read
//! as glTF says (on a buffer view and on zeros, indices of every width; malformed ones an
//! error, not a panic), every set of texture coordinates and `KHR_texture_transform`,
//! faces by number, glTF's default material, the surface at a hit and at a light's sample
//! (through a mirroring instance), a scene by its number, errors that name the culprit,
//! and, with `gltf-images`, the images decoded and looked up, and the instances cut as the
//! materials say. The files are written here.
#![cfg(feature = "gltf")]

mod support;

use std::path::{Path, PathBuf};

use hitkit::glam::{DVec2, DVec3};
use hitkit::load::{GltfOptions, LeftOut, LoadErrorKind, load_gltf, load_gltf_with};
use hitkit::{Bvh, Hittable, Interval, MaterialId, PdfHittable, Ray, ShadingContext};

fn dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hitkit-shading-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The buffer: a unit square's corners, two sets of texture coordinates (the second the
/// first halved and moved to the upper right quarter), nine indices (two faces and one
/// with no area), and sparse storage: a replacement for corner 2 indexed by `u8`, `u16`
/// and `u32`, and the indices 0 to 3 (for corners on zeros).
fn bytes() -> Vec<u8> {
    let mut b = Vec::new();
    let f32s = |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend(x.to_le_bytes()));
    f32s(&mut b, &[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.]); // 0: 48
    f32s(&mut b, &[0., 0., 1., 0., 1., 1., 0., 1.]); // 48: 32
    f32s(&mut b, &[0.5, 0.5, 1., 0.5, 1., 1., 0.5, 1.]); // 80: 32
    [0u16, 1, 2, 0, 2, 3, 0, 1, 1]
        .iter()
        .for_each(|i| b.extend(i.to_le_bytes())); // 112: 18
    b.resize(132, 0);
    b.push(2); // 132: 1
    b.resize(136, 0);
    f32s(&mut b, &[2., 2., 0.]); // 136: 12
    b.extend(2u16.to_le_bytes()); // 148: 2
    b.resize(152, 0);
    b.extend(2u32.to_le_bytes()); // 152: 4
    b.extend([0u8, 1, 2, 3]); // 156: 4
    b
}

/// The file: the square (both uv sets, a cut-out texture on the second set under a
/// transform, emitting) under a node mirrored, stretched and moved far out; four squares
/// whose corners are sparse (three on the square's corners with corner 2 replaced, one on
/// zeros with every corner given), with no material; scene 1 holds the first node alone.
/// `sparse8` replaces the first sparse accessor's JSON.
fn json(sparse8: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_texture_transform"],
  "buffers": [{{"uri": "shading.bin", "byteLength": 160}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 112, "byteLength": 18}},
    {{"buffer": 0, "byteOffset": 132, "byteLength": 1}},
    {{"buffer": 0, "byteOffset": 136, "byteLength": 12}},
    {{"buffer": 0, "byteOffset": 148, "byteLength": 2}},
    {{"buffer": 0, "byteOffset": 152, "byteLength": 4}},
    {{"buffer": 0, "byteOffset": 156, "byteLength": 4}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5123, "count": 9, "type": "SCALAR"}},
    {sparse8},
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [2, 2, 0],
      "sparse": {{"count": 1, "indices": {{"bufferView": 6, "componentType": 5123}}, "values": {{"bufferView": 5}}}}}},
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [2, 2, 0],
      "sparse": {{"count": 1, "indices": {{"bufferView": 7, "componentType": 5125}}, "values": {{"bufferView": 5}}}}}},
    {{"componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0],
      "sparse": {{"count": 4, "indices": {{"bufferView": 8, "componentType": 5121}}, "values": {{"bufferView": 0}}}}}}
  ],
  "materials": [
    {{"name": "cut", "alphaMode": "MASK", "emissiveFactor": [1, 1, 1],
      "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0, "texCoord": 1,
        "extensions": {{"KHR_texture_transform": {{"offset": [0.25, 0], "scale": [2, 2]}}}}}}}}}}
  ],
  "samplers": [{{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}}],
  "images": [{{"uri": "cut.png"}}],
  "textures": [{{"source": 0, "sampler": 0}}],
  "meshes": [
    {{"name": "square", "primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}}, "indices": 3, "material": 0}}]}},
    {{"name": "sparse8", "primitives": [{{"attributes": {{"POSITION": 4}}, "indices": 3}}]}},
    {{"name": "sparse16", "primitives": [{{"attributes": {{"POSITION": 5}}, "indices": 3}}]}},
    {{"name": "sparse32", "primitives": [{{"attributes": {{"POSITION": 6}}, "indices": 3}}]}},
    {{"name": "zeros", "primitives": [{{"attributes": {{"POSITION": 7}}, "indices": 3}}]}}
  ],
  "nodes": [
    {{"name": "square", "mesh": 0, "translation": [1e6, 0, 0], "scale": [-2, 3, 1]}},
    {{"name": "sparse8", "mesh": 1, "translation": [0, 0, -10]}},
    {{"name": "sparse16", "mesh": 2, "translation": [0, 0, -20]}},
    {{"name": "sparse32", "mesh": 3, "translation": [0, 0, -30]}},
    {{"name": "zeros", "mesh": 4, "translation": [0, 0, -40]}}
  ],
  "scenes": [{{"name": "all", "nodes": [0, 1, 2, 3, 4]}}, {{"nodes": [0]}}],
  "scene": 0
}}"#
    )
}

const SPARSE8: &str = r#"{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [2, 2, 0],
      "sparse": {"count": 1, "indices": {"bufferView": 4, "componentType": 5121}, "values": {"bufferView": 5}}}"#;

/// Writes the file (with `sparse8`), its buffer and its image (2 x 1 texels: the left
/// one transparent red, the right one opaque grey of sRGB code 128).
fn write(dir: &Path, sparse8: &str) -> PathBuf {
    std::fs::write(dir.join("shading.bin"), bytes()).unwrap();
    support::write_png(
        &dir.join("cut.png"),
        2,
        1,
        &[[255, 0, 0, 0], [128, 128, 128, 255]],
    );
    let path = dir.join("shading.gltf");
    std::fs::write(&path, json(sparse8)).unwrap();
    path
}

/// The corners of a mesh's faces with area, by face number.
fn corners(scene: &hitkit::load::GltfScene, mesh: usize) -> Vec<[DVec3; 3]> {
    let m = &scene.meshes[mesh];
    (0..3)
        .filter_map(|n| m.face(n))
        .map(|f| f.corners())
        .collect()
}

#[test]
fn sparse_accessors_replace_what_they_index_on_a_view_or_on_zeros() {
    let dir = dir("sparse");
    let scene = load_gltf(write(&dir, SPARSE8)).unwrap();
    let square = corners(&scene, 0);
    let replaced: Vec<[DVec3; 3]> = square
        .iter()
        .map(|face| {
            face.map(|p| {
                if p == DVec3::new(1.0, 1.0, 0.0) {
                    DVec3::new(2.0, 2.0, 0.0)
                } else {
                    p
                }
            })
        })
        .collect();
    // Corner 2 replaced, whatever the indices' width; on zeros, every corner given.
    for mesh in 1..=3 {
        assert_eq!(corners(&scene, mesh), replaced, "mesh {mesh}");
    }
    assert_eq!(corners(&scene, 4), square);
    assert!(square.iter().flatten().all(|p| p.z == 0.0) && square.len() == 2);

    // Malformed sparse storage: an error naming the mesh and the accessor, never a panic
    // or values silently dropped (the `gltf` crate skips an index out of order).
    let bad = [
        (
            SPARSE8.replace(r#""count": 1, "indices""#, r#""count": 2, "indices""#),
            "past its buffer view",
        ),
        (
            SPARSE8
                .replace(
                    r#""bufferView": 4, "componentType": 5121"#,
                    r#""bufferView": 7, "componentType": 5121"#,
                )
                .replace(r#""count": 1, "indices""#, r#""count": 3, "indices""#),
            "values",
        ),
        (
            SPARSE8
                .replace(r#""bufferView": 4"#, r#""bufferView": 8"#)
                .replace(r#""count": 1, "indices""#, r#""count": 5, "indices""#),
            "5 sparse values, for 4 elements",
        ),
        (
            SPARSE8.replace(r#""count": 4"#, r#""count": 2"#),
            "past the elements",
        ),
    ];
    for (accessor, problem) in bad {
        let err = load_gltf(write(&dir, &accessor)).unwrap_err();
        match &err.kind {
            LoadErrorKind::Malformed {
                mesh,
                accessor: 4,
                problem: p,
            } => {
                assert_eq!(mesh, "sparse8#0");
                assert!(p.contains(problem), "{p}");
            }
            _ => panic!("{err:?}"),
        }
    }
    // Out of order: the corners-on-zeros accessor's indices made 3, 0, 1, 2.
    let mut b = bytes();
    b[156..160].copy_from_slice(&[3, 0, 1, 2]);
    std::fs::write(dir.join("shading.bin"), &b).unwrap();
    let path = dir.join("shading.gltf");
    std::fs::write(&path, json(SPARSE8)).unwrap();
    let scene = load_gltf(&path);
    let err = scene.unwrap_err();
    assert!(err.to_string().contains("out of order"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn faces_by_number_and_the_default_material() {
    let dir = dir("faces");
    let scene = load_gltf(write(&dir, SPARSE8)).unwrap();
    let square = &scene.meshes[0];
    for n in 0..2 {
        assert_eq!(square.face(n).unwrap().index(), n);
    }
    // Face 2 has no area: never hit, so no face; face 3 does not exist.
    assert!(
        square.face(2).is_none() && square.face(3).is_none() && square.face(u32::MAX).is_none()
    );
    // The sparse squares name no material: glTF's default one, after the file's.
    assert_eq!(scene.materials.len(), 2);
    let default = &scene.materials[1];
    assert_eq!((default.index, default.base_color), (None, [1.0; 4]));
    assert_eq!(scene.materials[0].index, Some(0));
    assert_eq!(scene.meshes[1].material, 1);
    assert_eq!(scene.meshes[1].mesh.material(), MaterialId(1));
    assert_eq!(square.mesh.material(), MaterialId(0));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// At a hit through the mirrored, stretched instance 1e6 out, the surface names the
/// instance, the face, the material, and each set's texture coordinates as the mesh
/// interpolates them: the hit's own `uv` (set 0, from the exact barycentrics) against
/// the surface's (from the hit point moved back into the mesh), within what the point's
/// rounding allows (its error, a few ulps of 1e6, over the face's size of 2 and 3: about
/// 1e-9); set 1, the first halved and moved; the texture's, set 1 under its transform.
#[test]
fn the_surface_at_a_hit_gives_every_set_and_the_transform() {
    let dir = dir("surface");
    let scene = load_gltf(write(&dir, SPARSE8)).unwrap();
    let tree = Bvh::new(scene.transformed().unwrap());
    let texture = scene.materials[0].base_color_texture.unwrap();
    assert_eq!(texture.tex_coord, 1);
    let mut rng = support::SplitMix::new(59);
    for _ in 0..200 {
        // The square spans x in [1e6 - 2, 1e6], y in [0, 3] at z = 0.
        let (x, y) = (1e6 - 2.0 * rng.next_f64(), 3.0 * rng.next_f64());
        let ray = Ray::new(DVec3::new(x, y, 5.0), DVec3::NEG_Z);
        let hit = tree.hit(&ray, Interval::FORWARD).unwrap();
        let at = scene.surface(&hit).unwrap();
        assert_eq!((at.instance, at.material.name.as_str()), (0, "cut"));
        assert_eq!(Some(at.face.index()), hit.primitive);
        let uv0 = at.uv(0).unwrap();
        assert!(
            (uv0 - hit.uv).abs().max_element() < 1e-9,
            "{uv0} {}",
            hit.uv
        );
        // The mirror maps x to 1e6 - 2 u.
        let expected = DVec2::new((1e6 - x) / 2.0, y / 3.0);
        assert!((uv0 - expected).abs().max_element() < 1e-9);
        let uv1 = at.uv(1).unwrap();
        assert!((uv1 - (0.5 * uv0 + 0.5)).abs().max_element() < 1e-9);
        let read = at.coordinates(&texture);
        assert!(
            (read - (DVec2::new(0.25, 0.0) + 2.0 * uv1))
                .abs()
                .max_element()
                < 1e-8
        );
        assert!(at.uv(2).is_none());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A light's sample names its instance and face, with the mesh's texture coordinates at
/// the sampled point: the surface there (found from the point) agrees with the `uv` the
/// sample carries (from the light's own barycentrics, its corners swapped by the mirror).
/// A corner order left unswapped puts the two apart by up to a whole face.
#[test]
fn a_light_sample_names_its_face_and_its_texture_coordinates() {
    let dir = dir("lights");
    let scene = load_gltf(write(&dir, SPARSE8)).unwrap();
    let lights = scene.textured_lights().unwrap().unwrap();
    assert_eq!(lights.sources.len(), 2);
    // Below the square's front (+z: a mirror keeps the mesh's front, as glTF says).
    let at = ShadingContext::on_surface(DVec3::new(1e6 - 1.0, 1.5, 4.0), DVec3::NEG_Z);
    let mut rng = support::SplitMix::new(61);
    let mut sampled = 0;
    for _ in 0..500 {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        let Some(sample) = lights.sample_light(&at, u) else {
            continue;
        };
        sampled += 1;
        assert!(sample.record.front_face);
        let surface = scene.surface(&sample.record).unwrap();
        assert_eq!(surface.instance, 0);
        let uv = surface.uv(0).unwrap();
        assert!(
            (uv - sample.record.uv).abs().max_element() < 1e-9,
            "{uv} {}",
            sample.record.uv
        );
        let point = sample.record.point;
        let expected = DVec2::new((1e6 - point.x) / 2.0, point.y / 3.0);
        assert!((uv - expected).abs().max_element() < 1e-9);
        // The lights hit along the sample's direction: the same face, named alike.
        let ray = Ray::new(at.point, sample.direction);
        let hit = lights.hit(&ray, Interval::FORWARD).unwrap();
        assert_eq!(hit.primitive, sample.record.primitive);
        assert!((hit.uv - sample.record.uv).abs().max_element() < 1e-9);
    }
    assert!(sampled > 400, "{sampled}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_scene_by_its_number() {
    let dir = dir("scenes");
    let path = write(&dir, SPARSE8);
    let all = load_gltf(&path).unwrap();
    assert_eq!((all.instances.len(), all.scenes.read), (5, Some(0)));
    assert_eq!(all.scenes.names, ["all", "scene 1"]);
    let one = load_gltf_with(&path, GltfOptions::default().with_scene(1)).unwrap();
    assert_eq!((one.instances.len(), one.scenes.read), (1, Some(1)));
    let err = load_gltf_with(&path, GltfOptions::default().with_scene(2)).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Unsupported(_)), "{err:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Errors name the culprit: a missing buffer by its own file, a file that is neither JSON
/// nor a GLB by its first bytes, a rotation that is no rotation by its node (left out,
/// with what it carries); an image in a format of an extension (KTX2) loads, its texture
/// reading the extension's image.
#[test]
fn errors_name_the_culprit() {
    let dir = dir("culprit");
    let path = write(&dir, SPARSE8);
    std::fs::remove_file(dir.join("shading.bin")).unwrap();
    let err = load_gltf(&path).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Io(_)), "{err:?}");
    assert!(err.file.ends_with("shading.bin"), "{err}");

    let glb = dir.join("bad.glb");
    std::fs::write(&glb, b"glTX\x02\x00\x00\x00\x0c\x00\x00\x00").unwrap();
    let err = load_gltf(&glb).unwrap_err();
    assert!(err.to_string().contains("magic"), "{err}");

    let path = write(&dir, SPARSE8);
    let turned = json(SPARSE8).replace(
        r#""name": "sparse16", "mesh": 2,"#,
        r#""name": "sparse16", "mesh": 2, "rotation": [0, 0, 0, 0],"#,
    );
    std::fs::write(&path, turned).unwrap();
    let scene = load_gltf(&path).unwrap();
    assert_eq!(scene.instances.len(), 4);
    assert!(
        scene
            .left_out
            .iter()
            .any(|l| matches!(l, LeftOut::Node { node, .. } if node == "sparse16"))
    );

    // An image in a buffer view without a type (which glTF requires; the `gltf` crate
    // unwrapped it: found by the fuzz target): the file loads, the image left out.
    let untyped = json(SPARSE8).replace(r#"{"uri": "cut.png"}"#, r#"{"bufferView": 4}"#);
    std::fs::write(&path, untyped).unwrap();
    let scene = load_gltf(&path).unwrap();
    assert!(
        scene.left_out.iter().any(
            |l| matches!(l, LeftOut::Image { image: 0, reason } if reason.contains("mimeType"))
        )
    );
    assert!(scene.images[0].is_none());

    let basisu = json(SPARSE8)
        .replace(r#""textures": [{"source": 0, "sampler": 0}]"#, r#""textures": [{"sampler": 0, "extensions": {"KHR_texture_basisu": {"source": 1}}}]"#)
        .replace(r#""images": [{"uri": "cut.png"}]"#, r#""images": [{"uri": "cut.png"}, {"uri": "cut.ktx2", "mimeType": "image/ktx2"}]"#)
        .replace(r#""extensionsUsed": ["KHR_texture_transform"]"#, r#""extensionsUsed": ["KHR_texture_transform", "KHR_texture_basisu"], "extensionsRequired": ["KHR_texture_basisu"]"#);
    std::fs::write(&path, basisu).unwrap();
    let scene = load_gltf(&path).unwrap();
    assert_eq!(
        scene.materials[0].base_color_texture.map(|t| t.image),
        Some(1)
    );
    assert!(
        scene
            .left_out
            .contains(&LeftOut::Extension("KHR_texture_basisu".into()))
    );
    if cfg!(feature = "gltf-images") {
        assert!(
            scene.left_out.iter().any(
                |l| matches!(l, LeftOut::Image { image: 1, reason } if reason.contains("cut.ktx2"))
            ),
            "{:?}",
            scene.left_out
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The image decoded and looked up as its sampler says (nearest, clamped along u,
/// mirrored along v; sRGB colour decoded, alpha linear), and the square cut where the
/// texture's alpha (on set 1, under the transform) is below the cutoff, its back turned
/// away (single-sided). Along the face's `u`, set 1 is `0.5 u + 0.5` and the texture reads
/// `offset + 2 (0.5 u + 0.5)`: with the file's offset 0.25, from 1.25 on, past the image's
/// right edge, clamped to the opaque texel (nothing cut); with an offset of -1, `u`
/// itself, the transparent texel below 0.5.
#[cfg(feature = "gltf-images")]
#[test]
fn images_are_read_as_their_samplers_say_and_cut_as_the_material_says() {
    let dir = dir("images");
    let scene = load_gltf(write(&dir, SPARSE8)).unwrap();
    let image = scene.images[0].as_ref().unwrap();
    assert_eq!((image.width(), image.height()), (2, 1));
    let texture = scene.materials[0].base_color_texture.unwrap();
    let grey = ((128.0 / 255.0 + 0.055) / 1.055f64).powf(2.4);
    let texel = |u: f64, v: f64| scene.texel(&texture, DVec2::new(u, v));
    for v in [0.5, -0.5, 1.5, 2.5, -7.25] {
        assert_eq!(texel(0.25, v).to_array(), [1.0, 0.0, 0.0, 0.0], "v {v}");
        assert_eq!(texel(0.75, v).to_array(), [grey, grey, grey, 1.0], "v {v}");
        // Clamped along u: the edge texels beyond.
        assert_eq!(texel(-3.0, v).w, 0.0);
        assert_eq!(texel(9.0, v).w, 1.0);
    }

    // Which of 40 rays across the face's `u` meet it from the front (+z, the mirrored
    // square's front as glTF keeps it); none meets its back.
    let met = |scene: &hitkit::load::GltfScene| -> Vec<bool> {
        let tree = Bvh::new(scene.objects().unwrap());
        (0..40)
            .map(|i| {
                let u = (f64::from(i) + 0.5) / 40.0;
                let x = 1e6 - 2.0 * u;
                let back = Ray::new(DVec3::new(x, 1.5, -5.0), DVec3::Z);
                assert!(tree.hit(&back, Interval::FORWARD).is_none());
                let front = Ray::new(DVec3::new(x, 1.5, 5.0), DVec3::NEG_Z);
                tree.hit(&front, Interval::FORWARD).is_some()
            })
            .collect()
    };
    assert!(met(&scene).iter().all(|&m| m));
    let path = dir.join("shading.gltf");
    std::fs::write(&path, json(SPARSE8).replace("[0.25, 0]", "[-1, 0]")).unwrap();
    let scene = load_gltf(&path).unwrap();
    let expected: Vec<bool> = (0..40).map(|i| i >= 20).collect();
    assert_eq!(met(&scene), expected);
    std::fs::remove_dir_all(&dir).unwrap();
}
