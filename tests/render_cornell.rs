//! Light sampling must not bias the estimate: the Cornell box rendered with it and without
//! it converges to the same mean brightness.

#[path = "../examples/common/mod.rs"]
mod common;

use common::Effects;
use common::render::{Settings, render};
use common::scenes::cornell_scene;

#[test]
fn light_sampling_and_cosine_sampling_agree_on_the_mean_brightness() {
    let scene = cornell_scene(24);
    let settings = |seed| Settings {
        samples: 256,
        max_depth: 50,
        seed,
        threads: 0,
        progress: false,
    };
    let sampled = scene.effects();
    assert!(sampled.light_sampling && sampled.emission && !sampled.background);
    let unsampled = Effects {
        light_sampling: false,
        ..sampled
    };
    let (mean_a, se_a) = render(&scene, &settings(1), sampled)
        .unwrap()
        .mean_luminance();
    let (mean_b, se_b) = render(&scene, &settings(2), unsampled)
        .unwrap()
        .mean_luminance();
    // Both are unbiased estimates of the same mean; their difference has standard error
    // sqrt(se_a^2 + se_b^2), each estimated from the per-pixel sample variances. Four of
    // those leave a false alarm once in about 16,000 runs (normal tails; the path
    // contributions are heavy-tailed, which the sample variance only partly captures).
    let se = (se_a * se_a + se_b * se_b).sqrt();
    assert!(
        (mean_a - mean_b).abs() <= 4.0 * se,
        "with light sampling {mean_a} +- {se_a}, without {mean_b} +- {se_b}"
    );
    // The comparison means something only if the error is small against the mean.
    assert!(
        se < 0.05 * mean_a,
        "standard error {se} too large for mean {mean_a}"
    );
    // And light sampling is what makes this scene converge: it cuts the error.
    assert!(
        se_a < se_b,
        "light sampling {se_a} vs cosine sampling {se_b}"
    );
}
