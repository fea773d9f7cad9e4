//! A renderer written the way the book series' Rust ports are written, timed on hitkit's
//! shapes and trees and on the book's own formulas in Rust, side by side: the same scenes,
//! camera, samples and random numbers, one thread, the two renders in alternation. Prints a
//! Markdown table: median times, their ratio, and each image's mean luminance with its
//! standard error (the two must agree within noise).
//!
//! `cargo run --release -p hitkit-port -- --help`

mod naive;
mod render;
mod scenes;

use std::process::ExitCode;
use std::time::Instant;

use render::{Backend, Hitkit, Naive, render};

const USAGE: &str = "\
Times one renderer, written as the book series' Rust ports are, on hitkit and on the book's own
geometry in Rust (its 1e-8 parallel test, 0.0001 box padding, 0.001 t_min and a binary BVH of
boxed nodes), in alternation on one thread, and prints a Markdown table.

Usage: cargo run --release -p hitkit-port -- [OPTIONS]

Options:
  --rounds N     renders of each scene on each side, alternating [default: 3]
  --scale S      image width and samples per pixel as a fraction of the defaults (The Next
                 Week's quads 400 x 400 at 100 samples, its final scene 200 x 200 at 64, the
                 Cornell box 300 x 300 at 100, with hitkit's lamp sampled by solid angle and
                 by area), for a quick look [default: 1]
  --only SIDE    render on one side only, `hitkit` or `book` (for a profiler), no table
  --scene TEXT   only the scenes whose name contains TEXT (`quads`, `final`, `Cornell`)
  -h, --help     this text";

fn main() -> ExitCode {
    let (mut rounds, mut scale, mut only) = (3usize, 1.0f64, None);
    let mut scene_filter = String::new();
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        if flag == "-h" || flag == "--help" {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        let value = args.next().unwrap_or_default();
        let ok = match flag.as_str() {
            "--rounds" => value.parse().map(|v| rounds = v).is_ok() && rounds > 0,
            "--scale" => value.parse().map(|v| scale = v).is_ok() && scale > 0.0 && scale <= 1.0,
            "--scene" => {
                scene_filter = value.clone();
                true
            }
            "--only" if value == "hitkit" || value == "book" => {
                only = Some(value.clone());
                true
            }
            _ => false,
        };
        if !ok {
            eprintln!("hitkit-port: bad option {flag} {value:?}\n\n{USAGE}");
            return ExitCode::from(2);
        }
    }
    let size = |n: f64| ((n * scale).round() as usize).max(1);
    let scenes = [
        scenes::quads(size(400.0), size(100.0)),
        scenes::final_scene(size(200.0), size(64.0)),
        scenes::cornell(size(300.0), size(100.0), false),
        scenes::cornell(size(300.0), size(100.0), true),
    ];
    let scenes: Vec<_> = scenes
        .into_iter()
        .filter(|s| s.name.contains(scene_filter.as_str()))
        .collect();
    if let Some(side) = only {
        for scene in &scenes {
            let r = if side == "hitkit" {
                render(&Hitkit::new(scene), scene)
            } else {
                render(&Naive::new(scene), scene)
            };
            println!(
                "{}: mean {:.5} ± {:.5}",
                scene.name, r.mean, r.standard_error
            );
        }
        return ExitCode::SUCCESS;
    }
    println!(
        "| scene | book's geometry (s) | hitkit (s) | ratio | mean, book's | mean, hitkit | agree |"
    );
    println!("|---|---:|---:|---:|---:|---:|---|");
    let mut all_agree = true;
    for scene in &scenes {
        let (naive, hitkit) = (Naive::new(scene), Hitkit::new(scene));
        let (mut times, mut ratios) = ([Vec::new(), Vec::new()], Vec::new());
        let mut last = None;
        for _ in 0..rounds {
            let (a, ra) = timed(&naive, scene);
            let (b, rb) = timed(&hitkit, scene);
            times[0].push(a);
            times[1].push(b);
            ratios.push(b / a);
            last = Some((ra, rb));
        }
        let (ra, rb) = last.expect("at least one round");
        let se = (ra.standard_error.powi(2) + rb.standard_error.powi(2)).sqrt();
        let agree = (ra.mean - rb.mean).abs() <= 4.0 * se;
        all_agree &= agree;
        println!(
            "| {} ({}x{}, {} spp) | {:.2} | {:.2} | {:.2}x | {:.5} ± {:.5} | {:.5} ± {:.5} | {} |",
            scene.name,
            scene.width,
            scene.width,
            scene.samples,
            median(&mut times[0]),
            median(&mut times[1]),
            median(&mut ratios),
            ra.mean,
            ra.standard_error,
            rb.mean,
            rb.standard_error,
            if agree { "yes" } else { "NO" }
        );
    }
    if all_agree {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn timed<B: Backend>(b: &B, scene: &scenes::Scene) -> (f64, render::Render) {
    let start = Instant::now();
    let r = render(b, scene);
    (start.elapsed().as_secs_f64(), r)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
