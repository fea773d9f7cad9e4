//! What each of hitkit's accuracy choices fixes and what it costs, measured in one process
//! on the same hard-case workloads: the book's quad test, hitkit's well-conditioned plane
//! test with exact edges, 0.1.0's default (widened in `(alpha, beta)`), today's default
//! (the crossing region), spawned-ray offsets against `t_min`, and box-test variants. Prints
//! a Markdown table and writes `accuracy.svg` (failures against cost); then measures the
//! Cornell box's image error against render time.
//!
//! `cargo run --release -p hitkit-accuracy`; `-- --help` lists the options.
//!
//! The layout: `workloads/` generates the hard cases (each workload describes itself from
//! the constants that build it), `rows/` measures each accuracy choice on them, `report/`
//! prints the tables and draws the plot.

mod numbers;
mod report;
mod rows;
mod workloads;

use std::path::PathBuf;
use std::process::ExitCode;

use workloads::Workloads;

/// Timed repetitions of each workload; the table shows their median.
const REPETITIONS: usize = 7;
/// The Cornell box's width (and height) in part 2.
const RENDER_WIDTH: usize = 100;

/// The command line.
#[derive(Clone, Debug)]
struct Options {
    output_dir: PathBuf,
    quick: bool,
}

const USAGE: &str = "\
Measures what each of hitkit's accuracy choices fixes (failure counts on hard-case
workloads) and what it costs (ns per ray), prints a Markdown table, writes accuracy.svg,
then measures the Cornell box's image error against render time.

Usage: cargo run --release -p hitkit-accuracy -- [OPTIONS]

Options:
  --output-dir DIR  where to write accuracy.svg (created if missing) [default: .]
  --quick           a few rays and a small reference image: a smoke test, not numbers
                    to publish
  -h, --help        this text";

impl Options {
    /// `Ok(None)` for `--help`.
    fn parse(args: impl IntoIterator<Item = String>) -> Result<Option<Self>, String> {
        let mut options = Self {
            output_dir: PathBuf::from("."),
            quick: false,
        };
        let mut args = args.into_iter();
        while let Some(arg) = args.next() {
            match arg.as_str() {
                "-h" | "--help" => return Ok(None),
                "--quick" => options.quick = true,
                "--output-dir" => {
                    let dir = args
                        .next()
                        .ok_or("--output-dir needs a value: the directory to write into")?;
                    options.output_dir = PathBuf::from(dir);
                }
                other => match other.strip_prefix("--output-dir=") {
                    Some(dir) if !dir.is_empty() => options.output_dir = PathBuf::from(dir),
                    Some(_) => return Err("--output-dir= needs a directory".to_string()),
                    None => return Err(format!("unknown option `{other}`")),
                },
            }
        }
        Ok(Some(options))
    }
}

/// Runs both parts; an error message for anything that went wrong.
fn run(options: &Options) -> Result<(), String> {
    if options.output_dir.exists() && !options.output_dir.is_dir() {
        return Err(format!(
            "--output-dir: {} is not a directory",
            options.output_dir.display()
        ));
    }
    std::fs::create_dir_all(&options.output_dir).map_err(|e| {
        format!(
            "cannot use {} as the output directory: {e}",
            options.output_dir.display()
        )
    })?;
    let machine = hitkit_render::workloads::machine();
    println!("# What each accuracy choice fixes and what it costs\n");
    println!("Machine: {machine}.\n");
    println!("## Geometry\n");
    let size = if options.quick { 0.05 } else { 1.0 };
    let workloads = Workloads::generate(size);
    let repetitions = if options.quick { 1 } else { REPETITIONS };
    println!("{}", workloads.describe());
    report::print_columns(&workloads, repetitions);
    let (rows, notes) = rows::measure(&workloads, repetitions)?;
    report::print_table(&rows);
    report::print_notes(&rows, &notes);
    let path = report::write_plot(&rows, &options.output_dir, &machine)?;
    println!("Plot: {}\n", path.display());

    println!("## Light sampling: area against solid angle\n");
    report::print_samplers(&rows::samplers::measure_all(options.quick));

    println!("## Image error against time: the Cornell box\n");
    let width = if options.quick { 32 } else { RENDER_WIDTH };
    report::print_errors(&rows::render_error::measure(width, options.quick)?);
    Ok(())
}

fn main() -> ExitCode {
    let options = match Options::parse(std::env::args().skip(1)) {
        Ok(Some(options)) => options,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}\n\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
