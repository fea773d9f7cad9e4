//! The last Cornell box of "Ray Tracing: The Rest of Your Life" as the book's `main()` sets it
//! up: a tall box and a glass sphere, the lamp and the sphere both sampled as lights, 600x600,
//! 100 samples, depth 50, and no Russian roulette, so that it traces the book's work ray for
//! ray. `benches/book.sh` times it against the book's C++.
//!
//! `cargo run --release --example cornell_book` writes `cornell_book.png`; `-- --help` lists
//! the options.

use std::process::ExitCode;

use hitkit_render::cli::{Options, run};
use hitkit_render::scenes::cornell_book_scene;

fn main() -> ExitCode {
    let defaults = Options {
        width: 600,
        samples: 100,
        depth: 50,
        roulette: false,
        seed: 0,
        output: "cornell_book.png".into(),
        threads: 0,
    };
    run("cornell_book", defaults, |o| cornell_book_scene(o.width))
}
