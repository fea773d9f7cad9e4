//! A mesh that moves: a cloth waving in the wind (or the mesh of an OBJ file, twisting),
//! its vertices moved every frame and its tree refitted in place by
//! `TriangleMesh::set_vertices` (rebuilt only when its cost says so), rendered as numbered
//! PNGs with a progress bar over the frames.
//!
//! `cargo run --release --example deform` writes `deform-000.png` to `deform-011.png`;
//! `-- --frames N`, `-- --obj PATH` (twist that mesh instead), `-- --help` for the rest.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use hitkit::glam::DVec3;
use hitkit::{Aabb, Hittable, Interval, MaterialId, Quad, Ray, TriangleMesh};
use indicatif::{ProgressBar, ProgressStyle};

use hitkit_render::cli::{Options, check_output, write_png};
use hitkit_render::render::render;
use hitkit_render::scenes::load_obj;
use hitkit_render::{Background, CameraSettings, Color, Material, Scene};

/// The most frames.
const MAX_FRAMES: usize = 10_000;

/// The ground and the moving mesh.
struct World {
    ground: Quad,
    mesh: TriangleMesh,
}

impl Hittable for World {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<hitkit::HitRecord> {
        let ground = self.ground.hit(ray, ray_t);
        let t_max = ground.as_ref().map_or(ray_t.max, |h| h.t);
        self.mesh
            .hit(ray, Interval::new(ray_t.min, t_max))
            .or(ground)
    }

    fn bounding_box(&self) -> Aabb {
        self.ground.bounding_box().union(&self.mesh.bounding_box())
    }
}

/// What moves: a cloth (a grid pinned along its left edge, waving) or a loaded mesh
/// (twisted about its vertical axis, further every frame).
enum Motion {
    Cloth { columns: u32, rows: u32 },
    Twist { rest: Vec<DVec3> },
}

impl Motion {
    /// The vertices at time `s` in `[0, 1]`.
    fn vertices(&self, s: f64) -> Vec<DVec3> {
        use std::f64::consts::{PI, TAU};
        match self {
            Motion::Cloth { columns, rows } => {
                let mut vertices = Vec::new();
                for j in 0..=*rows {
                    for i in 0..=*columns {
                        // 3 wide, 2 high, hanging from a pole at x = -1.5.
                        let (u, v) = (
                            f64::from(i) / f64::from(*columns),
                            f64::from(j) / f64::from(*rows),
                        );
                        let phase = TAU * (1.5 * u - s) + 0.7 * v;
                        let wave = 0.5 * u * phase.sin();
                        vertices.push(DVec3::new(
                            -1.5 + 3.0 * u - 0.2 * u * u,
                            0.4 + 2.0 * v,
                            wave,
                        ));
                    }
                }
                vertices
            }
            Motion::Twist { rest } => {
                let (lo, hi) = rest
                    .iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                        (lo.min(*p), hi.max(*p))
                    });
                let height = (hi.y - lo.y).max(f64::MIN_POSITIVE);
                rest.iter()
                    .map(|&p| {
                        let angle = 0.5 * PI * s * (p.y - lo.y) / height;
                        let (sin, cos) = angle.sin_cos();
                        DVec3::new(cos * p.x - sin * p.z, p.y - lo.y, sin * p.x + cos * p.z)
                    })
                    .collect()
            }
        }
    }

    fn faces(&self) -> Vec<[u32; 3]> {
        match self {
            Motion::Cloth { columns, rows } => {
                let at = |i: u32, j: u32| j * (columns + 1) + i;
                (0..*rows)
                    .flat_map(|j| {
                        (0..*columns).flat_map(move |i| {
                            [
                                [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                                [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                            ]
                        })
                    })
                    .collect()
            }
            Motion::Twist { .. } => Vec::new(),
        }
    }
}

/// `deform.png` to `deform-007.png`.
fn frame_path(output: &Path, frame: usize) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or("deform".into(), |s| s.to_string_lossy());
    let ext = output
        .extension()
        .map_or("png".into(), |e| e.to_string_lossy());
    output.with_file_name(format!("{stem}-{frame:03}.{ext}"))
}

fn main() -> ExitCode {
    let defaults = Options {
        width: 400,
        samples: 32,
        depth: 20,
        roulette: true,
        seed: 0,
        output: "deform.png".into(),
        threads: 0,
    };
    // `--frames N` and `--obj PATH` are this example's own; the rest go to the common ones.
    let (mut frames, mut obj, mut rest) = (12usize, None, Vec::new());
    let mut args = hitkit_render::cli::split_equals(std::env::args().skip(1)).into_iter();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--frames" => match args.next().and_then(|v| v.parse().ok()) {
                Some(n) if (1..=MAX_FRAMES).contains(&n) => frames = n,
                _ => {
                    eprintln!("error: --frames needs a whole number from 1 to {MAX_FRAMES}");
                    return ExitCode::from(2);
                }
            },
            "--obj" => match args.next() {
                Some(path) => obj = Some(PathBuf::from(path)),
                None => {
                    eprintln!("error: --obj needs a value");
                    return ExitCode::from(2);
                }
            },
            _ => rest.push(arg),
        }
    }
    let options = match defaults.parse(rest) {
        Ok(Some(options)) => options,
        Ok(None) => {
            println!(
                "Renders a mesh that moves, as numbered PNGs (OUTPUT's name with -000, -001, ...).\n\n\
                 Usage: cargo run --release --example deform -- [OPTIONS]\n\n\
                 Options:\n  \
                 --frames N    frames, 1 to {MAX_FRAMES} [default: 12]\n  \
                 --obj PATH    twist the mesh in this OBJ file instead of waving a cloth\n  \
                 and the renderer's: --width, --samples, --depth, --roulette, --seed,\n  \
                 --output, --threads (see `--example quads -- --help`) [default width 400,\n  \
                 32 samples, depth 20, output deform.png]"
            );
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}");
            return ExitCode::from(2);
        }
    };
    let first = frame_path(&options.output, 0);
    if let Err(message) = check_output(&first) {
        eprintln!("error: {message}");
        return ExitCode::from(2);
    }

    let (motion, mesh) = match obj {
        None => {
            let motion = Motion::Cloth {
                columns: 120,
                rows: 80,
            };
            let mesh = TriangleMesh::new(&motion.vertices(0.0), &motion.faces());
            (motion, mesh.map_err(|e| e.to_string()))
        }
        Some(path) => match load_obj(&path) {
            Ok(mesh) => {
                // The loaded mesh's own vertices, in the caller's numbering, are what moves.
                let rest = rest_vertices(&mesh);
                let motion = Motion::Twist { rest };
                let mut mesh = mesh;
                let moved = mesh.set_vertices(&motion.vertices(0.0)).map(|()| mesh);
                (motion, moved.map_err(|e| e.to_string()))
            }
            Err(message) => (Motion::Twist { rest: Vec::new() }, Err(message)),
        },
    };
    let mesh = match mesh {
        Ok(mesh) => mesh.with_material(MaterialId(1)),
        Err(message) => {
            eprintln!("error: {message}");
            return ExitCode::from(2);
        }
    };
    let mut scene = Scene {
        world: World {
            ground: Quad::new(
                DVec3::new(-20.0, 0.0, 20.0),
                DVec3::new(40.0, 0.0, 0.0),
                DVec3::new(0.0, 0.0, -40.0),
            )
            .expect("a valid ground")
            .with_material(MaterialId(0)),
            mesh,
        },
        materials: vec![
            Material::Lambertian(Color::new(0.45, 0.45, 0.4)),
            Material::Lambertian(Color::new(0.75, 0.25, 0.2)),
        ],
        lights: None,
        next_event: false,
        background: Background::Sky,
        camera: CameraSettings {
            width: options.width,
            height: (options.width * 9 / 16).max(1),
            vfov: 40.0,
            lookfrom: DVec3::new(3.0, 2.2, 5.5),
            lookat: DVec3::new(0.0, 1.2, 0.0),
            vup: DVec3::Y,
            defocus_angle: 0.0,
            focus_dist: 6.0,
            shutter: false,
            mask: u32::MAX,
        },
    };
    // The bar is over the frames, not each frame's rows.
    let settings = options.settings(false);

    let bar = ProgressBar::new(frames as u64);
    if let Ok(style) =
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} frames {msg}")
    {
        bar.set_style(style);
    }
    let (mut refits, mut rebuilds) = (Vec::new(), 0);
    let start = Instant::now();
    for frame in 0..frames {
        if frame > 0 {
            let vertices = motion.vertices(frame as f64 / frames as f64);
            let mesh = &mut scene.world.mesh;
            let refit = Instant::now();
            if let Err(e) = mesh.set_vertices(&vertices) {
                bar.abandon();
                eprintln!("error: frame {frame}: {e}");
                return ExitCode::FAILURE;
            }
            // The default policy: rebuild once the refitted tree costs 1.5x its build.
            if mesh.cost().needs_rebuild() {
                mesh.rebuild();
                rebuilds += 1;
            }
            refits.push(refit.elapsed().as_secs_f64() * 1e3);
        }
        let image = match render(&scene, &settings, scene.effects()) {
            Ok(image) => image,
            Err(message) => {
                bar.abandon();
                eprintln!("error: {message}");
                return ExitCode::FAILURE;
            }
        };
        let path = frame_path(&options.output, frame);
        if let Err(e) = write_png(&path, &image) {
            bar.abandon();
            eprintln!("error: cannot write {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        bar.set_message(format!(
            "(tree cost {:.2}x its build)",
            scene.world.mesh.cost().ratio()
        ));
        bar.inc(1);
    }
    bar.finish();
    refits.sort_by(f64::total_cmp);
    let median = refits.get(refits.len() / 2).copied().unwrap_or(0.0);
    println!(
        "wrote {} to {} ({} frames of {} triangles, {}x{}, {} samples per pixel) in {:.2} s; \
         moving the mesh took {median:.2} ms a frame (median), with {rebuilds} rebuilds",
        first.display(),
        frame_path(&options.output, frames - 1).display(),
        frames,
        scene.world.mesh.hittable_face_count(),
        scene.camera.width,
        scene.camera.height,
        options.samples,
        start.elapsed().as_secs_f64(),
    );
    ExitCode::SUCCESS
}

/// The mesh's vertices in the caller's numbering (as `set_vertices` takes them): where
/// its faces' corners are (a vertex no face names stays at the origin: it never shows).
fn rest_vertices(mesh: &TriangleMesh) -> Vec<DVec3> {
    let mut vertices = vec![DVec3::ZERO; mesh.vertex_count()];
    for face in mesh.faces() {
        for (i, p) in face.indices().into_iter().zip(face.corners()) {
            vertices[i as usize] = p;
        }
    }
    vertices
}
