//! Meshes, instancing and motion: a generated torus (or any OBJ file) instanced 120 times,
//! each instance coloured by the id its hits carry, a few of them and three balls moving
//! over the shutter interval (motion blur).
//!
//! `cargo run --release --example mesh` writes `mesh.png`;
//! `cargo run --release --example mesh -- --obj PATH` renders the mesh in the OBJ file at
//! PATH instead (smooth where the file has vertex normals); `-- --help` lists the options.

use std::path::PathBuf;
use std::process::ExitCode;

use hitkit_render::cli::{Options, run_with};
use hitkit_render::scenes::{load_obj, mesh_scene};

fn main() -> ExitCode {
    let defaults = Options {
        width: 400,
        samples: 64,
        depth: 50,
        roulette: true,
        seed: 0,
        output: "mesh.png".into(),
        threads: 0,
    };
    // `--obj PATH` is this example's own; the rest go to the common options.
    let (mut obj, mut rest) = (None, Vec::new());
    let mut args = hitkit_render::cli::split_equals(std::env::args().skip(1)).into_iter();
    while let Some(arg) = args.next() {
        if arg == "--obj" {
            match args.next() {
                Some(path) => obj = Some(PathBuf::from(path)),
                None => {
                    eprintln!("error: --obj needs a value");
                    return ExitCode::from(2);
                }
            }
        } else {
            rest.push(arg);
        }
    }
    let extra = "\n  --obj PATH    render the mesh in this OBJ file instead of the generated torus";
    run_with("mesh", defaults, rest, extra, |o| {
        let mesh = obj.as_deref().map(load_obj).transpose()?;
        Ok(mesh_scene(o.width, mesh))
    })
}
