//! The examples' scenes, here so that tests and benches render exactly what the examples do.

use hitkit::glam::DVec3;
use hitkit::{MaterialId, Quad};

use super::{Background, CameraSettings, Color, Material, Scene};

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
        lights: Vec::new(),
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
        lights: Vec::new(),
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
        lights,
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
        lights,
        background: Background::Solid(Color::ZERO),
        camera: cornell_camera(width),
    }
}
