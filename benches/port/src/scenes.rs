//! The three scenes, described once as data and built twice: on the book's own geometry
//! ([`naive`](crate::naive)) and on hitkit, each the way a port of the book writes it
//! (`Box<dyn Hittable>` lists and nested trees, materials by id).

use hitkit::glam::{DQuat, DVec3};
use hitkit::{
    Bvh, Cuboid, Hittable, MaterialId, Moving, PdfHittable, Quad, Ray, Sampling, Sphere,
    Transformed,
};

use crate::naive;
use hitkit_render::medium::{ConstantMedium, hash_uniform};

/// Linear RGB.
pub type Color = DVec3;

#[derive(Clone, Copy)]
pub enum Material {
    Lambertian(Color),
    Metal(Color, f64),
    Dielectric(f64),
    Light(Color),
    Isotropic(Color),
}

/// The book's camera, without defocus.
pub struct Camera {
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    w: DVec3,
    half: f64,
}

impl Camera {
    pub fn new(from: DVec3, at: DVec3, vfov: f64) -> Self {
        let w = (from - at).normalize();
        let u = DVec3::Y.cross(w).normalize();
        Self {
            origin: from,
            u,
            v: w.cross(u),
            w,
            half: (vfov.to_radians() / 2.0).tan(),
        }
    }

    /// The ray through `(x, y)` of the square image, both in `[0, 1]`, y down.
    pub fn ray(&self, x: f64, y: f64, time: f64) -> Ray {
        let d =
            (2.0 * x - 1.0) * self.half * self.u + (1.0 - 2.0 * y) * self.half * self.v - self.w;
        Ray::new(self.origin, d).at_time(time)
    }
}

/// A shape of a scene, as the book's code builds it.
pub enum Shape {
    Sphere(DVec3, f64, u32),
    Moving(DVec3, DVec3, f64, u32),
    Quad(DVec3, DVec3, DVec3, u32),
    Cuboid(DVec3, DVec3, u32),
    Medium(Box<Shape>, f64, u32),
    /// A BVH of the shapes.
    Tree(Vec<Shape>),
    /// Turned about y by some degrees, then moved.
    Turned(Box<Shape>, f64, DVec3),
}

pub struct Scene {
    pub name: &'static str,
    pub world: Vec<Shape>,
    /// Sampled for next-event estimation (the book's third volume), where not empty.
    pub lights: Vec<Shape>,
    pub materials: Vec<Material>,
    /// What a ray that hits nothing sees.
    pub background: DVec3,
    /// hitkit samples its quad lights by area, as the book does (by default it samples a
    /// rectangle by the solid angle it subtends: dearer per sample, less noisy).
    pub area_lights: bool,
    pub camera: Camera,
    pub width: usize,
    pub samples: usize,
    pub depth: u32,
}

fn id(m: u32) -> MaterialId {
    MaterialId(m)
}

/// The book's geometry.
pub fn naive(shape: &Shape) -> Box<dyn naive::Hittable> {
    match *shape {
        Shape::Sphere(c, r, m) => Box::new(naive::Sphere::new(c, r, id(m))),
        Shape::Moving(a, b, r, m) => Box::new(naive::Sphere::moving(a, b, r, id(m))),
        Shape::Quad(q, u, v, m) => Box::new(naive::Quad::new(q, u, v, id(m))),
        Shape::Cuboid(a, b, m) => Box::new(naive::cuboid(a, b, id(m))),
        Shape::Medium(ref boundary, density, m) => Box::new(naive::Medium::new(
            naive(boundary),
            density,
            id(m),
            hash_uniform,
        )),
        Shape::Tree(ref shapes) => {
            Box::new(naive::BvhNode::new(shapes.iter().map(naive).collect()))
        }
        Shape::Turned(ref shape, degrees, offset) => Box::new(naive::Translate::new(
            Box::new(naive::RotateY::new(naive(shape), degrees)),
            offset,
        )),
    }
}

/// hitkit's.
pub fn hitkit(shape: &Shape) -> Box<dyn Hittable> {
    match *shape {
        Shape::Sphere(c, r, m) => Box::new(Sphere::new(c, r).unwrap().with_material(id(m))),
        Shape::Moving(a, b, r, m) => {
            Box::new(Moving::new(Sphere::new(a, r).unwrap().with_material(id(m)), b - a).unwrap())
        }
        Shape::Quad(q, u, v, m) => Box::new(Quad::new(q, u, v).unwrap().with_material(id(m))),
        Shape::Cuboid(a, b, m) => Box::new(Cuboid::new(a, b).unwrap().with_material(id(m))),
        Shape::Medium(ref boundary, density, m) => Box::new(ConstantMedium::new(
            hitkit(boundary),
            density,
            id(m),
            hash_uniform,
        )),
        Shape::Tree(ref shapes) => Box::new(Bvh::new(shapes.iter().map(hitkit).collect())),
        Shape::Turned(ref shape, degrees, offset) => Box::new(
            Transformed::new(
                hitkit(shape),
                DQuat::from_rotation_y(degrees.to_radians()),
                offset,
            )
            .unwrap(),
        ),
    }
}

/// hitkit's lights: quads and spheres.
pub fn hitkit_light(shape: &Shape, area: bool) -> Box<dyn PdfHittable> {
    let sampling = if area {
        Sampling::Area
    } else {
        Sampling::SolidAngle
    };
    match *shape {
        Shape::Sphere(c, r, m) => Box::new(Sphere::new(c, r).unwrap().with_material(id(m))),
        Shape::Quad(q, u, v, m) => Box::new(
            Quad::new(q, u, v)
                .unwrap()
                .with_material(id(m))
                .with_sampling(sampling),
        ),
        _ => panic!("only quads and spheres are sampled"),
    }
}

/// A stream of numbers in `[0, 1)` for the scenes' random layout (the same on both sides).
struct Layout(u64);

impl Layout {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// *The Next Week*'s final scene: a floor of 400 boxes in a BVH, a lamp, a moving sphere,
/// glass, metal, a glass ball of fog and a thin mist over everything, the textured and the
/// noise spheres as plain colours, and 1,000 small spheres in a BVH, turned and moved; the
/// whole in a BVH.
pub fn final_scene(width: usize, samples: usize) -> Scene {
    use Material::*;
    let materials = vec![
        Lambertian(DVec3::new(0.48, 0.83, 0.53)), // 0 ground
        Light(DVec3::splat(7.0)),                 // 1
        Lambertian(DVec3::new(0.7, 0.3, 0.1)),    // 2
        Dielectric(1.5),                          // 3
        Metal(DVec3::new(0.8, 0.8, 0.9), 1.0),    // 4
        Isotropic(DVec3::new(0.2, 0.4, 0.9)),     // 5
        Isotropic(DVec3::ONE),                    // 6
        Lambertian(DVec3::new(0.3, 0.4, 0.8)),    // 7 earth, as a colour
        Lambertian(DVec3::splat(0.6)),            // 8 noise, as a colour
        Lambertian(DVec3::splat(0.73)),           // 9 white
    ];
    let mut rng = Layout(1);
    let mut boxes = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let (x0, z0) = (
                -1000.0 + 100.0 * f64::from(i),
                -1000.0 + 100.0 * f64::from(j),
            );
            let y1 = 1.0 + 100.0 * rng.next();
            boxes.push(Shape::Cuboid(
                DVec3::new(x0, 0.0, z0),
                DVec3::new(x0 + 100.0, y1, z0 + 100.0),
                0,
            ));
        }
    }
    let small: Vec<Shape> = (0..1000)
        .map(|_| {
            Shape::Sphere(
                DVec3::new(rng.next(), rng.next(), rng.next()) * 165.0,
                10.0,
                9,
            )
        })
        .collect();
    let glass_ball = || Shape::Sphere(DVec3::new(360.0, 150.0, 145.0), 70.0, 3);
    // The world in a BVH of its own, as the ports put it (`bvh_node(world)`), over the
    // floor's BVH and the turned BVH of small spheres.
    let world = vec![
        Shape::Tree(boxes),
        Shape::Quad(
            DVec3::new(123.0, 554.0, 147.0),
            DVec3::new(300.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 265.0),
            1,
        ),
        Shape::Moving(
            DVec3::new(400.0, 400.0, 200.0),
            DVec3::new(430.0, 400.0, 200.0),
            50.0,
            2,
        ),
        Shape::Sphere(DVec3::new(260.0, 150.0, 45.0), 50.0, 3),
        Shape::Sphere(DVec3::new(0.0, 150.0, 145.0), 50.0, 4),
        glass_ball(),
        Shape::Medium(Box::new(glass_ball()), 0.2, 5),
        Shape::Medium(Box::new(Shape::Sphere(DVec3::ZERO, 5000.0, 3)), 0.0001, 6),
        Shape::Sphere(DVec3::new(400.0, 200.0, 400.0), 100.0, 7),
        Shape::Sphere(DVec3::new(220.0, 280.0, 300.0), 80.0, 8),
        Shape::Turned(
            Box::new(Shape::Tree(small)),
            15.0,
            DVec3::new(-100.0, 270.0, 395.0),
        ),
    ];
    Scene {
        name: "The Next Week's final scene",
        world: vec![Shape::Tree(world)],
        lights: Vec::new(),
        materials,
        background: DVec3::ZERO,
        area_lights: false,
        camera: Camera::new(
            DVec3::new(478.0, 278.0, -600.0),
            DVec3::new(278.0, 278.0, 0.0),
            40.0,
        ),
        width,
        samples,
        depth: 40,
    }
}

/// *The Rest of Your Life*'s Cornell box: a turned box and a glass sphere, the lamp and the
/// sphere sampled as lights (the lamp by area where `area_lights`, as the book does).
pub fn cornell(width: usize, samples: usize, area_lights: bool) -> Scene {
    use Material::*;
    let materials = vec![
        Lambertian(DVec3::new(0.65, 0.05, 0.05)), // 0 red
        Lambertian(DVec3::splat(0.73)),           // 1 white
        Lambertian(DVec3::new(0.12, 0.45, 0.15)), // 2 green
        Light(DVec3::splat(15.0)),                // 3
        Dielectric(1.5),                          // 4
    ];
    let v = |x, y, z| DVec3::new(x, y, z);
    let lamp = |m| {
        Shape::Quad(
            v(343.0, 554.0, 332.0),
            v(-130.0, 0.0, 0.0),
            v(0.0, 0.0, -105.0),
            m,
        )
    };
    let ball = |m| Shape::Sphere(v(190.0, 90.0, 190.0), 90.0, m);
    let world = vec![
        Shape::Quad(
            v(555.0, 0.0, 0.0),
            v(0.0, 555.0, 0.0),
            v(0.0, 0.0, 555.0),
            2,
        ),
        Shape::Quad(v(0.0, 0.0, 0.0), v(0.0, 555.0, 0.0), v(0.0, 0.0, 555.0), 0),
        lamp(3),
        Shape::Quad(
            v(555.0, 555.0, 555.0),
            v(-555.0, 0.0, 0.0),
            v(0.0, 0.0, -555.0),
            1,
        ),
        Shape::Quad(v(0.0, 0.0, 0.0), v(555.0, 0.0, 0.0), v(0.0, 0.0, 555.0), 1),
        Shape::Quad(
            v(0.0, 0.0, 555.0),
            v(555.0, 0.0, 0.0),
            v(0.0, 555.0, 0.0),
            1,
        ),
        Shape::Turned(
            Box::new(Shape::Cuboid(DVec3::ZERO, v(165.0, 330.0, 165.0), 1)),
            15.0,
            v(265.0, 0.0, 295.0),
        ),
        ball(4),
    ];
    Scene {
        name: if area_lights {
            "The Rest of Your Life's Cornell box, lamp sampled by area"
        } else {
            "The Rest of Your Life's Cornell box"
        },
        world,
        lights: vec![lamp(3), ball(4)],
        materials,
        background: DVec3::ZERO,
        area_lights,
        camera: Camera::new(v(278.0, 278.0, -800.0), v(278.0, 278.0, 0.0), 40.0),
        width,
        samples,
        depth: 50,
    }
}

/// *The Next Week*'s quads: five quads of five colours around the camera, under a sky.
pub fn quads(width: usize, samples: usize) -> Scene {
    use Material::*;
    let v = |x, y, z| DVec3::new(x, y, z);
    let materials = vec![
        Lambertian(v(1.0, 0.2, 0.2)), // 0 left red
        Lambertian(v(0.2, 1.0, 0.2)), // 1 back green
        Lambertian(v(0.2, 0.2, 1.0)), // 2 right blue
        Lambertian(v(1.0, 0.5, 0.0)), // 3 upper orange
        Lambertian(v(0.2, 0.8, 0.8)), // 4 lower teal
    ];
    let world = vec![
        Shape::Quad(v(-3.0, -2.0, 5.0), v(0.0, 0.0, -4.0), v(0.0, 4.0, 0.0), 0),
        Shape::Quad(v(-2.0, -2.0, 0.0), v(4.0, 0.0, 0.0), v(0.0, 4.0, 0.0), 1),
        Shape::Quad(v(3.0, -2.0, 1.0), v(0.0, 0.0, 4.0), v(0.0, 4.0, 0.0), 2),
        Shape::Quad(v(-2.0, 3.0, 1.0), v(4.0, 0.0, 0.0), v(0.0, 0.0, 4.0), 3),
        Shape::Quad(v(-2.0, -3.0, 5.0), v(4.0, 0.0, 0.0), v(0.0, 0.0, -4.0), 4),
    ];
    Scene {
        name: "The Next Week's quads",
        world,
        lights: Vec::new(),
        materials,
        background: v(0.70, 0.80, 1.00),
        area_lights: false,
        camera: Camera::new(v(0.0, 0.0, 9.0), DVec3::ZERO, 80.0),
        width,
        samples,
        depth: 50,
    }
}
