//! The examples' command line, and writing the image.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use hitkit::Hittable;

use crate::Color;
use crate::Scene;
use crate::render::{Rendered, Settings, render};

/// The largest image width the examples render: 8K. The pixels are kept as `f64` RGB
/// (24 bytes each), so a square image of this width takes 1.5 GiB; wider ones would take
/// more memory than a workstation has before the first pixel is traced.
pub const MAX_WIDTH: usize = 8192;
/// The most samples per pixel: a million, which at 400x400 is days of rendering.
pub const MAX_SAMPLES: usize = 1 << 20;
/// The longest path: Russian roulette ends nearly every path long before it.
pub const MAX_DEPTH: usize = 10_000;
/// The most worker threads.
pub const MAX_THREADS: usize = 1024;

/// What each example may change from the command line, with its defaults.
#[derive(Clone, Debug)]
pub struct Options {
    pub width: usize,
    pub samples: usize,
    pub depth: usize,
    /// Russian roulette after a few bounces (see `Settings::roulette`).
    pub roulette: bool,
    pub seed: u64,
    pub output: PathBuf,
    pub threads: usize,
}

impl Options {
    pub fn usage(&self, example: &str) -> String {
        format!(
            "Renders the {example} scene to a PNG.\n\n\
             Usage: cargo run --release --example {example} -- [OPTIONS]\n\n\
             Options:\n  \
             --width N     image width in pixels, 1 to {MAX_WIDTH} [default: {}]\n  \
             --samples N   samples per pixel, 1 to {MAX_SAMPLES} [default: {}]\n  \
             --depth N     longest path, in bounces, 1 to {MAX_DEPTH} [default: {}]\n  \
             --roulette Y  end paths by Russian roulette after 3 bounces, yes or no [default: {}]\n  \
             --seed S      random seed; the same seed gives the same image [default: {}]\n  \
             --output PATH where to write the PNG (checked before rendering) [default: {}]\n  \
             --threads N   worker threads, 0 for one per core, at most {MAX_THREADS} [default: {}]\n  \
             -h, --help    this text",
            self.width,
            self.samples,
            self.depth,
            if self.roulette { "yes" } else { "no" },
            self.seed,
            self.output.display(),
            self.threads
        )
    }

    /// The render settings these options ask for, with a progress bar or without.
    pub fn settings(&self, progress: bool) -> Settings {
        Settings {
            samples: self.samples,
            max_depth: self.depth,
            roulette: self.roulette,
            seed: self.seed,
            threads: self.threads,
            progress,
        }
    }

    /// These options changed by `args` (the command line without the program's name);
    /// `Ok(None)` for `--help`, an error naming the flag for a bad or out-of-range value.
    pub fn parse(mut self, args: impl IntoIterator<Item = String>) -> Result<Option<Self>, String> {
        let mut args = split_equals(args).into_iter();
        while let Some(flag) = args.next() {
            if flag == "-h" || flag == "--help" {
                return Ok(None);
            }
            let mut value = || args.next().ok_or_else(|| format!("{flag} needs a value"));
            let count = |v: String, min: usize, max: usize| match v.parse::<usize>() {
                Ok(n) if (min..=max).contains(&n) => Ok(n),
                _ => Err(format!(
                    "{flag}: `{v}` is not a whole number from {min} to {max}"
                )),
            };
            match flag.as_str() {
                "--width" => self.width = count(value()?, 1, MAX_WIDTH)?,
                "--samples" => self.samples = count(value()?, 1, MAX_SAMPLES)?,
                "--depth" => self.depth = count(value()?, 1, MAX_DEPTH)?,
                "--threads" => self.threads = count(value()?, 0, MAX_THREADS)?,
                "--seed" => {
                    let v = value()?;
                    self.seed = v
                        .parse()
                        .map_err(|_| format!("--seed: `{v}` is not a whole number"))?;
                }
                "--output" => self.output = PathBuf::from(value()?),
                "--roulette" => {
                    self.roulette = match value()?.as_str() {
                        "yes" => true,
                        "no" => false,
                        other => return Err(format!("--roulette: `{other}` is not yes or no")),
                    }
                }
                other => return Err(format!("unknown option `{other}`")),
            }
        }
        Ok(Some(self))
    }
}

/// The command line with every `--flag=value` split into `--flag` and `value`, so that both
/// spellings are taken (and `--width=-5` is refused for its value, not as an unknown flag).
pub fn split_equals(args: impl IntoIterator<Item = String>) -> Vec<String> {
    args.into_iter()
        .flat_map(|arg| match arg.split_once('=') {
            Some((flag, value)) if flag.starts_with("--") => {
                vec![flag.to_owned(), value.to_owned()]
            }
            _ => vec![arg],
        })
        .collect()
}

/// The whole of an example's `main`: parse the options (starting from `defaults`), build the
/// scene for them, render with the effects it calls for, write the PNG, and say where and
/// how long it took.
pub fn run<W: Hittable>(
    example: &str,
    defaults: Options,
    scene: impl FnOnce(&Options) -> Scene<W>,
) -> ExitCode {
    run_with(example, defaults, std::env::args().skip(1), "", |o| {
        Ok(scene(o))
    })
}

/// [`run`] on the arguments `args`, with `extra` lines of usage (for options the example
/// parsed itself) and a scene that may fail to build (an error naming why).
pub fn run_with<W: Hittable>(
    example: &str,
    defaults: Options,
    args: impl IntoIterator<Item = String>,
    extra: &str,
    scene: impl FnOnce(&Options) -> Result<Scene<W>, String>,
) -> ExitCode {
    let usage = format!("{}{extra}", defaults.usage(example));
    let options = match defaults.clone().parse(args) {
        Ok(Some(options)) => options,
        Ok(None) => {
            println!("{usage}");
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}\n\n{usage}");
            return ExitCode::from(2);
        }
    };
    // Before the render, not after it: a long render is not lost to a typo in the path.
    if let Err(message) = check_output(&options.output) {
        eprintln!("error: {message}");
        return ExitCode::from(2);
    }
    let scene = match scene(&options) {
        Ok(scene) => scene,
        Err(message) => {
            eprintln!("error: {message}");
            return ExitCode::from(2);
        }
    };
    let settings = options.settings(true);
    let start = Instant::now();
    let image = match render(&scene, &settings, scene.effects()) {
        Ok(image) => image,
        Err(message) => {
            eprintln!("error: {message}");
            return ExitCode::FAILURE;
        }
    };
    let elapsed = start.elapsed();
    if let Err(e) = write_png(&options.output, &image) {
        eprintln!("error: cannot write {}: {e}", options.output.display());
        return ExitCode::FAILURE;
    }
    println!(
        "wrote {} ({}x{}, {} samples per pixel) in {:.2} s",
        options.output.display(),
        image.width,
        image.height,
        options.samples,
        elapsed.as_secs_f64()
    );
    ExitCode::SUCCESS
}

/// Whether a PNG can be written to `path`: its directory exists and the file can be opened
/// for writing. An existing file is left as it is (not truncated), and a file this check
/// creates is removed again. The error names the path and what the system said.
pub fn check_output(path: &Path) -> Result<(), String> {
    let cannot = |e: std::io::Error| format!("cannot write {}: {e}", path.display());
    if path.is_dir() {
        return Err(format!(
            "cannot write {}: it is a directory",
            path.display()
        ));
    }
    if path.exists() {
        std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(cannot)?;
    } else {
        std::fs::File::create(path).map_err(cannot)?;
        std::fs::remove_file(path).map_err(cannot)?;
    }
    Ok(())
}

/// 8-bit sRGB with the book's gamma 2.
pub fn to_rgb8(c: Color) -> [u8; 3] {
    let byte = |x: f64| (256.0 * x.max(0.0).sqrt().clamp(0.0, 0.999)) as u8;
    [byte(c.x), byte(c.y), byte(c.z)]
}

pub fn write_png(path: &Path, image: &Rendered) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| e.to_string())?;
    let mut encoder = png::Encoder::new(
        std::io::BufWriter::new(file),
        image.width as u32,
        image.height as u32,
    );
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    let data: Vec<u8> = image.pixels.iter().flat_map(|c| to_rgb8(*c)).collect();
    writer.write_image_data(&data).map_err(|e| e.to_string())
}
