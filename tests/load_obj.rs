//! `load::load_obj` (the `obj` feature): an OBJ file's objects, materials, normals and
//! texture coordinates as the file gives them, and bad files as errors naming the file and
//! what is wrong. The files are written here, not kept in the repository.
#![cfg(feature = "obj")]

use std::path::PathBuf;

use hitkit::glam::{DVec2, DVec3};
use hitkit::load::{LoadErrorKind, load_obj};
use hitkit::{GeometryError, Hittable, Interval, MaterialId, Ray};

/// A fresh directory for one test's files.
fn dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hitkit-obj-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const TWO_OBJECTS: &str = "\
mtllib two.mtl
v 0 0 0
v 2 0 0
v 2 2 0
v 0 2 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
o floor
usemtl grey
f 1/1/1 2/2/1 3/3/1 4/4/1
v 0 0 -3
v 2 0 -3
v 1 2 -3
o back
usemtl lamp
f 5 6 7
";

const MATERIALS: &str = "\
newmtl lamp
Ke 4 4 4
newmtl grey
Kd 0.5 0.5 0.5
";

#[test]
fn objects_materials_normals_and_texture_coordinates_come_as_the_file_gives_them() {
    let dir = dir("two");
    std::fs::write(dir.join("two.obj"), TWO_OBJECTS).unwrap();
    std::fs::write(dir.join("two.mtl"), MATERIALS).unwrap();
    let scene = load_obj(dir.join("two.obj")).unwrap();
    assert_eq!(scene.materials, ["lamp", "grey"]);
    assert!(scene.material_error.is_none());
    let names: Vec<_> = scene.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["floor", "back"]);
    let (floor, back) = (&scene.meshes[0], &scene.meshes[1]);
    assert_eq!(
        (floor.material.as_deref(), back.material.as_deref()),
        (Some("grey"), Some("lamp"))
    );
    assert_eq!(
        (floor.mesh.material(), back.mesh.material()),
        (MaterialId(1), MaterialId(0))
    );
    assert_eq!((floor.mesh.face_count(), back.mesh.face_count()), (2, 1));
    // The floor's texture coordinates are interpolated (the file's, not barycentrics),
    // and its normal is the file's.
    let down = Ray::new(DVec3::new(1.5, 0.5, 1.0), DVec3::NEG_Z);
    let hit = floor.mesh.hit(&down, Interval::FORWARD).unwrap();
    assert!(
        (hit.uv - DVec2::new(0.75, 0.25)).length() < 1e-12,
        "{:?}",
        hit.uv
    );
    assert_eq!(hit.shading_normal, DVec3::Z);
    // The back triangle has neither: barycentrics for uv.
    let hit = back
        .mesh
        .hit(
            &Ray::new(DVec3::new(1.0, 0.5, 0.0), DVec3::NEG_Z),
            Interval::FORWARD,
        )
        .unwrap();
    assert_eq!(hit.t, 3.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_material_library_is_reported_beside_the_meshes() {
    let dir = dir("nomtl");
    std::fs::write(dir.join("two.obj"), TWO_OBJECTS).unwrap();
    let scene = load_obj(dir.join("two.obj")).unwrap();
    assert_eq!(scene.meshes.len(), 2);
    assert!(scene.materials.is_empty());
    assert!(scene.material_error.is_some());
    assert!(
        scene
            .meshes
            .iter()
            .all(|m| m.material.is_none() && m.mesh.material() == MaterialId(0))
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_files_are_errors_naming_the_file_and_what_is_wrong() {
    let dir = dir("bad");
    let cases: [(&str, &str); 4] = [
        ("empty.obj", "# nothing here\n"),
        ("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n"),
        ("past.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
        ("huge.obj", "v 0 0 0\nv 1e308 0 0\nv 0 inf 0\nf 1 2 3\n"),
    ];
    for (name, text) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let err = load_obj(&path).unwrap_err();
        assert_eq!(err.file, path);
        let message = err.to_string();
        assert!(message.contains(name), "{message}");
        let expected = match (name, &err.kind) {
            ("empty.obj", LoadErrorKind::Empty) => true,
            ("past.obj", LoadErrorKind::Parse(why)) => why.contains("out of bounds"),
            (
                "nan.obj" | "huge.obj",
                LoadErrorKind::Geometry {
                    error: GeometryError::NonFiniteElement { index: 2, .. },
                    ..
                },
            ) => true,
            _ => false,
        };
        assert!(expected, "{name}: {err:?}");
    }
    let missing = dir.join("missing.obj");
    let err = load_obj(&missing).unwrap_err();
    assert!(matches!(err.kind, LoadErrorKind::Io(_)), "{err:?}");
    assert!(err.to_string().contains("missing.obj"));
    std::fs::remove_dir_all(&dir).unwrap();
}
