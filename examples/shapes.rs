//! hitkit's interior predicates side by side: a triangle, a disk, a ring and a star written
//! as a closure, all `Quad`s on the same plane machinery.
//!
//! `cargo run --release --example shapes` writes `shapes.png`; `-- --help` lists the options.

use std::process::ExitCode;

use hitkit_render::cli::{Options, run};
use hitkit_render::scenes::shapes_scene;

fn main() -> ExitCode {
    let defaults = Options {
        width: 600,
        samples: 64,
        depth: 20,
        roulette: true,
        seed: 0,
        output: "shapes.png".into(),
        threads: 0,
    };
    run("shapes", defaults, |o| shapes_scene(o.width))
}
