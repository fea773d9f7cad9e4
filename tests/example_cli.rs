//! The examples' command line: absurd sizes and unwritable outputs are refused with an error
//! that names them, before anything is rendered.

use std::path::PathBuf;

use hitkit_render::cli::{MAX_SAMPLES, MAX_WIDTH, Options, check_output};

fn defaults() -> Options {
    Options {
        width: 400,
        samples: 100,
        depth: 50,
        roulette: true,
        seed: 0,
        output: "out.png".into(),
        threads: 0,
    }
}

fn parse(args: &[&str]) -> Result<Option<Options>, String> {
    defaults().parse(args.iter().map(|s| s.to_string()))
}

#[test]
fn sizes_in_range_are_taken_and_absurd_ones_refused_naming_the_flag() {
    let o = parse(&[
        "--width",
        "640",
        "--samples",
        "16",
        "--depth",
        "8",
        "--threads",
        "1",
    ])
    .unwrap()
    .unwrap();
    assert_eq!((o.width, o.samples, o.depth, o.threads), (640, 16, 8, 1));
    let limit = MAX_WIDTH.to_string();
    assert_eq!(
        parse(&["--width", &limit]).unwrap().unwrap().width,
        MAX_WIDTH
    );
    for (flag, bad) in [
        ("--width", (MAX_WIDTH + 1).to_string()),
        ("--width", "0".to_string()),
        ("--width", "100000000000".to_string()),
        ("--width", "-3".to_string()),
        ("--samples", "0".to_string()),
        ("--samples", (MAX_SAMPLES + 1).to_string()),
        ("--depth", "0".to_string()),
        ("--threads", "1e9".to_string()),
    ] {
        let error = parse(&[flag, &bad]).expect_err(&bad);
        assert!(error.starts_with(flag) && error.contains(&bad), "{error}");
    }
    assert!(parse(&["--width"]).unwrap_err().contains("needs a value"));
    assert!(parse(&["--help"]).unwrap().is_none());
    assert!(!parse(&["--roulette", "no"]).unwrap().unwrap().roulette);
    assert!(
        parse(&["--roulette", "maybe"])
            .unwrap_err()
            .contains("maybe")
    );
}

#[test]
fn an_output_that_cannot_be_written_is_refused_and_a_good_one_left_alone() {
    let dir = std::env::temp_dir().join(format!("hitkit-example-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A directory that does not exist.
    let missing = dir.join("no such directory").join("out.png");
    let error = check_output(&missing).unwrap_err();
    assert!(error.contains("no such directory"), "{error}");
    // A directory where the file should be.
    let error = check_output(&dir).unwrap_err();
    assert!(error.contains("is a directory"), "{error}");
    // A new file: writable, and not left behind by the check.
    let new: PathBuf = dir.join("new.png");
    check_output(&new).unwrap();
    assert!(!new.exists());
    // An existing file: writable, and not truncated by the check.
    let old = dir.join("old.png");
    std::fs::write(&old, b"keep").unwrap();
    check_output(&old).unwrap();
    assert_eq!(std::fs::read(&old).unwrap(), b"keep");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--flag=value` is taken as `--flag value` (so `--width=-5` is refused for its value,
/// naming it, not as an unknown option).
#[test]
fn flags_with_equals_are_taken() {
    let o = parse(&["--width=640", "--roulette=no"]).unwrap().unwrap();
    assert_eq!((o.width, o.roulette), (640, false));
    let error = parse(&["--width=-5"]).unwrap_err();
    assert!(
        error.starts_with("--width") && error.contains("-5"),
        "{error}"
    );
    let split = hitkit_render::cli::split_equals(["--obj=a=b.obj".to_string(), "x=y".to_string()]);
    assert_eq!(split, ["--obj", "a=b.obj", "x=y"]);
}

/// An OBJ file that cannot be read is refused with the operating system's reason, and one
/// whose faces are all degenerate with a word, not an empty image.
#[test]
fn obj_files_that_cannot_render_are_refused_saying_why() {
    // (A directory of its own: the tests of this file run side by side.)
    let dir = std::env::temp_dir().join(format!("hitkit-example-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("missing.obj");
    let reason = std::fs::File::open(&missing).unwrap_err().to_string();
    let error = hitkit_render::scenes::load_obj(&missing).unwrap_err();
    assert!(error.contains(&reason), "{error}");

    let flat = dir.join("flat.obj");
    std::fs::write(&flat, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    let error = hitkit_render::scenes::load_obj(&flat).unwrap_err();
    assert!(error.contains("degenerate"), "{error}");
    std::fs::remove_dir_all(&dir).unwrap();
}
