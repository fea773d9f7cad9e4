//! Many lights: a long hall lit by small lamps of varied power (by default 1,000 ceiling
//! panels and 126 wall sconces), lit by next-event estimation (a shadow ray from each
//! diffuse hit to a point on a lamp, weighed against the cosine bounce by multiple
//! importance sampling), the lamp picked by hitkit's `LightTree` (by importance from the
//! shading point), by a power-weighted `Mixture`, or uniformly.
//!
//! `cargo run --release --example many_lights` writes `many_lights.png`;
//! `-- --lights power` or `-- --lights uniform` picks the other way; `-- --rows N` sets the
//! hall's length (four panels a row); `-- --help` lists the rest.
//!
//! `-- --compare SECONDS` measures what the choice is worth: for the hall and for the
//! Cornell box (one light), a reference image by the light tree at `--reference N` samples
//! per pixel, then each of the three ways, and the tree with the book's one-sample mixture
//! of light and cosine directions in place of next-event estimation, rendered one sample
//! per pixel at a time, in turn (the same seeds for each), until each has had `SECONDS` of
//! rendering; it prints each one's mean squared error against the reference, at equal time.

use std::process::ExitCode;
use std::time::{Duration, Instant};

use hitkit::Hittable;
use hitkit_render::cli::{Options, run_with};
use hitkit_render::render::{Rendered, luminance, render};
use hitkit_render::scenes::{Pick, cornell_pick, hall_scene};
use hitkit_render::{Color, Scene};

const EXTRA: &str = "\n  \
--lights WAY  how to pick a lamp: tree, power or uniform [default: tree]\n  \
--rows N      rows of four ceiling panels, 1 to 100000, 0.6 m apart [default: 250]\n  \
--compare S   instead of one image: the error table, S seconds of rendering for each way\n  \
--reference N samples per pixel of the comparison's reference images [default: 1024]";

fn main() -> ExitCode {
    let defaults = Options {
        width: 480,
        samples: 64,
        depth: 8,
        roulette: true,
        seed: 0,
        output: "many_lights.png".into(),
        threads: 0,
    };
    let usage = format!("{}{EXTRA}", defaults.usage("many_lights"));
    let fail = |message: String| {
        eprintln!("error: {message}\n\n{usage}");
        ExitCode::from(2)
    };
    // `--lights`, `--rows`, `--compare` and `--reference` are this example's own; the rest
    // go to the common ones.
    let (mut pick, mut rows, mut compare, mut reference) = (Pick::Tree, 250, None, 1024);
    let (mut args, mut rest) = (std::env::args().skip(1), Vec::new());
    while let Some(flag) = args.next() {
        let own = ["--lights", "--rows", "--compare", "--reference"];
        if !own.contains(&flag.as_str()) {
            rest.push(flag);
            continue;
        }
        let Some(value) = args.next() else {
            return fail(format!("{flag} needs a value"));
        };
        let parsed = match flag.as_str() {
            "--lights" => match value.as_str() {
                "tree" => Ok(Pick::Tree),
                "power" => Ok(Pick::Power),
                "uniform" => Ok(Pick::Uniform),
                other => Err(format!("--lights: `{other}` is not tree, power or uniform")),
            }
            .map(|p| pick = p),
            "--rows" => number(&flag, &value, 1, 100_000).map(|n| rows = n),
            "--reference" => number(&flag, &value, 1, 1_000_000).map(|n| reference = n),
            _ => value
                .parse::<f64>()
                .ok()
                .filter(|s| (0.1..=86_400.0).contains(s))
                .map(|s| compare = Some(s))
                .ok_or_else(|| {
                    format!("--compare: `{value}` is not a number of seconds from 0.1 to 86400")
                }),
        };
        if let Err(message) = parsed {
            return fail(message);
        }
    }
    if let Some(seconds) = compare {
        let options = match defaults.clone().parse(rest) {
            Ok(Some(options)) => options,
            Ok(None) => {
                println!("{usage}");
                return ExitCode::SUCCESS;
            }
            Err(message) => return fail(message),
        };
        return match compare_all(&options, rows, reference, Duration::from_secs_f64(seconds)) {
            Ok(()) => ExitCode::SUCCESS,
            Err(message) => {
                eprintln!("error: {message}");
                ExitCode::FAILURE
            }
        };
    }
    run_with("many_lights", defaults, rest, EXTRA, |o| {
        Ok(hall_scene(o.width, rows, pick))
    })
}

/// The lamps of a scene: its emissive materials (each lamp has its own).
fn lamps<W>(scene: &Scene<W>) -> usize {
    let emits = |m: &&hitkit_render::Material| matches!(m, hitkit_render::Material::Light(_));
    scene.materials.iter().filter(emits).count()
}

fn number(flag: &str, value: &str, lo: usize, hi: usize) -> Result<usize, String> {
    value
        .parse::<usize>()
        .ok()
        .filter(|n| (lo..=hi).contains(n))
        .ok_or_else(|| format!("{flag}: `{value}` is not a whole number from {lo} to {hi}"))
}

/// The ways compared: how a lamp is picked, and whether by next-event estimation.
const PICKS: [(Pick, bool, &str); 4] = [
    (Pick::Tree, true, "light tree"),
    (Pick::Power, true, "power-weighted mixture"),
    (Pick::Uniform, true, "uniform mixture"),
    (
        Pick::Tree,
        false,
        "light tree, the book's one-sample mixture (no shadow rays)",
    ),
];

/// The error table for the hall and the Cornell box.
fn compare_all(
    options: &Options,
    rows: usize,
    reference: usize,
    budget: Duration,
) -> Result<(), String> {
    let hall_width = options.width;
    let cornell_width = (options.width * 9 / 16).max(1);
    let hall = |pick| hall_scene(hall_width, rows, pick);
    let cornell = |pick| cornell_pick(cornell_width, pick);
    let mut lines = compare(
        &format!("hall, {} lamps", lamps(&hall(Pick::Uniform))),
        hall,
        options,
        reference,
        budget,
    )?;
    lines.extend(compare(
        "Cornell box, 1 lamp",
        cornell,
        options,
        reference,
        budget,
    )?);
    println!(
        "{}, {}; {hall_width}x{} (hall) and {cornell_width}x{cornell_width} (Cornell box), up to {} bounces with Russian roulette; reference: the light tree at {reference} samples per pixel; each way rendered one sample per pixel at a time, in turn, until it had {:.0} s\n",
        hitkit_render::workloads::machine(),
        if options.threads == 0 {
            "a thread per core".to_string()
        } else {
            format!("{} threads", options.threads)
        },
        hall_width * 9 / 16,
        options.depth,
        budget.as_secs_f64(),
    );
    println!(
        "| scene | lamps picked by | samples per pixel | render s | MSE (luminance) | MSE / power-weighted's |"
    );
    println!("|---|---|---:|---:|---:|---:|");
    for line in lines {
        println!("{line}");
    }
    Ok(())
}

/// One scene's rows: the reference, then the ways in turn for `budget` each.
fn compare<W: Hittable>(
    name: &str,
    scene: impl Fn(Pick) -> Scene<W>,
    options: &Options,
    reference: usize,
    budget: Duration,
) -> Result<Vec<String>, String> {
    eprintln!("{name}: reference, {reference} samples per pixel");
    let mut settings = options.settings(true);
    settings.samples = reference;
    settings.seed = u64::MAX / 2;
    let truth = scene(Pick::Tree);
    let truth = render(&truth, &settings, truth.effects())?;
    let reference_noise = truth.variance.iter().sum::<f64>() / truth.variance.len() as f64;
    // Every way's scene built first: the build is not render time.
    let scenes: Vec<Scene<W>> = PICKS
        .iter()
        .map(|&(pick, next_event, _)| Scene {
            next_event,
            ..scene(pick)
        })
        .collect();
    let mut sums: Vec<Vec<Color>> = vec![vec![Color::ZERO; truth.pixels.len()]; PICKS.len()];
    let mut spent = [Duration::ZERO; PICKS.len()];
    let mut passes = [0usize; PICKS.len()];
    let mut settings = options.settings(false);
    settings.samples = 1;
    eprintln!("{name}: {:.0} s for each way", budget.as_secs_f64());
    while spent.iter().any(|&s| s < budget) {
        for k in 0..PICKS.len() {
            if spent[k] >= budget {
                continue;
            }
            // The same seeds for every way (common random numbers): with one lamp, which
            // every way picks always, the next-event ways render the same image pass for pass.
            settings.seed = passes[k] as u64;
            let start = Instant::now();
            let pass: Rendered = render(&scenes[k], &settings, scenes[k].effects())?;
            spent[k] += start.elapsed();
            passes[k] += 1;
            for (sum, p) in sums[k].iter_mut().zip(&pass.pixels) {
                *sum += *p;
            }
        }
    }
    let mse: Vec<f64> = (0..PICKS.len())
        .map(|k| {
            let n = passes[k] as f64;
            let error: f64 = sums[k]
                .iter()
                .zip(&truth.pixels)
                .map(|(s, t)| (luminance(*s / n) - luminance(*t)).powi(2))
                .sum();
            error / truth.pixels.len() as f64
        })
        .collect();
    let power = mse[1];
    let mut lines: Vec<String> = PICKS
        .iter()
        .enumerate()
        .map(|(k, (_, _, way))| {
            format!(
                "| {name} | {way} | {} | {:.1} | {:.3e} | {:.3} |",
                passes[k],
                spent[k].as_secs_f64(),
                mse[k],
                mse[k] / power
            )
        })
        .collect();
    lines.push(format!(
        "| {name} | (the reference's own noise, in every MSE above) | {reference} | | {reference_noise:.3e} | |"
    ));
    Ok(lines)
}
