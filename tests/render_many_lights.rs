//! Picking lights by importance must not bias the estimate: the many-lights hall rendered
//! with its lamps picked by a `LightTree` (seeing the shading normal), by a power-weighted
//! `Mixture` and uniformly converges to the same mean brightness (each is mixed with
//! cosine sampling by the renderer, which weighs a direction by the mixture's density: a
//! tree whose density disagreed with its sampling would show here); and the tree's
//! estimate has less variance per sample than the mixtures'.

mod support;

use hitkit_render::render::{Settings, render};
use hitkit_render::scenes::{Pick, hall_scene};
use support::assert_same_mean;

/// A short hall (40 rows: 160 panels and 20 sconces), small, for a debug build.
fn mean(pick: Pick, seed: u64) -> ((f64, f64), f64) {
    mean_of(hall_scene(32, 40, pick), seed)
}

/// The mean luminance of `scene` and its standard error, and its mean per-pixel variance.
fn mean_of<W: hitkit::Hittable>(scene: hitkit_render::Scene<W>, seed: u64) -> ((f64, f64), f64) {
    let settings = Settings {
        samples: 96,
        max_depth: 8,
        roulette: true,
        seed,
        threads: 0,
        progress: false,
    };
    let image = render(&scene, &settings, scene.effects()).unwrap();
    let variance = image.variance.iter().sum::<f64>() / image.variance.len() as f64;
    (image.mean_luminance(), variance)
}

/// Next-event estimation with multiple importance sampling (a shadow ray to a point on a
/// light, and a cosine-weighted bounce, weighed by the power heuristic) converges to the
/// mean of the book's one-sample mixture of the lights' and the material's densities,
/// which the hall was rendered with before: the shadow rays neither lose light (an end
/// found again) nor gain it (an occluder missed), and the weights sum to 1.
#[test]
fn next_event_estimation_keeps_the_mean_of_the_books_mixture() {
    let (next_event, _) = mean_of(hall_scene(32, 40, Pick::Tree), 4);
    let mut mixture = hall_scene(32, 40, Pick::Tree);
    mixture.next_event = false;
    let (mixture, _) = mean_of(mixture, 5);
    assert_same_mean(
        next_event,
        mixture,
        "next-event estimation against the mixture",
    );
}

#[test]
fn a_light_tree_a_mixture_and_a_uniform_choice_agree_on_the_hall() {
    let (tree, tree_variance) = mean(Pick::Tree, 1);
    let (power, power_variance) = mean(Pick::Power, 2);
    let (uniform, uniform_variance) = mean(Pick::Uniform, 3);
    assert_same_mean(tree, power, "tree against power-weighted mixture");
    assert_same_mean(tree, uniform, "tree against uniform mixture");
    // Per pixel and sample: the tree aims where the light comes from.
    assert!(
        tree_variance < power_variance && tree_variance < uniform_variance,
        "variance {tree_variance} by the tree, {power_variance} by power, {uniform_variance} uniformly"
    );
}
