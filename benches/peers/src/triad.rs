//! The triad: what a path tracer traces on scenes with structure. From a camera, primary
//! rays; from each primary hit, one cosine-weighted bounce (closest hit) and, where the hit
//! faces the scene's lamp, one shadow ray to a point drawn on it (any hit, `ray_t` ending
//! at the lamp). hitkit's `TriangleMesh` and `Bvh<Quad<Triangle>>` against obvhs's CWBVH,
//! one thread, every library timed on every ray set in turn within each run.

use std::hint::black_box;
use std::time::{Duration, Instant};

use hitkit::custom::Made;
use hitkit::glam::{DVec3, UVec2};
use hitkit::{
    Bvh, Candidate, Filtered, Hittable, Interval, Quad, Ray, Triangle, TriangleMesh, Visits,
};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::{build_cwbvh, build_cwbvh_from_tris};
use obvhs::ray::RayHit;

use crate::library::{Library, ftz_daz};
use crate::{Args, Hit, Scene, closer, f32_box, f32_up, quads};
use hitkit_render::workloads::{self, SplitMix};

/// A horizontal lamp facing down: a corner and two edges.
#[derive(Clone, Copy)]
struct Lamp {
    corner: DVec3,
    u: DVec3,
    v: DVec3,
}

/// A pinhole camera.
struct Camera {
    eye: DVec3,
    target: DVec3,
    /// Vertical field of view, degrees.
    fov: f64,
}

impl Camera {
    /// A `side` x `side` grid of rays through pixel centres.
    fn rays(&self, side: usize) -> Vec<Ray> {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(DVec3::Y).normalize();
        let up = right.cross(forward);
        let half = (self.fov.to_radians() / 2.0).tan();
        let mut rays = Vec::with_capacity(side * side);
        for j in 0..side {
            for i in 0..side {
                let x = (2.0 * (i as f64 + 0.5) / side as f64 - 1.0) * half;
                let y = (1.0 - 2.0 * (j as f64 + 0.5) / side as f64) * half;
                rays.push(Ray::new(self.eye, forward + x * right + y * up));
            }
        }
        rays
    }
}

/// A scene of the triad: the mesh, where the camera is and the lamp.
pub struct TriadScene {
    scene: Scene,
    camera: Camera,
    lamp: Lamp,
}

/// Vertices and faces, vertices shared where quads meet at a corner.
#[derive(Default)]
struct Builder {
    vertices: Vec<DVec3>,
    faces: Vec<[u32; 3]>,
    index: std::collections::HashMap<[u64; 3], u32>,
}

impl Builder {
    fn vertex(&mut self, p: DVec3) -> u32 {
        let next = self.vertices.len() as u32;
        let key = p.to_array().map(f64::to_bits);
        *self.index.entry(key).or_insert_with(|| {
            self.vertices.push(p);
            next
        })
    }

    /// The parallelogram `q`, `q + u`, `q + u + v`, `q + v` as two triangles.
    fn quad(&mut self, q: DVec3, u: DVec3, v: DVec3) {
        let [a, b, c, d] = [q, q + u, q + u + v, q + v].map(|p| self.vertex(p));
        self.faces.push([a, b, c]);
        self.faces.push([a, c, d]);
    }

    /// The book's `box(a, b)` turned by `degrees` about `y` (as its `rotate_y`) and moved
    /// by `offset`: eight shared corners, twelve faces.
    fn cuboid(&mut self, size: DVec3, degrees: f64, offset: DVec3) {
        let (sin, cos) = degrees.to_radians().sin_cos();
        let place =
            |p: DVec3| DVec3::new(cos * p.x + sin * p.z, p.y, -sin * p.x + cos * p.z) + offset;
        let ids: Vec<u32> = (0..8)
            .map(|i| self.vertex(place(workloads::cube_corner(i) * size)))
            .collect();
        self.faces.extend(
            hitkit_render::workloads::cube_faces()
                .iter()
                .map(|f| f.map(|i| ids[i as usize])),
        );
    }

    fn finish(self, name: &str) -> Scene {
        Scene {
            name: name.to_owned(),
            vertices: self.vertices,
            faces: self.faces,
        }
    }
}

/// The book's Cornell box ("The Next Week", final scene of chapter 9): five walls and two
/// turned boxes as one mesh, its camera; its lamp a light apart from the mesh. With
/// `skylight`, the lamp is moved above a hole in the ceiling (the ceiling four quads around
/// it), so that most shadow rays from the room are stopped by the ceiling or a wall (the
/// case of a renderer's rooms, where most lights are out of sight), and the rest pass
/// through the hole.
fn cornell(skylight: bool) -> TriadScene {
    let mut b = Builder::default();
    let (x, y, z) = (DVec3::X * 555.0, DVec3::Y * 555.0, DVec3::Z * 555.0);
    b.quad(x, y, z);
    b.quad(DVec3::ZERO, y, z);
    b.quad(DVec3::ZERO, x, z);
    if skylight {
        b.quad(z, x, y);
        // The ceiling at y = 555 around the hole x in [213, 343], z in [227, 332].
        let at = |px: f64, pz: f64| DVec3::new(px, 555.0, pz);
        let (x0, x1, z0, z1) = (213.0, 343.0, 227.0, 332.0);
        b.quad(at(0.0, 0.0), DVec3::X * x0, DVec3::Z * 555.0);
        b.quad(at(x1, 0.0), DVec3::X * (555.0 - x1), DVec3::Z * 555.0);
        b.quad(at(x0, 0.0), DVec3::X * (x1 - x0), DVec3::Z * z0);
        b.quad(at(x0, z1), DVec3::X * (x1 - x0), DVec3::Z * (555.0 - z1));
    } else {
        b.quad(DVec3::splat(555.0), -x, -z);
        b.quad(z, x, y);
    }
    b.cuboid(
        DVec3::new(165.0, 330.0, 165.0),
        15.0,
        DVec3::new(265.0, 0.0, 295.0),
    );
    b.cuboid(DVec3::splat(165.0), -18.0, DVec3::new(130.0, 0.0, 65.0));
    TriadScene {
        scene: b.finish(if skylight {
            "Cornell box, lamp above a skylight"
        } else {
            "Cornell box"
        }),
        camera: Camera {
            eye: DVec3::new(278.0, 278.0, -800.0),
            target: DVec3::new(278.0, 278.0, 0.0),
            fov: 40.0,
        },
        lamp: Lamp {
            corner: DVec3::new(343.0, if skylight { 755.0 } else { 554.0 }, 332.0),
            u: DVec3::new(-130.0, 0.0, 0.0),
            v: DVec3::new(0.0, 0.0, -105.0),
        },
    }
}

/// A lamp over the box `(lo, hi)`, half its height above it, `fraction` of its width.
fn lamp_over((lo, hi): (DVec3, DVec3), fraction: f64) -> Lamp {
    let size = hi - lo;
    let side = fraction * size.x.max(size.z);
    let centre = 0.5 * (lo + hi);
    Lamp {
        corner: DVec3::new(
            centre.x - side / 2.0,
            hi.y + size.y / 2.0,
            centre.z - side / 2.0,
        ),
        u: DVec3::X * side,
        v: DVec3::Z * side,
    }
}

/// The model alone, from the peers table's camera (`workloads::camera_rays`), a lamp above.
fn model(model: &Scene) -> TriadScene {
    let bounds = hitkit_render::workloads::bounds(&model.tris());
    let (lo, hi) = bounds;
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    let eye = centre + DVec3::new(0.3, 0.4, 1.0).normalize() * radius * 2.5;
    TriadScene {
        scene: Scene {
            name: model.name.clone(),
            vertices: model.vertices.clone(),
            faces: model.faces.clone(),
        },
        // The field of view that just fits the bounding sphere, as `workloads::camera_rays`.
        camera: Camera {
            eye,
            target: centre,
            fov: 2.0 * (radius / (eye - centre).length()).asin().to_degrees(),
        },
        lamp: lamp_over(bounds, 0.5),
    }
}

/// `copies` copies of `model`, each turned about the vertical by the golden angle from the
/// last, on a square grid on a floor, flattened into one mesh; a camera above the front,
/// and a lamp over the middle.
fn crowd(model: &Scene, copies: usize) -> TriadScene {
    let (lo, hi) = hitkit_render::workloads::bounds(&model.tris());
    let size = hi - lo;
    let centre = 0.5 * (lo + hi);
    let spacing = 1.2 * size.x.max(size.z);
    let columns = (copies as f64).sqrt().ceil() as usize;
    let mut b = Builder::default();
    for copy in 0..copies {
        let (sin, cos) = (copy as f64 * 2.399_963).sin_cos();
        let offset = DVec3::new(
            (copy % columns) as f64 * spacing,
            0.0,
            (copy / columns) as f64 * spacing,
        );
        let base = b.vertices.len() as u32;
        b.vertices.extend(model.vertices.iter().map(|&p| {
            let r = p - centre;
            DVec3::new(cos * r.x + sin * r.z, r.y, -sin * r.x + cos * r.z) + centre + offset
        }));
        b.faces
            .extend(model.faces.iter().map(|f| f.map(|i| i + base)));
    }
    let rows = copies.div_ceil(columns);
    let extent = DVec3::new(columns as f64 * spacing, 0.0, rows as f64 * spacing);
    let floor = DVec3::new(centre.x - spacing, lo.y, centre.z - spacing);
    b.quad(
        floor,
        DVec3::Z * (extent.z + spacing),
        DVec3::X * (extent.x + spacing),
    );
    let middle = floor + 0.5 * DVec3::new(extent.x + spacing, 0.0, extent.z + spacing);
    let reach = 0.5 * extent.x.max(extent.z);
    let scene = b.finish(&format!("crowd of {copies} {}", model.name));
    let bounds = hitkit_render::workloads::bounds(&scene.tris());
    TriadScene {
        scene,
        camera: Camera {
            eye: middle + DVec3::new(0.0, 1.2, 1.6) * reach,
            target: middle,
            fov: 50.0,
        },
        lamp: lamp_over(bounds, 0.3),
    }
}

/// The closed sphere seen from inside, a lamp under its top: every bounce stays in it,
/// and no shadow ray is blocked (the sphere is convex), so each must prove that.
fn inside_sphere(levels: u32) -> TriadScene {
    let (vertices, faces) = hitkit_render::workloads::icosphere(levels);
    TriadScene {
        scene: Scene {
            name: format!("inside closed sphere {}", faces.len()),
            vertices,
            faces,
        },
        camera: Camera {
            eye: DVec3::new(0.0, -0.2, 0.5),
            target: DVec3::new(0.0, -0.4, -1.0),
            fov: 70.0,
        },
        lamp: Lamp {
            corner: DVec3::new(-0.2, 0.7, -0.2),
            u: DVec3::X * 0.4,
            v: DVec3::Z * 0.4,
        },
    }
}

/// The triad's scenes: the model (if it loaded), the Cornell box (its lamp inside, and
/// above a skylight), the crowd of copies of the model, the closed sphere from inside.
pub fn scenes(model_scene: Option<&Scene>, args: &Args) -> Vec<TriadScene> {
    let mut scenes = Vec::new();
    if let Some(m) = model_scene {
        scenes.push(model(m));
    }
    scenes.push(cornell(false));
    scenes.push(cornell(true));
    if let Some(m) = model_scene.filter(|_| args.crowd > 0) {
        scenes.push(crowd(m, args.crowd));
    }
    if args.sphere > 0 {
        scenes.push(inside_sphere(args.sphere));
    }
    if let Some(only) = &args.scene {
        scenes.retain(|s| s.scene.name.contains(only.as_str()));
    }
    scenes
}

/// The three ray sets of a scene, made from hitkit's hits: shadow rays end at the lamp
/// (`t = 1`).
struct Rays {
    primary: Vec<Ray>,
    bounce: Vec<Ray>,
    shadow: Vec<Ray>,
}

fn make_rays(ts: &TriadScene, mesh: &TriangleMesh, side: usize, seed: u64) -> Rays {
    let primary = ts.camera.rays(side);
    let mut rng = SplitMix::new(seed);
    let (mut bounce, mut shadow) = (Vec::new(), Vec::new());
    let lamp = ts.lamp;
    let lamp_normal = lamp.u.cross(lamp.v);
    for ray in &primary {
        let Some(hit) = mesh.hit(ray, Interval::FORWARD) else {
            continue;
        };
        // The normal on the side the ray came from.
        let n = if hit.normal.dot(ray.direction) < 0.0 {
            hit.normal
        } else {
            -hit.normal
        };
        let cosine = n + rng.direction();
        if cosine.length_squared() > 1e-12 {
            bounce.push(hit.spawn_ray(cosine));
        }
        let q = lamp.corner + rng.next_f64() * lamp.u + rng.next_f64() * lamp.v;
        let to = q - hit.point;
        // Faces the lamp, and the lamp's lit side (down) faces it.
        let down = if lamp_normal.y < 0.0 {
            lamp_normal
        } else {
            -lamp_normal
        };
        if to.dot(n) > 0.0 && to.dot(down) < 0.0 {
            shadow.push(hit.spawn_ray(to));
        }
    }
    Rays {
        primary,
        bounce,
        shadow,
    }
}

/// Where a shadow ray ends: at the lamp.
const SHADOW: Interval = Interval::new(0.0, 1.0);

struct Mesh<'a>(TriangleMesh, &'a [usize]);

/// A mesh's closest hit as the scene numbers its faces (`position`), and its `t`.
fn face_hit(mesh: &impl Hittable, position: &[usize], ray: &Ray) -> Hit {
    mesh.hit(ray, Interval::FORWARD)
        .map(|h| (position[h.primitive.expect("a face") as usize], h.t))
}

impl Library for Mesh<'_> {
    fn name(&self) -> String {
        "hitkit TriangleMesh".into()
    }
    fn closest(&self, ray: &Ray) -> Hit {
        face_hit(&self.0, self.1, ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.0.occluded(ray, SHADOW)
    }
    fn count(&self, ray: &Ray, any: bool) -> Option<(u32, u32)> {
        let Visits { nodes, tests } = if any {
            self.0.occluded_visits(ray, SHADOW)
        } else {
            self.0.hit_visits(ray, Interval::FORWARD)
        };
        Some((nodes, tests))
    }
}

/// The mesh's closest hits by `find` alone: `t`, the face (by its place in the mesh's
/// order) and its barycentrics, no record; what obvhs's rows return. Its answers are the
/// `hit` row's, numbered otherwise, so they are not compared.
struct MeshFind(TriangleMesh);

impl Library for MeshFind {
    fn name(&self) -> String {
        "hitkit TriangleMesh, find (no record)".into()
    }
    fn closest(&self, ray: &Ray) -> Hit {
        self.0
            .find(ray, Interval::FORWARD, &mut Made::new())
            .map(|found| (found.part as usize, found.t))
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.0.occluded(ray, SHADOW)
    }
    fn count(&self, _: &Ray, _: bool) -> Option<(u32, u32)> {
        None
    }
    fn checked(&self) -> bool {
        false
    }
}

/// The mesh behind a filter that rejects nothing (`Filtered`), though it reads each
/// candidate's texture coordinates as a cut-out does: what asking it costs, where nothing
/// is cut.
struct MeshFiltered<'a, F>(Filtered<TriangleMesh, F>, &'a [usize]);

impl<F: Fn(&Candidate) -> bool + Send + Sync> Library for MeshFiltered<'_, F> {
    fn name(&self) -> String {
        "hitkit TriangleMesh, Filtered (rejecting nothing)".into()
    }
    fn closest(&self, ray: &Ray) -> Hit {
        face_hit(&self.0, self.1, ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.0.occluded(ray, SHADOW)
    }
    fn count(&self, _: &Ray, _: bool) -> Option<(u32, u32)> {
        None
    }
}

struct Generic(Bvh<Quad<Triangle>>);

impl Library for Generic {
    fn name(&self) -> String {
        "hitkit Bvh<Quad<Triangle>>".into()
    }
    fn closest(&self, ray: &Ray) -> Hit {
        self.0
            .hit_with_index(ray, Interval::FORWARD)
            .map(|(i, h)| (i, h.t))
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.0.occluded(ray, SHADOW)
    }
    fn count(&self, ray: &Ray, any: bool) -> Option<(u32, u32)> {
        let Visits { nodes, tests } = if any {
            self.0.occluded_visits(ray, SHADOW)
        } else {
            self.0.hit_visits(ray, Interval::FORWARD)
        };
        Some((nodes, tests))
    }
}

/// obvhs's ray, starting at `t = 1e-4`: its node test starts there whatever `tmin` (see
/// `run_obvhs`), and its triangle test needs a start past zero not to find the surface a
/// bounce or shadow ray leaves (it has no `spawn_ray`), as a renderer on it would set.
fn obvhs_ray(ray: &Ray, t_max: f32) -> obvhs::ray::Ray {
    obvhs::ray::Ray::new(
        ray.origin.as_vec3a(),
        ray.direction.as_vec3a(),
        OBVHS_T_MIN,
        t_max,
    )
}

/// obvhs's own start (`cwbvh::node::EPSILON`).
pub(crate) const OBVHS_T_MIN: f32 = 1e-4;

/// obvhs's node visits and leaf tests for one ray, through its exported traversal macro
/// (the loop its own `ray_traverse` and `ray_traverse_miss` run): `leaf` returns the
/// crossing's `t` (`inf` for none); with `any`, the walk stops at the first crossing
/// before `tmax`, otherwise it lowers `tmax` to each crossing found.
fn obvhs_count(
    tree: &CwBvh,
    ray: obvhs::ray::Ray,
    any: bool,
    mut leaf: impl FnMut(&obvhs::ray::Ray, usize) -> f32,
) -> (u32, u32) {
    let (mut nodes, mut tests) = (0u32, 0u32);
    let mut traverse_ray = ray;
    let mut state = tree.new_traversal(ray.direction);
    let mut node;
    'outer: {
        obvhs::traverse!(
            tree,
            node,
            state,
            {
                nodes += 1;
                node.intersect_ray(&traverse_ray, state.oct_inv4)
            },
            {
                tests += 1;
                let t = leaf(&traverse_ray, state.primitive_id as usize);
                if t < traverse_ray.tmax {
                    if any {
                        break 'outer;
                    }
                    traverse_ray.tmax = t;
                }
            }
        );
    }
    (nodes, tests)
}

/// obvhs on its own f32 triangles (medium preset, Möller-Trumbore at the leaves):
/// `ray_traverse`, and `ray_traverse_miss` for shadow rays.
struct ObvhsOwn<'a> {
    tree: CwBvh,
    ordered: Vec<obvhs::triangle::Triangle>,
    position: &'a [usize],
}

impl Library for ObvhsOwn<'_> {
    fn name(&self) -> String {
        "obvhs 0.4 CWBVH medium, own f32 triangles".into()
    }
    fn closest(&self, ray: &Ray) -> Hit {
        let mut hit = RayHit::none();
        self.tree
            .ray_traverse(obvhs_ray(ray, f32::INFINITY), &mut hit, |r, id| {
                self.ordered[id].intersect(r)
            })
            .then(|| {
                let face = self.tree.primitive_indices[hit.primitive_id as usize] as usize;
                (self.position[face], f64::from(hit.t))
            })
    }
    fn occluded(&self, ray: &Ray) -> bool {
        !self
            .tree
            .ray_traverse_miss(obvhs_ray(ray, 1.0), |r, id| self.ordered[id].intersect(r))
    }
    fn count(&self, ray: &Ray, any: bool) -> Option<(u32, u32)> {
        let r = obvhs_ray(ray, if any { 1.0 } else { f32::INFINITY });
        Some(obvhs_count(&self.tree, r, any, |r, id| {
            self.ordered[id].intersect(r)
        }))
    }
}

/// obvhs's CWBVH (medium preset) on hitkit's boxes with hitkit's triangle test at the
/// leaves: the trees compared with the same leaf test.
struct ObvhsLeaf {
    tree: CwBvh,
    ordered: Vec<(usize, Quad<Triangle>)>,
}

impl Library for ObvhsLeaf {
    fn name(&self) -> String {
        "obvhs 0.4 CWBVH medium, hitkit's test".into()
    }
    fn closest(&self, ray: &Ray) -> Hit {
        let mut best = None;
        self.tree.ray_traverse(
            obvhs_ray(ray, f32::INFINITY),
            &mut RayHit::none(),
            |_, id| {
                let (index, quad) = &self.ordered[id];
                crate::closer(quad, *index, ray, &mut best).map_or(f32::INFINITY, f32_up)
            },
        );
        best
    }
    fn occluded(&self, ray: &Ray) -> bool {
        !self.tree.ray_traverse_miss(obvhs_ray(ray, 1.0), |_, id| {
            // 0 for an occluder (below `tmax` = 1), infinity for none.
            if self.ordered[id].1.occluded(ray, SHADOW) {
                0.0
            } else {
                f32::INFINITY
            }
        })
    }
    fn count(&self, ray: &Ray, any: bool) -> Option<(u32, u32)> {
        let r = obvhs_ray(ray, if any { 1.0 } else { f32::INFINITY });
        let mut best = None;
        Some(obvhs_count(&self.tree, r, any, |_, id| {
            let (index, quad) = &self.ordered[id];
            if any {
                if quad.occluded(ray, SHADOW) {
                    0.0
                } else {
                    f32::INFINITY
                }
            } else {
                closer(quad, *index, ray, &mut best).map_or(f32::INFINITY, f32_up)
            }
        }))
    }
}

/// The median of `times`.
fn median(times: &mut [Duration]) -> Duration {
    times.sort();
    times[times.len() / 2]
}

/// Answers of one library on the three sets.
struct Answers {
    primary: Vec<Hit>,
    bounce: Vec<Hit>,
    shadow: Vec<bool>,
}

fn answer(lib: &dyn Library, rays: &Rays) -> Answers {
    Answers {
        primary: rays.primary.iter().map(|r| lib.closest(r)).collect(),
        bounce: rays.bounce.iter().map(|r| lib.closest(r)).collect(),
        shadow: rays.shadow.iter().map(|r| lib.occluded(r)).collect(),
    }
}

/// The three sets' times for one library, one run.
fn time(lib: &dyn Library, rays: &Rays) -> [Duration; 3] {
    let closest = |set: &[Ray]| {
        let start = Instant::now();
        for r in set {
            black_box(lib.closest(black_box(r)));
        }
        start.elapsed()
    };
    let shadow = {
        let start = Instant::now();
        for r in &rays.shadow {
            black_box(lib.occluded(black_box(r)));
        }
        start.elapsed()
    };
    [closest(&rays.primary), closest(&rays.bounce), shadow]
}

/// Whether `--only` chooses `lib` (every library without it).
fn chosen(lib: &dyn Library, args: &Args) -> bool {
    args.only
        .as_ref()
        .is_none_or(|only| lib.name().contains(only.as_str()))
}

// The sets traced once each for an instruction counter, one function a set, so that
// callgrind's `--toggle-collect` counts each apart from the builds and from the others.
#[inline(never)]
fn count_primary(lib: &dyn Library, rays: &[Ray]) {
    closest_all(lib, rays, "primary");
}

#[inline(never)]
fn count_bounce(lib: &dyn Library, rays: &[Ray]) {
    closest_all(lib, rays, "bounce");
}

#[inline(never)]
fn count_miss(lib: &dyn Library, rays: &[Ray]) {
    closest_all(lib, rays, "miss");
}

#[inline(never)]
fn count_shadow(lib: &dyn Library, rays: &[Ray]) {
    rays.iter().for_each(|r| {
        black_box(lib.occluded(black_box(r)));
    });
}

/// Every ray's closest hit; `mark` keeps the compiler from merging the passes that call
/// this into one function.
#[inline(always)]
fn closest_all(lib: &dyn Library, rays: &[Ray], mark: &str) {
    black_box(mark);
    rays.iter().for_each(|r| {
        black_box(lib.closest(black_box(r)));
    });
}

/// FNV-1a over every answer, bit for bit: two builds that answer alike print the same.
fn digest(a: &Answers) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    for hit in a.primary.iter().chain(&a.bounce) {
        match hit {
            Some((face, t)) => {
                eat(*face as u64);
                eat(t.to_bits());
            }
            None => eat(u64::MAX),
        }
    }
    a.shadow.iter().for_each(|&o| eat(u64::from(o)));
    h
}

/// How many answers differ.
fn differ<T: PartialEq>(a: &[T], b: &[T]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// How closest hits `b` differ from `a` by face: the rays, how many of them one of the
/// two misses, and the largest relative difference of `t` where both hit.
fn faces_differ(a: &[Hit], b: &[Hit]) -> String {
    let (mut rays, mut missed, mut dt) = (0, 0, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        if x.map(|h| h.0) == y.map(|h| h.0) {
            continue;
        }
        rays += 1;
        match (x, y) {
            (Some((_, s)), Some((_, t))) => dt = dt.max((s - t).abs() / s.abs().max(t.abs())),
            _ => missed += 1,
        }
    }
    format!("{rays} (of which {missed} hit by one only; t differs by at most {dt:.1e} of itself)")
}

/// Runs the triad on every scene and prints its tables.
pub fn run(scenes: &[TriadScene], args: &Args) {
    let (mut speed, mut counts, mut sets, mut notes) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    #[allow(unused_mut)]
    let mut memory: Vec<String> = Vec::new();
    for ts in scenes {
        let scene = &ts.scene;
        let name = &scene.name;
        let position = scene.positions();
        let quads = quads(&scene.tris());
        eprintln!("{name}: {} triangles", quads.len());
        let mesh = TriangleMesh::new(&scene.vertices, &scene.faces).expect("a valid mesh");
        let rays = make_rays(ts, &mesh, args.side, args.seed.wrapping_add(2));
        let tris: Vec<obvhs::triangle::Triangle> = scene
            .faces
            .iter()
            .map(|&[a, b, c]| obvhs::triangle::Triangle {
                v0: scene.vertices[a as usize].as_vec3a(),
                v1: scene.vertices[b as usize].as_vec3a(),
                v2: scene.vertices[c as usize].as_vec3a(),
            })
            .collect();
        let own_tree = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let own = ObvhsOwn {
            ordered: own_tree
                .primitive_indices
                .iter()
                .map(|&i| tris[i as usize])
                .collect(),
            tree: own_tree,
            position: &position,
        };
        let boxes: Vec<_> = quads.iter().map(|q| f32_box(&q.bounding_box())).collect();
        let leaf_tree = build_cwbvh(
            &boxes,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let leaf = ObvhsLeaf {
            ordered: leaf_tree
                .primitive_indices
                .iter()
                .map(|&i| (i as usize, quads[i as usize]))
                .collect(),
            tree: leaf_tree,
        };
        #[cfg_attr(not(feature = "embree"), allow(unused_variables))]
        let mesh_bytes = mesh.heap_bytes();
        #[allow(unused_mut)]
        let mut libs: Vec<Box<dyn Library + '_>> = vec![
            Box::new(Mesh(mesh.clone(), &position)),
            Box::new(own),
            Box::new(Generic(Bvh::new(quads.clone()))),
            Box::new(leaf),
            Box::new(MeshFind(mesh.clone())),
        ];
        let mesh_box = mesh.bounding_box();
        let libs_mesh = mesh;
        // The ceiling, where it is built in (row 5).
        #[cfg(feature = "embree")]
        {
            let embree = crate::embree::Embree::new(&scene.vertices, &scene.faces, &position);
            let faces = quads.len() as f64;
            memory.push(format!(
                "| {name} | {mesh_bytes} | {} | {:.1} | {:.1} |",
                embree.bytes,
                mesh_bytes as f64 / faces,
                embree.bytes as f64 / faces,
            ));
            libs.push(Box::new(embree));
        }
        let embree_row = (libs.len() > 5).then_some(5);
        libs.push(Box::new(MeshFiltered(
            Filtered::new(libs_mesh, |c: &Candidate| black_box(c.uv()).x > f64::MIN),
            &position,
        )));
        if args.count {
            // The camera's rays turned around: from outside the scene, each misses the
            // tree's root box, so that what they cost is a query's fixed cost.
            let missing: Vec<Ray> = rays
                .primary
                .iter()
                .map(|r| Ray::new(r.origin, -r.direction))
                .filter(|r| !mesh_box.hit(r, Interval::FORWARD))
                .collect();
            // The library named exactly, where one is (the mesh's name is in two others').
            let exact = libs.iter().any(|lib| Some(lib.name()) == args.only);
            for lib in libs.iter().filter(|lib| {
                chosen(lib.as_ref(), args) && (!exact || Some(lib.name()) == args.only)
            }) {
                eprintln!(
                    "counting\t{name}\t{}\t{} {} {} {}",
                    lib.name(),
                    rays.primary.len(),
                    rays.bounce.len(),
                    rays.shadow.len(),
                    missing.len(),
                );
                count_primary(lib.as_ref(), &rays.primary);
                count_bounce(lib.as_ref(), &rays.bounce);
                count_shadow(lib.as_ref(), &rays.shadow);
                count_miss(lib.as_ref(), &missing);
            }
            continue;
        }
        // Answers first (untimed), against the mesh's; then FTZ/DAZ's effect on them.
        let reference = answer(libs[0].as_ref(), &rays);
        notes.push(format!(
            "{name}: digest of TriangleMesh's answers (face, bits of t, occlusion), to compare builds: {:016x}",
            digest(&reference)
        ));
        let hits = |a: &[Hit]| a.iter().flatten().count();
        sets.push(format!(
            "| {name} | {} | {} | {} ({} hit) | {} ({} hit) | {} ({} occluded) |",
            quads.len(),
            ts.scene.vertices.len(),
            rays.primary.len(),
            hits(&reference.primary),
            rays.bounce.len(),
            hits(&reference.bounce),
            rays.shadow.len(),
            reference.shadow.iter().filter(|&&o| o).count(),
        ));
        for lib in libs[1..].iter().filter(|lib| lib.checked()) {
            let a = answer(lib.as_ref(), &rays);
            let face = |r: &[Hit], a: &[Hit]| {
                r.iter()
                    .zip(a)
                    .filter(|(x, y)| x.map(|h| h.0) != y.map(|h| h.0))
                    .count()
            };
            let d = [
                face(&reference.primary, &a.primary),
                face(&reference.bounce, &a.bounce),
                differ(&reference.shadow, &a.shadow),
            ];
            if d != [0; 3] {
                notes.push(format!(
                    "{name}, {}: faces differ from TriangleMesh's on primary rays {}, bounce rays {}; {} shadow rays answer otherwise",
                    lib.name(),
                    faces_differ(&reference.primary, &a.primary),
                    faces_differ(&reference.bounce, &a.bounce),
                    d[2]
                ));
            }
        }
        if args.ftz {
            for lib in [&libs[0], &libs[2]] {
                let old = ftz_daz(true);
                let a = answer(lib.as_ref(), &rays);
                ftz_daz(old & 0x8040 != 0);
                let r = if std::ptr::eq(lib, &libs[0]) {
                    &reference
                } else {
                    &answer(lib.as_ref(), &rays)
                };
                notes.push(format!(
                    "{name}, {} with FTZ/DAZ on: answers differ on {} primary, {} bounce, {} shadow rays",
                    lib.name(),
                    differ(&r.primary, &a.primary),
                    differ(&r.bounce, &a.bounce),
                    differ(&r.shadow, &a.shadow),
                ));
            }
        }
        // Node visits and face tests per ray, in a pass of their own.
        for lib in libs
            .iter()
            .filter(|lib| lib.count(&rays.primary[0], false).is_some())
        {
            let per_ray = |set: &[Ray], any: bool| {
                let (n, t) = set.iter().fold((0u64, 0u64), |(n, t), r| {
                    let (a, b) = lib.count(r, any).unwrap_or((0, 0));
                    (n + u64::from(a), t + u64::from(b))
                });
                let len = set.len().max(1) as f64;
                format!("{:.1} | {:.2}", n as f64 / len, t as f64 / len)
            };
            counts.push(format!(
                "| {name} | {} | {} | {} | {} |",
                lib.name(),
                per_ray(&rays.primary, false),
                per_ray(&rays.bounce, false),
                per_ray(&rays.shadow, true),
            ));
        }
        // Timed: within each run, every library (and with --ftz, the hitkit ones again
        // with FTZ/DAZ on) on every set in turn.
        let variants: Vec<(usize, bool)> = (0..libs.len())
            .map(|i| (i, false))
            .chain(if args.ftz {
                vec![(0, true), (2, true)]
            } else {
                vec![]
            })
            .filter(|&(i, _)| chosen(libs[i].as_ref(), args))
            .collect();
        let mut times = vec![[Vec::new(), Vec::new(), Vec::new()]; variants.len()];
        for _ in 0..args.runs {
            for (v, &(i, ftz)) in variants.iter().enumerate() {
                let old = ftz.then(|| ftz_daz(true));
                let t = time(libs[i].as_ref(), &rays);
                if let Some(old) = old {
                    ftz_daz(old & 0x8040 != 0);
                }
                for k in 0..3 {
                    times[v][k].push(t[k]);
                }
            }
        }
        let lens = [rays.primary.len(), rays.bounce.len(), rays.shadow.len()];
        let mrays: Vec<[f64; 3]> = times
            .iter_mut()
            .map(|t| {
                core::array::from_fn(|k| lens[k] as f64 / median(&mut t[k]).as_secs_f64() / 1e6)
            })
            .collect();
        // Where library `i` was timed (without FTZ/DAZ): its row of `mrays`.
        let timed = |i: usize| variants.iter().position(|&v| v == (i, false));
        for (v, &(i, ftz)) in variants.iter().enumerate() {
            // The ratio to obvhs on its own triangles (row 1), and for the generic tree,
            // to obvhs with the same leaf test (row 3); then to Embree, where it is built in.
            let against = timed(if i == 2 { 3 } else { 1 });
            let embree = embree_row.and_then(timed);
            let ratio = |k: usize| {
                if i == 1 || i == 3 || Some(i) == embree_row {
                    return String::new();
                }
                let of = |r: Option<usize>| r.map(|r| format!("{:.2}x", mrays[v][k] / mrays[r][k]));
                let ratios: Vec<String> = [of(against), of(embree)].into_iter().flatten().collect();
                if ratios.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", ratios.join("; "))
                }
            };
            speed.push(format!(
                "| {name} | {}{} | {:.2}{} | {:.2}{} | {:.2}{} |",
                libs[i].name(),
                if ftz { ", FTZ/DAZ on" } else { "" },
                mrays[v][0],
                ratio(0),
                mrays[v][1],
                ratio(1),
                mrays[v][2],
                ratio(2),
            ));
        }
    }
    println!(
        "{}; one thread; {} x {} camera rays, a cosine bounce from each primary hit, a shadow ray to a point on the lamp from each primary hit facing it; Mrays/s, median of {} runs, the libraries in turn within each run; seed {:#x}\n",
        hitkit_render::workloads::machine(),
        args.side,
        args.side,
        args.runs,
        args.seed,
    );
    println!("| scene | triangles | vertices | primary rays | bounce rays | shadow rays |");
    println!("|---|---:|---:|---:|---:|---:|");
    sets.iter().for_each(|r| println!("{r}"));
    println!(
        "\nMrays/s; in brackets hitkit's against obvhs on its own triangles (for `Bvh<Quad<Triangle>>`, against obvhs with hitkit's test), and where Embree is built in, then against Embree:\n"
    );
    println!("| scene | library | primary | bounce | shadow |");
    println!("|---|---|---:|---:|---:|");
    speed.iter().for_each(|r| println!("{r}"));
    println!(
        "\nNode visits and face tests per ray (a node: hitkit's holds 8 children, as obvhs's):\n"
    );
    println!(
        "| scene | library | primary nodes | primary tests | bounce nodes | bounce tests | shadow nodes | shadow tests |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    counts.iter().for_each(|r| println!("{r}"));
    if !memory.is_empty() {
        println!("\nMemory after the build: TriangleMesh::heap_bytes, Embree's memory monitor\n");
        println!(
            "| scene | TriangleMesh bytes | Embree bytes | TriangleMesh bytes/face | Embree bytes/face |"
        );
        println!("|---|---:|---:|---:|---:|");
        memory.iter().for_each(|r| println!("{r}"));
    }
    if !notes.is_empty() {
        println!();
        notes.iter().for_each(|n| println!("{n}"));
    }
}
