//! Every light built from arbitrary numbers, sampled from an arbitrary point with an
//! arbitrary `u` of `[0, 1)^2` (corners included): the direction and its density are
//! never NaN or infinite (clause 4); where the light can be reached from the point at all,
//! every sampled direction has a positive density (clause 6); and a light sample's ray
//! finds the light at the distance it reports, with a positive, finite density, from a
//! surface receiving on either side and on one alone; and so do two copies of it in a
//! `LightTree`.

#![no_main]

use std::sync::Arc;

use hitkit::glam::DVec2;
use hitkit::{Hittable, Interval, LightTree, Mixture, PdfHittable, Ray, ShadingContext};
use hitkit_fuzz::LightInput;
use libfuzzer_sys::fuzz_target;

/// `k / 65536`, or the corner just below 1 for `u16::MAX`: every `u` in `[0, 1)`.
fn unit(k: u16) -> f64 {
    if k == u16::MAX {
        1.0f64.next_down()
    } else {
        f64::from(k) / 65536.0
    }
}

fuzz_target!(|input: LightInput| {
    let Some(light) = input.light.light() else {
        return;
    };
    let origin = input.origin.get();
    // Reachable: the middle of the square samples a direction of positive density (an
    // origin on the light's own plane, or the light past f64's reach, has none).
    let middle = light.sample_direction(origin, DVec2::splat(0.5));
    let reachable = light.pdf_value(origin, middle) > 0.0;
    // Two copies in a light tree: a walk that weighs the copies by the context.
    let pair = LightTree::from_lights(vec![light.clone(), light.clone()], &[1.0, 1.0]).ok();
    let at = match input.normal {
        Some(n) => ShadingContext::on_surface(origin, n.get()),
        None => ShadingContext::at(origin),
    };
    for &(x, y) in input
        .samples
        .iter()
        .take(16)
        .chain(&[(0, 0), (u16::MAX, u16::MAX)])
    {
        let u = DVec2::new(unit(x), unit(y));
        let d = light.sample_direction(origin, u);
        let pdf = light.pdf_value(origin, d);
        assert!(
            d.is_finite() && pdf.is_finite() && pdf >= 0.0,
            "u {u}: {d} {pdf}"
        );
        if reachable && origin.is_finite() {
            assert!(
                pdf > 0.0,
                "from {origin}, u {u}: direction {d} has density 0"
            );
        }
        // The light; the pair from a surface receiving on either side, and on its front
        // alone.
        let samples = [
            light.sample_light(&at, u),
            pair.as_ref().and_then(|p| p.sample_light(&at, u)),
            pair.as_ref()
                .and_then(|p| p.sample_light_reflecting(&at, u)),
        ];
        for (k, sample) in samples.into_iter().enumerate() {
            let Some(sample) = sample else { continue };
            assert!(sample.pdf > 0.0 && sample.pdf.is_finite(), "{sample:?}");
            assert!(
                sample.distance.is_finite() && sample.direction.is_finite(),
                "{sample:?}"
            );
            let ray = Ray::new(at.point, sample.direction);
            let hit = match (k, &pair) {
                (0, _) | (_, None) => light.hit(&ray, Interval::FORWARD),
                (_, Some(p)) => p.hit(&ray, Interval::FORWARD),
            };
            assert_eq!(hit.map(|h| h.t), Some(sample.distance), "{sample:?}");
        }
    }
    punctual(&input, light, &at);
});

/// A point, spot or sun alone and beside the light in a `LightTree`, a `Mixture` and a
/// list: every sample a delta one names is the punctual light's (finite, positive `pdf`,
/// a unit direction, a positive distance, finite but for a sun's), and every other the
/// light's, found at its distance; no density is NaN.
fn punctual(input: &LightInput, light: Arc<dyn PdfHittable>, at: &ShadingContext) {
    let Some(p) = input.punctual.and_then(|p| p.light()) else {
        return;
    };
    let both: Vec<Arc<dyn PdfHittable>> = vec![light, Arc::new(p)];
    let tree = LightTree::from_lights(both.clone(), &[1.0, 1.0]).ok();
    let mixture = Mixture::new(both.clone(), &[1.0, 1.0]).ok();
    for &(x, y) in input.samples.iter().take(8).chain(&[(0, 0)]) {
        let u = DVec2::new(unit(x), unit(y));
        let samples = [
            p.sample_light(at, u).map(|s| (s, None)),
            tree.as_ref().and_then(|t| {
                t.sample_light(at, u)
                    .map(|s| (s, Some(t as &dyn PdfHittable)))
            }),
            tree.as_ref().and_then(|t| {
                t.sample_light_reflecting(at, u)
                    .map(|s| (s, Some(t as &dyn PdfHittable)))
            }),
            mixture.as_ref().and_then(|m| {
                m.sample_light(at, u)
                    .map(|s| (s, Some(m as &dyn PdfHittable)))
            }),
            both.sample_light(at, u)
                .map(|s| (s, Some(&both as &dyn PdfHittable))),
        ];
        for (sample, of) in samples.into_iter().flatten() {
            assert!(sample.pdf > 0.0 && sample.pdf.is_finite(), "{sample:?}");
            assert!(sample.direction.is_finite(), "{sample:?}");
            if let Some(of) = of {
                let density = of.light_pdf(at, sample.direction);
                assert!(
                    density.is_finite() && density >= 0.0,
                    "{sample:?}: {density}"
                );
            }
            if sample.delta {
                assert!(of.is_none() || sample.light == 1, "{sample:?}");
                assert!(
                    (sample.direction.length() - 1.0).abs() < 1e-12,
                    "{sample:?}"
                );
                let sun = p.position().is_none();
                assert!(
                    sample.distance > 0.0 && (sun || sample.distance.is_finite()),
                    "{sample:?}"
                );
                continue;
            }
            assert_eq!(sample.light, 0, "{sample:?}");
            assert!(sample.distance.is_finite(), "{sample:?}");
        }
    }
}
