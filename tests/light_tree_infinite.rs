//! A sky beside many lamps in one `LightTree`: a light of unbounded box is an infinite
//! light, picked apart from the tree (each infinite light and the tree alike, as pbrt-v4's
//! `BVHLightSampler` picks), sampled on its own, and counted in every density.

mod support;

use std::f64::consts::PI;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Aabb, HitRecord, Hittable, Interval, LightTree, PdfHittable, Ray, ShadingContext};
use hitkit_render::halls::{self, Hall};
use support::{SplitMix, mean_and_error};

/// How far the sky's surface is: beyond every lamp of the halls.
const FAR: f64 = 1e6;

/// A sky of uniform radiance over the upper hemisphere, sampled by the cosine about `+Y`
/// (from any point), its surface at `FAR` along each upward direction.
struct Sky;

impl Hittable for Sky {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let d = ray.direction.normalize();
        let t = FAR / ray.direction.length();
        (d.y > 0.0 && ray_t.surrounds(t)).then(|| HitRecord::new(ray, t, ray.at(t), -d))
    }

    fn bounding_box(&self) -> Aabb {
        Aabb::UNIVERSE
    }
}

impl PdfHittable for Sky {
    fn pdf_value(&self, _: DVec3, direction: DVec3) -> f64 {
        (direction.y / direction.length()).max(0.0) / PI
    }

    fn sample_direction(&self, _: DVec3, u: DVec2) -> DVec3 {
        let (r, phi) = (u.x.sqrt(), 2.0 * PI * u.y);
        DVec3::new(r * phi.cos(), (1.0 - u.x).max(1e-12).sqrt(), r * phi.sin()).normalize()
    }
}

/// A hall's lamps and the sky (of power 1, the last light) in one tree, and the sky's
/// index.
fn with_sky(lamps: &halls::Lamps) -> (LightTree<Box<dyn PdfHittable>>, usize) {
    let mut all: Vec<Box<dyn PdfHittable>> = Vec::new();
    for q in &lamps.quads {
        all.push(Box::new(*q));
    }
    all.push(Box::new(Sky));
    let mut powers = lamps.powers.clone();
    powers.push(1.0);
    let mut emission = lamps.emission.clone();
    emission.push(hitkit::Emission::Everywhere);
    let sky = all.len() - 1;
    (LightTree::new(all, &powers, &emission).unwrap(), sky)
}

/// The sky is picked half the time (it and the tree alike), whatever its power; the
/// probabilities sum to 1; a pick's probability is `probability`'s bit for bit; a full
/// sample's density is `light_pdf`'s, and counts the sky; the tree's box holds the sky's.
#[test]
fn a_sky_is_picked_beside_the_tree() {
    let lamps = halls::lamps(Hall::Ceiling, 200, 1.0, 3);
    let (tree, sky) = with_sky(&lamps);
    assert!(!tree.bounding_box().is_bounded());
    let mut rng = SplitMix::new(5);
    for at in halls::floor_points(10, 1.0, 9) {
        assert_eq!(tree.probability(&at, sky), 0.5);
        let sum: f64 = (0..=sky).map(|i| tree.probability(&at, i)).sum();
        assert!((sum - 1.0).abs() <= 1e-12, "{sum}");
        let (mut skies, n) = (0, 2000);
        for k in 0..n {
            let pick = tree.pick(&at, (k as f64 + 0.5) / n as f64).unwrap();
            assert_eq!(pick.probability, tree.probability(&at, pick.light));
            skies += usize::from(pick.light == sky);
        }
        assert_eq!(skies, n / 2);
        let sample = tree
            .sample_light(&at, DVec2::new(rng.next_f64(), rng.next_f64()))
            .unwrap();
        assert_eq!(sample.pdf, tree.light_pdf(&at, sample.direction));
        // Straight up between the lamps, only the sky: half its density.
        let up = DVec3::new(0.013, 1.0, 0.007).normalize();
        let between = ShadingContext::on_surface(DVec3::new(0.01, 0.0, 0.01), DVec3::Y);
        assert_eq!(
            tree.light_pdf(&between, up),
            0.5 * Sky.pdf_value(between.point, up)
        );
    }
}

/// Next-event estimation by `pick` from floor points, the sky and the lamps together: the
/// mean within 4 standard errors of `PI L` (the sky's irradiance, `L = 1`, unoccluded)
/// plus the lamps' exact irradiance. And the full sample's estimate (`sample_light`: the
/// first light surface along the direction, which light it is, the full density) agrees
/// with the pick's where the pick's sky samples are seen past the lamps (a lamp in front of
/// the sky hides it from the full sample).
#[test]
fn a_sky_and_many_lamps_are_estimated_without_bias() {
    let lamps = halls::lamps(Hall::Room, 400, 1.0, 3);
    let (tree, sky) = with_sky(&lamps);
    let radiance = |i: usize, direction: DVec3| {
        if i == sky {
            1.0
        } else if -direction.dot(lamps.normals[i]) > 0.0 {
            lamps.radiance(i)
        } else {
            0.0
        }
    };
    let mut rng = SplitMix::new(11);
    for at in halls::floor_points(3, 1.0, 13) {
        let exact = PI
            + (0..lamps.quads.len())
                .map(|i| halls::irradiance(&lamps, i, &at))
                .sum::<f64>();
        let (mut by_pick, mut seen, mut by_sample) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..20_000 {
            let pick = tree.pick(&at, rng.next_f64()).unwrap();
            let u = DVec2::new(pick.rest, rng.next_f64());
            let light = &tree.lights()[pick.light];
            let (all, past_lamps) = light.sample_light(&at, u).map_or((0.0, 0.0), |s| {
                let value = radiance(pick.light, s.direction) * s.direction.y.max(0.0)
                    / (pick.probability * s.pdf);
                let ray = Ray::new(at.point, s.direction);
                let hidden =
                    pick.light == sky && lamps.quads.hit(&ray, Interval::FORWARD).is_some();
                (value, if hidden { 0.0 } else { value })
            });
            by_pick.push(all);
            seen.push(past_lamps);
            let u = DVec2::new(rng.next_f64(), rng.next_f64());
            by_sample.push(tree.sample_light(&at, u).map_or(0.0, |s| {
                radiance(s.light, s.direction) * s.direction.y.max(0.0) / s.pdf
            }));
        }
        let (mean, error) = mean_and_error(&by_pick);
        assert!(
            (mean - exact).abs() <= 4.0 * error,
            "pick at {}: {mean} +- {error} against {exact}",
            at.point
        );
        support::assert_same_mean(
            mean_and_error(&seen),
            mean_and_error(&by_sample),
            "the pick past the lamps and the full sample",
        );
    }
}
