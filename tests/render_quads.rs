//! The example renderer on the book's quads scene: each wall shows its own colour where it
//! should, the book's flat background shows at the corners, and the image does not depend
//! on the thread count.

mod support;

use hitkit::glam::DVec3;
use hitkit_render::cli::to_rgb8;
use hitkit_render::render::{Rendered, Settings, render};
use hitkit_render::scenes::{QUADS_BACKGROUND, quads_scene};

const SIDE: usize = 48;

/// A quad's name, its centre, and what must hold of the colour seen there.
type Check = (&'static str, DVec3, fn(DVec3) -> bool);

fn settings(threads: usize) -> Settings {
    Settings {
        samples: 16,
        max_depth: 50,
        roulette: true,
        seed: 7,
        threads,
        progress: false,
    }
}

/// The pixel where a pinhole camera at (0, 0, 9) looking down -z with an 80 degree field of
/// view (the scene's) sees the point `p`.
fn pixel_of(p: DVec3) -> (usize, usize) {
    let d = p - DVec3::new(0.0, 0.0, 9.0);
    let half = 40f64.to_radians().tan();
    let (x, y) = (d.x / -d.z / half, d.y / -d.z / half);
    let i = ((x + 1.0) / 2.0 * SIDE as f64) as usize;
    let j = ((1.0 - y) / 2.0 * SIDE as f64) as usize;
    (i, j)
}

fn at(image: &Rendered, (i, j): (usize, usize)) -> DVec3 {
    image.pixels[j * image.width + i]
}

#[test]
fn each_wall_shows_its_colour_and_the_background_shows_at_the_corners() {
    let scene = quads_scene(SIDE);
    let image = render(&scene, &settings(0), scene.effects()).unwrap();
    // The centre of each quad, and which channel must dominate there.
    let checks: [Check; 5] = [
        ("left red", DVec3::new(-3.0, 0.0, 3.0), |c| {
            c.x > c.y && c.x > c.z
        }),
        ("back green", DVec3::new(0.0, 0.0, 0.0), |c| {
            c.y > c.x && c.y > c.z
        }),
        ("right blue", DVec3::new(3.0, 0.0, 3.0), |c| {
            c.z > c.x && c.z > c.y
        }),
        ("upper orange", DVec3::new(0.0, 3.0, 3.0), |c| {
            c.x > c.y && c.y > c.z
        }),
        ("lower teal", DVec3::new(0.0, -3.0, 3.0), |c| {
            c.y > c.x && c.z > c.x
        }),
    ];
    for (name, centre, dominated) in checks {
        let c = at(&image, pixel_of(centre));
        assert!(dominated(c), "{name} at {:?} is {c}", pixel_of(centre));
    }
    // Every ray through a corner pixel passes beside the quads (the corner's direction,
    // about (-0.84, 0.84, -1), leaves the box the quads span at z = 5.4), and a ray that
    // hits nothing returns the background exactly: the pixel is the mean of `samples`
    // equal values, which `samples` roundings of the running sum keep within
    // `gamma(samples)` of it (Higham 4.2), and the same byte in the PNG. The book's
    // image shows (214, 228, 255) there.
    let bound = support::gamma(settings(0).samples as u32);
    for corner in [(0, 0), (SIDE - 1, 0), (0, SIDE - 1), (SIDE - 1, SIDE - 1)] {
        let c = at(&image, corner);
        assert!(
            (c - QUADS_BACKGROUND).abs().max_element() <= bound,
            "corner {corner:?} is {c}"
        );
        assert_eq!(to_rgb8(c), [214, 228, 255], "corner {corner:?}");
    }
}

#[test]
fn the_same_seed_gives_the_same_image_with_any_thread_count() {
    let scene = quads_scene(16);
    let one = render(&scene, &settings(1), scene.effects()).unwrap();
    let two = render(&scene, &settings(2), scene.effects()).unwrap();
    assert_eq!(one.pixels, two.pixels);
    let other_seed = render(
        &scene,
        &Settings {
            seed: 8,
            ..settings(2)
        },
        scene.effects(),
    )
    .unwrap();
    assert_ne!(one.pixels, other_seed.pixels);
}

#[test]
fn the_quads_scene_calls_for_its_background_and_nothing_else() {
    let effects = quads_scene(8).effects();
    assert!(effects.background);
    assert!(!effects.emission && !effects.light_sampling && !effects.defocus);
}

/// Every effect forced on (what the render bench compares against) renders a scene that
/// has no lights to sample: light sampling finds none to aim at, and nothing is NaN. (The
/// forced lens draws its own random numbers, so the picture is not the same.)
#[test]
fn every_effect_forced_on_renders_a_scene_without_lights() {
    let scene = quads_scene(16);
    let all = render(&scene, &settings(1), hitkit_render::Effects::ALL).unwrap();
    assert!(all.pixels.iter().all(|c| c.is_finite()));
    assert!(all.mean_luminance().0 > 0.0);
}
