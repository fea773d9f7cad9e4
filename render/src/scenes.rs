//! The examples' scenes, here so that tests and benches render exactly what the examples do.

use hitkit::glam::DVec3;
use hitkit::{MaterialId, Quad};

use crate::{Background, CameraSettings, Color, Material, Scene};

/// The quads scene's background: the book's `cam.background`.
pub const QUADS_BACKGROUND: Color = Color::new(0.70, 0.80, 1.00);

/// The book's five quads, each its own colour, against the book's flat light blue
/// background (0.70, 0.80, 1.00), as in its image of the scene. Five quads are traced fastest
/// as a plain list (a `Bvh` of them measured 20% slower: its box tests cost more than the
/// quad tests they save).
pub fn quads_scene(width: usize) -> Scene<Vec<Quad>> {
    let materials = vec![
        Material::Lambertian(Color::new(1.0, 0.2, 0.2)), // left red
        Material::Lambertian(Color::new(0.2, 1.0, 0.2)), // back green
        Material::Lambertian(Color::new(0.2, 0.2, 1.0)), // right blue
        Material::Lambertian(Color::new(1.0, 0.5, 0.0)), // upper orange
        Material::Lambertian(Color::new(0.2, 0.8, 0.8)), // lower teal
    ];
    let quad = |q: [f64; 3], u: [f64; 3], v: [f64; 3], m: u32| {
        Quad::new(q.into(), u.into(), v.into())
            .expect("the book's quads are valid")
            .with_material(MaterialId(m))
    };
    let world = vec![
        quad([-3.0, -2.0, 5.0], [0.0, 0.0, -4.0], [0.0, 4.0, 0.0], 0),
        quad([-2.0, -2.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0], 1),
        quad([3.0, -2.0, 1.0], [0.0, 0.0, 4.0], [0.0, 4.0, 0.0], 2),
        quad([-2.0, 3.0, 1.0], [4.0, 0.0, 0.0], [0.0, 0.0, 4.0], 3),
        quad([-2.0, -3.0, 5.0], [4.0, 0.0, 0.0], [0.0, 0.0, -4.0], 4),
    ];
    Scene {
        world,
        materials,
        lights: None,
        next_event: false,
        background: Background::Solid(QUADS_BACKGROUND),
        camera: CameraSettings {
            width,
            height: width,
            vfov: 80.0,
            lookfrom: DVec3::new(0.0, 0.0, 9.0),
            lookat: DVec3::ZERO,
            vup: DVec3::Y,
            defocus_angle: 0.0,
            focus_dist: 10.0,
            shutter: false,
            mask: u32::MAX,
        },
    }
}

/// A triangle, a disk, a ring and a user-written predicate (a star) side by side above a
/// ground quad, under the sky.
pub fn shapes_scene(width: usize) -> Scene<Vec<Box<dyn hitkit::Hittable>>> {
    use hitkit::{Disk, Ring, Triangle};
    let materials = vec![
        Material::Lambertian(Color::new(0.8, 0.3, 0.2)),
        Material::Lambertian(Color::new(0.2, 0.6, 0.8)),
        Material::Lambertian(Color::new(0.9, 0.7, 0.2)),
        Material::Lambertian(Color::new(0.5, 0.8, 0.3)),
        Material::Lambertian(Color::splat(0.5)),
    ];
    let (x, y) = (DVec3::X, DVec3::Y);
    // A five-pointed star in (alpha, beta) around the centre of the unit square: inside when
    // the radius is below a boundary that swings between 0.2 and 0.5 with the angle.
    let star = |a: f64, b: f64| {
        let (dx, dy) = (a - 0.5, b - 0.5);
        let angle = dy.atan2(dx) * 5.0;
        (dx * dx + dy * dy).sqrt() <= 0.35 + 0.15 * angle.cos()
    };
    let id = MaterialId;
    let world: Vec<Box<dyn hitkit::Hittable>> = vec![
        Box::new(
            Quad::with_interior(DVec3::new(-4.0, -1.0, 0.0), 2.0 * x, 2.0 * y, Triangle)
                .unwrap()
                .with_material(id(0)),
        ),
        Box::new(
            Quad::with_interior(DVec3::new(-0.9, 0.0, 0.0), x, y, Disk)
                .unwrap()
                .with_material(id(1)),
        ),
        Box::new(
            Quad::with_interior(DVec3::new(1.3, 0.0, 0.0), x, y, Ring::new(0.5).unwrap())
                .unwrap()
                .with_material(id(2)),
        ),
        Box::new(
            Quad::with_interior(DVec3::new(2.5, -1.0, 0.0), 2.0 * x, 2.0 * y, star)
                .unwrap()
                .with_material(id(3)),
        ),
        Box::new(
            Quad::new(
                DVec3::new(-50.0, -1.2, 50.0),
                100.0 * x,
                DVec3::new(0.0, 0.0, -100.0),
            )
            .unwrap()
            .with_material(id(4)),
        ),
    ];
    Scene {
        world,
        materials,
        lights: None,
        next_event: false,
        background: Background::Sky,
        camera: CameraSettings {
            width,
            height: width / 2,
            vfov: 40.0,
            lookfrom: DVec3::new(0.0, 1.0, 8.0),
            lookat: DVec3::ZERO,
            vup: DVec3::Y,
            defocus_angle: 0.0,
            focus_dist: 8.0,
            shutter: false,
            mask: u32::MAX,
        },
    }
}

/// The walls and lamp of the Cornell box (the book's `cornell_box()`), and the materials
/// red, white, green and light (ids 0 to 3).
fn cornell_walls() -> (Vec<Material>, Vec<Quad>, Quad) {
    let (red, white, green, light) = (MaterialId(0), MaterialId(1), MaterialId(2), MaterialId(3));
    let materials = vec![
        Material::Lambertian(Color::new(0.65, 0.05, 0.05)),
        Material::Lambertian(Color::splat(0.73)),
        Material::Lambertian(Color::new(0.12, 0.45, 0.15)),
        Material::Light(Color::splat(15.0)),
    ];
    let quad = |q: [f64; 3], u: [f64; 3], v: [f64; 3], m: MaterialId| {
        Quad::new(q.into(), u.into(), v.into())
            .expect("the book's quads are valid")
            .with_material(m)
    };
    let lamp = quad(
        [343.0, 554.0, 332.0],
        [-130.0, 0.0, 0.0],
        [0.0, 0.0, -105.0],
        light,
    );
    let walls = vec![
        quad(
            [555.0, 0.0, 0.0],
            [0.0, 555.0, 0.0],
            [0.0, 0.0, 555.0],
            green,
        ),
        quad([0.0, 0.0, 0.0], [0.0, 555.0, 0.0], [0.0, 0.0, 555.0], red),
        quad([0.0, 0.0, 0.0], [555.0, 0.0, 0.0], [0.0, 0.0, 555.0], white),
        quad(
            [555.0, 555.0, 555.0],
            [-555.0, 0.0, 0.0],
            [0.0, 0.0, -555.0],
            white,
        ),
        quad(
            [0.0, 0.0, 555.0],
            [555.0, 0.0, 0.0],
            [0.0, 555.0, 0.0],
            white,
        ),
    ];
    (materials, walls, lamp)
}

/// A white box of `size` turned by `degrees` about y and moved by `offset` (the book's
/// `rotate_y` then `translate`).
fn cornell_block(
    size: [f64; 3],
    degrees: f64,
    offset: [f64; 3],
) -> hitkit::Transformed<hitkit::Cuboid> {
    use hitkit::glam::DQuat;
    let block = hitkit::Cuboid::new(DVec3::ZERO, size.into())
        .expect("a valid box")
        .with_material(MaterialId(1));
    hitkit::Transformed::new(
        block,
        DQuat::from_rotation_y(degrees.to_radians()),
        offset.into(),
    )
    .expect("a valid motion")
}

/// The walls, the lamp and a tall box: what both Cornell scenes have. The walls and the
/// lamp are one `Vec<Quad>` in the world (a single entry whose loop over the six quads is
/// compiled for `Quad`), not six boxed entries each called through a `dyn Hittable`.
fn cornell_room() -> (Vec<Material>, Vec<Box<dyn hitkit::Hittable>>, Quad) {
    use hitkit::Hittable;
    let (materials, mut walls, lamp) = cornell_walls();
    walls.push(lamp);
    let mut world: Vec<Box<dyn Hittable>> = vec![Box::new(walls)];
    world.push(Box::new(cornell_block(
        [165.0, 330.0, 165.0],
        15.0,
        [265.0, 0.0, 295.0],
    )));
    (materials, world, lamp)
}

/// The book's camera on the Cornell box.
fn cornell_camera(width: usize) -> CameraSettings {
    CameraSettings {
        width,
        height: width,
        vfov: 40.0,
        lookfrom: DVec3::new(278.0, 278.0, -800.0),
        lookat: DVec3::new(278.0, 278.0, 0.0),
        vup: DVec3::Y,
        defocus_angle: 0.0,
        focus_dist: 10.0,
        shutter: false,
        mask: u32::MAX,
    }
}

/// The Cornell box of "Ray Tracing: The Rest of Your Life": walls and light as quads, two
/// boxes of six quads each, rotated and translated; the light is sampled by `sampling`.
pub fn cornell_scene(
    width: usize,
    sampling: hitkit::Sampling,
) -> Scene<Vec<Box<dyn hitkit::Hittable>>> {
    use hitkit::PdfHittable;
    let (materials, mut world, lamp) = cornell_room();
    world.push(Box::new(cornell_block(
        [165.0, 165.0, 165.0],
        -18.0,
        [130.0, 0.0, 65.0],
    )));
    let lights: Vec<Box<dyn PdfHittable>> = vec![Box::new(lamp.with_sampling(sampling))];
    Scene {
        world,
        materials,
        lights: Some(Box::new(lights)),
        next_event: false,
        background: Background::Solid(Color::ZERO),
        camera: cornell_camera(width),
    }
}

/// The last Cornell box of "Ray Tracing: The Rest of Your Life", as its `main()` builds it:
/// the tall box, a glass sphere in place of the short one, and both the lamp (sampled by
/// area, as the book's quad pdf is) and the sphere (by the cone it subtends) as lights,
/// picked with equal probability. Rendered without Russian roulette, this is the book's
/// work ray for ray: the like-for-like comparison of `benches/book.sh`.
pub fn cornell_book_scene(width: usize) -> Scene<Vec<Box<dyn hitkit::Hittable>>> {
    use hitkit::{PdfHittable, Sampling, Sphere};
    let (mut materials, mut world, lamp) = cornell_room();
    let glass = MaterialId(materials.len() as u32);
    materials.push(Material::Dielectric(1.5));
    let sphere = Sphere::new(DVec3::new(190.0, 90.0, 190.0), 90.0)
        .expect("the book's sphere is valid")
        .with_material(glass);
    world.push(Box::new(sphere));
    let lights: Vec<Box<dyn PdfHittable>> = vec![
        Box::new(lamp.with_sampling(Sampling::Area)),
        Box::new(sphere),
    ];
    Scene {
        world,
        materials,
        lights: Some(Box::new(lights)),
        next_event: false,
        background: Background::Solid(Color::ZERO),
        camera: cornell_camera(width),
    }
}

/// A torus around the y axis (ring radius `big`, tube radius `small`), `around` by
/// `along` quads of two triangles sharing their vertices (the seams close: the last row
/// and column reuse the first), with its exact normals and `(around, along)` texture
/// coordinates per vertex: a closed, smooth mesh with no file needed.
pub fn torus(big: f64, small: f64, around: u32, along: u32) -> hitkit::TriangleMesh {
    use std::f64::consts::TAU;
    let (mut vertices, mut normals, mut uvs) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..around {
        let (s, c) = (TAU * f64::from(i) / f64::from(around)).sin_cos();
        for j in 0..along {
            let (sv, cv) = (TAU * f64::from(j) / f64::from(along)).sin_cos();
            let normal = DVec3::new(c * cv, sv, s * cv);
            vertices.push(DVec3::new(big * c, 0.0, big * s) + small * normal);
            normals.push(normal);
            uvs.push(hitkit::glam::DVec2::new(
                f64::from(i) / f64::from(around),
                f64::from(j) / f64::from(along),
            ));
        }
    }
    let at = |i: u32, j: u32| (i % around) * along + (j % along);
    let faces: Vec<[u32; 3]> = (0..around)
        .flat_map(|i| {
            (0..along).flat_map(move |j| {
                [
                    [at(i, j), at(i, j + 1), at(i + 1, j)],
                    [at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)],
                ]
            })
        })
        .collect();
    hitkit::TriangleMesh::new(&vertices, &faces)
        .and_then(|m| m.with_normals(&normals))
        .and_then(|m| m.with_uvs(&uvs))
        .expect("the torus is a valid mesh")
}

/// The triangles of the OBJ file at `path` (every model, triangulated), with the file's
/// vertex normals where it has one for every vertex, centred at the origin and scaled to
/// a largest extent of 2.
pub fn load_obj(path: &std::path::Path) -> Result<hitkit::TriangleMesh, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    // Opened first, so that a missing or unreadable file is refused with the operating
    // system's reason (tobj's error names none).
    std::fs::File::open(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let (models, _) = tobj::load_obj(path, &options)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let (mut vertices, mut normals, mut faces) = (Vec::new(), Vec::new(), Vec::new());
    let mut all_normals = true;
    for model in models {
        let m = model.mesh;
        let base = vertices.len() as u32;
        let triple = |v: &[f64]| -> Vec<DVec3> {
            v.chunks_exact(3)
                .map(|p| DVec3::new(p[0], p[1], p[2]))
                .collect()
        };
        let positions = triple(&m.positions);
        all_normals &= m.normals.len() == m.positions.len();
        normals.extend(triple(&m.normals));
        vertices.extend(positions);
        faces.extend(
            m.indices
                .chunks_exact(3)
                .map(|f| [f[0] + base, f[1] + base, f[2] + base]),
        );
    }
    if faces.is_empty() {
        return Err(format!("{} has no triangles", path.display()));
    }
    let (lo, hi) = vertices
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let (centre, scale) = (0.5 * (lo + hi), 2.0 / (hi - lo).max_element());
    let placed: Vec<DVec3> = vertices.iter().map(|&p| scale * (p - centre)).collect();
    let mesh = hitkit::TriangleMesh::new(&placed, &faces)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if mesh.hittable_face_count() == 0 {
        return Err(format!(
            "{}: all {} triangles are degenerate (no area): nothing to render",
            path.display(),
            faces.len()
        ));
    }
    if all_normals {
        mesh.with_normals(&normals)
            .map_err(|e| format!("{}: {e}", path.display()))
    } else {
        Ok(mesh)
    }
}

/// Sets each hit's material from the instance it came through: `first + instance % count`.
/// How a renderer gives instances of one shared mesh their own materials, through
/// `HitRecord::instance`.
pub struct ByInstance<T> {
    pub inner: T,
    pub first: u32,
    pub count: u32,
}

impl<T: hitkit::Hittable> hitkit::Hittable for ByInstance<T> {
    fn hit(&self, ray: &hitkit::Ray, ray_t: hitkit::Interval) -> Option<hitkit::HitRecord> {
        let hit = self.inner.hit(ray, ray_t)?;
        let id = hit.instance.map_or(0, |i| i % self.count);
        Some(hit.with_material(MaterialId(self.first + id)))
    }

    fn bounding_box(&self) -> hitkit::Aabb {
        self.inner.bounding_box()
    }

    fn occluded(&self, ray: &hitkit::Ray, ray_t: hitkit::Interval) -> bool {
        self.inner.occluded(ray, ray_t)
    }
}

/// A mesh (a generated torus, or `mesh` from a file) instanced 120 times over a ground
/// quad under the sky, each instance turned its own way and coloured by its instance id;
/// a few of them in motion (rising over the shutter interval: motion blur), and three
/// moving balls, as the book's bouncing spheres.
pub fn mesh_scene(
    width: usize,
    mesh: Option<hitkit::TriangleMesh>,
) -> Scene<Vec<Box<dyn hitkit::Hittable>>> {
    use std::sync::Arc;

    use hitkit::glam::DQuat;
    use hitkit::{Bvh, Hittable, Moving, Sphere, Transformed};

    let mesh = Arc::new(mesh.unwrap_or_else(|| torus(1.0, 0.35, 96, 48)));
    let mut materials = vec![
        Material::Lambertian(Color::new(0.5, 0.5, 0.5)), // ground
        Material::Metal(Color::new(0.8, 0.8, 0.9), 0.05),
        Material::Dielectric(1.5),
    ];
    let palette = [
        Color::new(0.8, 0.3, 0.3),
        Color::new(0.3, 0.7, 0.4),
        Color::new(0.3, 0.4, 0.8),
        Color::new(0.9, 0.7, 0.2),
        Color::new(0.7, 0.4, 0.8),
        Color::new(0.2, 0.7, 0.8),
    ];
    let first = materials.len() as u32;
    materials.extend(palette.iter().map(|&c| Material::Lambertian(c)));

    // A fixed seed, so the scene is the same on every run (the renderer's generator).
    let mut rng = {
        use rand::SeedableRng;
        rand::rngs::SmallRng::seed_from_u64(0x6d65_7368)
    };
    let mut next = move || rand::RngExt::random::<f64>(&mut rng);
    let mut instances: Vec<Box<dyn Hittable>> = Vec::new();
    for id in 0..120u32 {
        let (row, column) = (f64::from(id / 12), f64::from(id % 12));
        let at = DVec3::new(
            3.0 * (column - 5.5) + next() - 0.5,
            1.0,
            -3.0 * row + next() - 0.5,
        );
        let turn = DQuat::from_euler(
            hitkit::glam::EulerRot::YXZ,
            std::f64::consts::TAU * next(),
            0.6 * (next() - 0.5),
            0.6 * (next() - 0.5),
        );
        let instance = Transformed::new(mesh.clone(), turn, at)
            .expect("a finite motion")
            .with_instance_id(id);
        if id % 17 == 5 {
            instances.push(Box::new(
                Moving::new(instance, DVec3::new(0.0, 0.6, 0.0)).expect("a finite motion"),
            ));
        } else {
            instances.push(Box::new(instance));
        }
    }
    let mut world: Vec<Box<dyn Hittable>> = vec![
        Box::new(
            Quad::new(
                DVec3::new(-100.0, 0.0, 60.0),
                DVec3::new(200.0, 0.0, 0.0),
                DVec3::new(0.0, 0.0, -200.0),
            )
            .expect("a valid ground")
            .with_material(MaterialId(0)),
        ),
        Box::new(ByInstance {
            inner: Bvh::new(instances),
            first,
            count: palette.len() as u32,
        }),
    ];
    for (k, x) in [-4.0, 0.0, 4.0].into_iter().enumerate() {
        let ball = Sphere::new(DVec3::new(x, 0.8, 3.5), 0.8)
            .expect("a valid ball")
            .with_material(MaterialId(1 + (k as u32 % 2)));
        world.push(Box::new(
            Moving::new(ball, DVec3::new(0.0, 0.4 * (k as f64 + 1.0), 0.0))
                .expect("a finite motion"),
        ));
    }
    Scene {
        world,
        materials,
        lights: None,
        next_event: false,
        background: Background::Sky,
        camera: CameraSettings {
            width,
            height: width * 9 / 16,
            vfov: 35.0,
            lookfrom: DVec3::new(0.0, 9.0, 16.0),
            lookat: DVec3::new(0.0, 0.5, -8.0),
            vup: DVec3::Y,
            defocus_angle: 0.0,
            focus_dist: 10.0,
            shutter: true,
            mask: u32::MAX,
        },
    }
}

/// How the many-lights scene's renderer picks a light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pick {
    /// Every light equally often (a list of lights, as the other scenes have).
    Uniform,
    /// In proportion to power: a `Mixture`.
    Power,
    /// By importance from the shading point and normal: a `LightTree`.
    Tree,
}

/// A long hall lit by many small lamps of varied power: `rows` rows of four ceiling panels
/// facing down and a triangular sconce on each wall facing in, 20 cm to 30 cm across, of
/// radiances over two decades (a fixed seed: the same scene every run); grey walls, a
/// darker floor, the camera at one end looking down the hall. From any point most lamps
/// are far: a uniform or power-weighted choice wastes most of its samples on them.
pub fn hall_scene(
    width: usize,
    rows: usize,
    pick: Pick,
) -> Scene<hitkit::Bvh<Box<dyn hitkit::Hittable>>> {
    use hitkit::{Emission, Hittable, LightTree, Mixture, PdfHittable, Triangle};
    let length = 0.6 * rows as f64 + 1.0;
    let (wall, floor) = (MaterialId(0), MaterialId(1));
    let mut materials = vec![
        Material::Lambertian(Color::splat(0.7)),
        Material::Lambertian(Color::splat(0.35)),
    ];
    let quad = |q: DVec3, u: DVec3, v: DVec3, m: MaterialId| {
        Quad::new(q, u, v)
            .expect("the hall's quads are valid")
            .with_material(m)
    };
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let mut world: Vec<Box<dyn Hittable>> = vec![
        Box::new(quad(
            DVec3::new(-3.0, 0.0, 1.0),
            6.0 * x,
            -length * z,
            floor,
        )),
        Box::new(quad(DVec3::new(-3.0, 4.0, 1.0), -length * z, 6.0 * x, wall)),
        Box::new(quad(DVec3::new(-3.0, 0.0, 1.0), 4.0 * y, -length * z, wall)),
        Box::new(quad(DVec3::new(3.0, 0.0, 1.0), -length * z, 4.0 * y, wall)),
        Box::new(quad(
            DVec3::new(-3.0, 0.0, 1.0 - length),
            6.0 * x,
            4.0 * y,
            wall,
        )),
        Box::new(quad(DVec3::new(-3.0, 0.0, 1.0), 4.0 * y, 6.0 * x, wall)),
    ];
    let mut rng = {
        use rand::SeedableRng;
        rand::rngs::SmallRng::seed_from_u64(0x6861_6c6c)
    };
    let mut next = move || rand::RngExt::random::<f64>(&mut rng);
    let (mut lights, mut powers, mut emission): (
        Vec<Box<dyn PdfHittable>>,
        Vec<f64>,
        Vec<Emission>,
    ) = (Vec::new(), Vec::new(), Vec::new());
    let lamp = |materials: &mut Vec<Material>, radiance: Color| {
        materials.push(Material::Light(radiance));
        MaterialId(materials.len() as u32 - 1)
    };
    for row in 0..rows {
        let at = -0.6 * row as f64 - 0.3;
        for column in 0..4 {
            // Radiance log-uniform over two decades, a warm or a cool tint.
            let radiance = 0.3
                * 10f64.powf(2.0 * next())
                * if next() < 0.5 {
                    Color::new(1.0, 0.8, 0.6)
                } else {
                    Color::new(0.7, 0.8, 1.0)
                };
            let size = 0.2 + 0.1 * next();
            let m = lamp(&mut materials, radiance);
            let corner = DVec3::new(
                -2.25 + 1.5 * column as f64 - 0.5 * size,
                3.99,
                at - 0.5 * size,
            );
            // Facing down: `x cross z` is `-y`.
            let panel = quad(corner, size * x, size * z, m);
            powers.push(std::f64::consts::PI * crate::render::luminance(radiance) * panel.area());
            emission.push(Emission::OneSide(-y));
            world.push(Box::new(panel));
            lights.push(Box::new(panel));
        }
        // A sconce on each wall every fourth row, facing into the hall.
        if row % 4 == 0 {
            for side in [-1.0, 1.0] {
                let radiance = Color::splat(0.3 * 10f64.powf(0.5 + 1.5 * next()));
                let m = lamp(&mut materials, radiance);
                let (u, v) = if side < 0.0 {
                    (0.3 * y, 0.3 * z)
                } else {
                    (0.3 * z, 0.3 * y)
                };
                let corner = DVec3::new(2.99 * side, 2.0, at);
                let sconce = Quad::with_interior(corner, u, v, Triangle)
                    .expect("the sconces are valid")
                    .with_material(m);
                powers.push(
                    std::f64::consts::PI * crate::render::luminance(radiance) * sconce.area(),
                );
                emission.push(Emission::OneSide(u.cross(v)));
                world.push(Box::new(sconce));
                lights.push(Box::new(sconce));
            }
        }
    }
    let lights: Box<dyn hitkit::PdfHittable> = match pick {
        Pick::Uniform => Box::new(lights),
        Pick::Power => Box::new(Mixture::new(lights, &powers).expect("positive powers")),
        Pick::Tree => {
            Box::new(LightTree::new(lights, &powers, &emission).expect("valid lights and powers"))
        }
    };
    let height = (width * 9 / 16).max(1);
    Scene {
        world: hitkit::Bvh::new(world),
        materials,
        lights: Some(lights),
        next_event: true,
        background: Background::Solid(Color::ZERO),
        camera: CameraSettings {
            width,
            height,
            vfov: 60.0,
            lookfrom: DVec3::new(0.0, 1.7, 0.5),
            lookat: DVec3::new(0.0, 1.5, -20.0),
            vup: DVec3::Y,
            defocus_angle: 0.0,
            focus_dist: 10.0,
            shutter: false,
            mask: u32::MAX,
        },
    }
}

/// [`cornell_scene`] (its lamp sampled by area) with its one light picked as `pick` says:
/// what the many-lights comparison checks a light tree costs nothing where one light is all.
pub fn cornell_pick(width: usize, pick: Pick) -> Scene<Vec<Box<dyn hitkit::Hittable>>> {
    use hitkit::{Emission, LightTree, Mixture};
    let mut scene = cornell_scene(width, hitkit::Sampling::Area);
    let lamp = cornell_walls().2.with_sampling(hitkit::Sampling::Area);
    let lights = vec![lamp];
    scene.lights = Some(match pick {
        Pick::Uniform => Box::new(lights),
        Pick::Power => Box::new(Mixture::new(lights, &[1.0]).expect("one light")),
        // The book's lamp faces down.
        Pick::Tree => Box::new(
            LightTree::new(lights, &[1.0], &[Emission::OneSide(-DVec3::Y)]).expect("one light"),
        ),
    });
    // As the hall is rendered, so that the comparison weighs the picks alone.
    scene.next_event = true;
    scene
}
