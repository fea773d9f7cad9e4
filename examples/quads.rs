//! The quads scene of "Ray Tracing: The Next Week", exactly as the book sets it up.
//!
//! `cargo run --release --example quads` writes `quads.png`; `-- --help` lists the options.

use std::process::ExitCode;

use hitkit_render::cli::{Options, run};
use hitkit_render::scenes::quads_scene;

fn main() -> ExitCode {
    let defaults = Options {
        width: 400,
        samples: 100,
        depth: 50,
        roulette: true,
        seed: 0,
        output: "quads.png".into(),
        threads: 0,
    };
    run("quads", defaults, |o| quads_scene(o.width))
}
