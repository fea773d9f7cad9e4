//! Point, spot and sun lights (`PunctualLight`): each alone gives its closed form (a point
//! light's irradiance is `I cos / d^2`, a spot's times glTF's falloff, a sun's `E cos`),
//! exactly, at any offset; in a `LightTree`, `Mixture` or list beside lights of area, the
//! estimate of every kind stays unbiased (the punctual part against its closed form, the
//! area part against the same lights without them), by next-event estimation and by the
//! book's sampling, which leaves them out; shadow rays reach them, to infinity for a sun;
//! and bad input is an error.

mod support;

use std::f64::consts::PI;

use hitkit::glam::{DMat3, DVec2, DVec3};
use hitkit::{
    Emission, GeometryError, HitRecord, Hittable, Interval, Light, LightTree, MaterialId, Mixture,
    PdfHittable, PunctualLight, Quad, Ray, ShadingContext,
};
use support::{SplitMix, assert_same_mean, mean_and_error};

/// The share glTF's spot sends at cosine `c` from its axis, written out apart from the
/// library: the square of the ramp from `cos outer` (0) to `cos inner` (1).
fn spot_share(c: f64, inner: f64, outer: f64) -> f64 {
    let t = (c - outer.cos()) / (inner.cos() - outer.cos());
    t.clamp(0.0, 1.0).powi(2)
}

/// The irradiance `intensity` (candela; lux for a sun) brings to `at` on a surface of
/// normal `n` from each kind, in closed form: `I f cos / d^2`, `E cos`, cosine clamped at 0.
fn closed_form(kind: &Kind, at: DVec3, n: DVec3) -> f64 {
    match *kind {
        Kind::Point { at: p, intensity } => {
            let v = p - at;
            intensity * (v.normalize().dot(n)).max(0.0) / v.length_squared()
        }
        Kind::Spot {
            at: p,
            axis,
            inner,
            outer,
            intensity,
        } => {
            let v = p - at;
            let f = spot_share((-v.normalize()).dot(axis.normalize()), inner, outer);
            intensity * f * (v.normalize().dot(n)).max(0.0) / v.length_squared()
        }
        Kind::Sun { toward, lux } => lux * toward.normalize().dot(n).max(0.0),
    }
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Point {
        at: DVec3,
        intensity: f64,
    },
    Spot {
        at: DVec3,
        axis: DVec3,
        inner: f64,
        outer: f64,
        intensity: f64,
    },
    Sun {
        toward: DVec3,
        lux: f64,
    },
}

impl Kind {
    fn light(&self) -> PunctualLight {
        match *self {
            Kind::Point { at, .. } => PunctualLight::point(at).unwrap(),
            Kind::Spot {
                at,
                axis,
                inner,
                outer,
                ..
            } => PunctualLight::spot(at, axis, inner, outer).unwrap(),
            Kind::Sun { toward, .. } => PunctualLight::sun(-toward).unwrap(),
        }
    }

    fn emitted(&self) -> f64 {
        match *self {
            Kind::Point { intensity, .. } | Kind::Spot { intensity, .. } => intensity,
            Kind::Sun { lux, .. } => lux,
        }
    }
}

/// Relative agreement allowed between the library's `emitted cos / pdf` and the closed
/// form: both start from the same difference of positions; the library's unit vector and
/// length (`v / |v|`, `|v|^2` of the rounded length) and the test's (`normalize`,
/// `length_squared`) differ by a few ulps each: 1e-14 is some 45 ulps.
const EXACT: f64 = 1e-14;

/// The spot's ramp besides: the cosine from its axis is off by a few ulps of 1 (a dot
/// product of two unit vectors, each a few ulps off), and `t^2` moves by at most
/// `2 / (cos inner - cos outer)` times that, an absolute error of the share that is large
/// against a share near 0 at the cone's edge: `16 eps / (cos inner - cos outer)` of the
/// unattenuated irradiance is twice `2 * 4 eps` of it.
fn ramp_slack(kind: &Kind, at: DVec3, n: DVec3) -> f64 {
    match *kind {
        Kind::Spot {
            at: p,
            inner,
            outer,
            intensity,
            ..
        } => {
            let v = p - at;
            let unattenuated = intensity * v.normalize().dot(n).max(0.0) / v.length_squared();
            16.0 * f64::EPSILON / (inner.cos() - outer.cos()) * unattenuated
        }
        _ => 0.0,
    }
}

#[test]
fn each_kind_alone_gives_its_closed_form_at_any_offset() {
    let mut rng = SplitMix::new(7);
    let mut spots_in_ramp = 0;
    for &offset in &[0.0, 1234.567, 3.3e6 + 0.7, 1.1e9 + 0.3] {
        for _ in 0..400 {
            let centre = DVec3::splat(offset) + rng.direction() * 0.5;
            let rotation = DMat3::from_axis_angle(rng.direction(), 6.0 * rng.next_f64());
            let n = rotation * DVec3::Y;
            let at =
                centre + rotation * DVec3::new(rng.next_f64() - 0.5, 0.0, rng.next_f64() - 0.5);
            let above = centre + rotation * (DVec3::new(0.0, 2.0, 0.0) + rng.direction() * 0.8);
            let inner = 0.05 + 0.3 * rng.next_f64();
            let outer = inner + 0.1 + 0.5 * rng.next_f64();
            // The spot aimed near the point, so that many samples fall in its ramp.
            let axis = (at - above).normalize() + rng.direction() * 0.3;
            let kinds = [
                Kind::Point {
                    at: above,
                    intensity: 15.0,
                },
                Kind::Spot {
                    at: above,
                    axis,
                    inner,
                    outer,
                    intensity: 80.0,
                },
                Kind::Sun {
                    toward: rotation * (DVec3::Y + rng.direction() * 0.9),
                    lux: 3.0,
                },
            ];
            let ctx = ShadingContext::on_surface(at, n);
            for kind in &kinds {
                let expected = closed_form(kind, at, n);
                let light = kind.light();
                let sample = light.sample_light(&ctx, DVec2::new(rng.next_f64(), rng.next_f64()));
                let Some(s) = sample else {
                    // Only a spot's point outside its cone has no sample.
                    assert!(
                        matches!(kind, Kind::Spot { .. }) && expected == 0.0,
                        "{kind:?}"
                    );
                    continue;
                };
                assert!(
                    s.delta && s.pdf > 0.0 && s.pdf.is_finite(),
                    "{kind:?}: {s:?}"
                );
                assert_eq!(light.light_pdf(&ctx, s.direction), 0.0);
                assert_eq!(light.pdf_value(at, s.direction), 0.0);
                assert_eq!(
                    light.sample_direction(at, DVec2::new(0.3, 0.3)),
                    DVec3::ZERO
                );
                let got = kind.emitted() * s.direction.dot(n).max(0.0) / s.pdf;
                assert!(
                    (got - expected).abs() <= EXACT * expected + ramp_slack(kind, at, n),
                    "{kind:?} from {at}: {got} against {expected}"
                );
                if let Kind::Spot { .. } = kind {
                    let c = (-s.direction).dot(axis.normalize());
                    spots_in_ramp += usize::from(c > outer.cos() && c < inner.cos());
                }
                // The record: on the light (or the unit direction to a sun), facing back.
                assert_eq!(s.record.normal, -s.direction);
                assert!(s.record.front_face);
                match light.position() {
                    Some(p) => assert_eq!((s.record.point, s.record.t), (p, s.distance)),
                    None => assert_eq!(
                        (s.record.point, s.distance, s.record.t),
                        (s.direction, f64::INFINITY, f64::INFINITY)
                    ),
                }
            }
        }
    }
    // The falloff's ramp itself was tested, not only its two flat ends.
    assert!(spots_in_ramp > 300, "{spots_in_ramp}");
}

/// The falloff and the units pinned by hand: a test that a linear ramp, a missing square
/// or an irradiance in the wrong units (`I / d` or `4 PI I / d^2`) fails.
#[test]
fn falloff_and_units_by_hand() {
    let spot = PunctualLight::spot(DVec3::new(0.0, 2.0, 0.0), DVec3::NEG_Y, 0.0, PI / 3.0).unwrap();
    // From (x, 0, 0), the cosine from the axis is 2 / sqrt(x^2 + 4): at x = 2 / sqrt(3),
    // c = sqrt(3) / 2, a share t = (c - cos 60) / (1 - cos 60) of the ramp.
    let x = 2.0 / 3f64.sqrt();
    let ctx = ShadingContext::on_surface(DVec3::new(x, 0.0, 0.0), DVec3::Y);
    let s = spot.sample_light(&ctx, DVec2::ZERO).unwrap();
    let c = 3f64.sqrt() / 2.0;
    let t: f64 = (c - 0.5) / 0.5;
    let d2 = x * x + 4.0;
    // Irradiance of 10 cd there: 10 t^2 cos / d^2, cos = c at the floor too.
    let e = 10.0 * s.direction.dot(DVec3::Y) / s.pdf;
    assert!((e - 10.0 * t * t * c / d2).abs() < 1e-14, "{e}");
    assert!(
        (e - 10.0 * t * c / d2).abs() > 0.1 * e,
        "a linear ramp would pass"
    );
    // A sun of 5 lux at 60 degrees from the normal: 2.5.
    let sun = PunctualLight::sun(DVec3::new(-(3f64.sqrt()), -1.0, 0.0)).unwrap();
    let s = sun.sample_light(&ctx, DVec2::ZERO).unwrap();
    assert!((5.0 * s.direction.dot(DVec3::Y) / s.pdf - 2.5).abs() < 1e-15);
    // The power a tree weighs by: 4 PI I for a point; a spot's integral of its falloff.
    let point = PunctualLight::point(DVec3::ZERO).unwrap();
    assert!((point.power(2.0) - 8.0 * PI).abs() < 1e-14);
    let mut rng = SplitMix::new(3);
    let n = 400_000;
    let integral: f64 = (0..n)
        .map(|_| 4.0 * PI * spot.falloff(rng.direction()))
        .sum::<f64>()
        / n as f64;
    // A Monte Carlo integral over the sphere: its error is about 4 PI sqrt(p (1 - p) / n)
    // for the quarter of the sphere the cone covers, 0.006: 0.03 is five of that.
    assert!(
        (spot.power(1.0) - integral).abs() < 0.03,
        "{} {integral}",
        spot.power(1.0)
    );
}

/// A hall with every kind: 24 panels facing down, 8 points, 4 spots and a sun.
struct Hall {
    panels: Vec<Quad>,
    kinds: Vec<Kind>,
}

fn hall() -> Hall {
    let mut rng = SplitMix::new(11);
    let mut panels = Vec::new();
    for i in 0..24 {
        let q = DVec3::new(
            f64::from(i % 6) * 3.0 - 8.0,
            4.0,
            f64::from(i / 6) * 3.0 - 5.0,
        );
        panels.push(
            Quad::new(q, DVec3::X * 0.9, DVec3::Z * 0.7)
                .unwrap()
                .with_material(MaterialId(1)),
        );
    }
    let mut kinds = Vec::new();
    for _ in 0..8 {
        kinds.push(Kind::Point {
            at: DVec3::new(
                16.0 * rng.next_f64() - 8.0,
                1.0 + 2.0 * rng.next_f64(),
                12.0 * rng.next_f64() - 6.0,
            ),
            intensity: 5.0 + 20.0 * rng.next_f64(),
        });
    }
    for _ in 0..4 {
        let at = DVec3::new(
            16.0 * rng.next_f64() - 8.0,
            3.5,
            12.0 * rng.next_f64() - 6.0,
        );
        kinds.push(Kind::Spot {
            at,
            axis: DVec3::NEG_Y + rng.direction() * 0.4,
            inner: 0.2,
            outer: 0.7,
            intensity: 60.0,
        });
    }
    kinds.push(Kind::Sun {
        toward: DVec3::new(0.3, 1.0, 0.2),
        lux: 2.0,
    });
    Hall { panels, kinds }
}

impl Hall {
    /// Its panels, then its punctual lights, and their powers (a panel's the flux of its
    /// radiance; a punctual light's [`PunctualLight::power`]).
    fn lights(&self) -> (Vec<Light<Quad>>, Vec<f64>) {
        let lights = self
            .panels
            .iter()
            .map(|&q| Light::Surface(q))
            .chain(self.kinds.iter().map(|k| Light::Punctual(k.light())))
            .collect();
        let panels = self.panels.iter().map(|q| PI * RADIANCE * q.area());
        let punctual = self.kinds.iter().map(|k| k.light().power(k.emitted()));
        (lights, panels.chain(punctual).collect())
    }
}

/// A panel's radiance (its front side, facing down, alone emits).
const RADIANCE: f64 = 4.0;

/// One next-event estimate of the irradiance at `ctx` (normal `n`) from `lights`: the
/// punctual part (`delta` samples, by their kind's emitted value) and the area part.
fn estimate(
    sample: Option<hitkit::LightSample>,
    n: DVec3,
    emitted: impl Fn(usize) -> f64,
) -> (f64, f64) {
    let Some(s) = sample else { return (0.0, 0.0) };
    let cos = s.direction.dot(n).max(0.0);
    if s.delta {
        (emitted(s.light) * cos / s.pdf, 0.0)
    } else if s.record.front_face {
        (0.0, RADIANCE * cos / s.pdf)
    } else {
        (0.0, 0.0)
    }
}

#[test]
fn every_kind_beside_area_lights_stays_unbiased() {
    let hall = hall();
    let (lights, powers) = hall.lights();
    let tree = LightTree::from_lights(lights.clone(), &powers).unwrap();
    let mixture = Mixture::new(lights.clone(), &powers).unwrap();
    let panels_only =
        LightTree::from_lights(hall.panels.clone(), &powers[..hall.panels.len()]).unwrap();
    let first = hall.panels.len();
    let emitted = |i: usize| hall.kinds[i - first].emitted();
    let mut rng = SplitMix::new(5);
    for point in [
        DVec3::new(0.3, 0.0, 0.2),
        DVec3::new(-6.0, 0.0, 4.5),
        DVec3::new(7.0, 0.0, -5.5),
    ] {
        let n = DVec3::Y;
        let ctx = ShadingContext::on_surface(point, n);
        let exact: f64 = hall.kinds.iter().map(|k| closed_form(k, point, n)).sum();
        let reference: Vec<f64> = (0..100_000)
            .map(|_| {
                let u = DVec2::new(rng.next_f64(), rng.next_f64());
                estimate(panels_only.sample_light(&ctx, u), n, |_| 0.0).1
            })
            .collect();
        let reference = mean_and_error(&reference);
        // The mixture and the list pick by power alone, everywhere: more samples for the
        // same error.
        for (name, sampler, count) in [
            ("tree", &tree as &dyn PdfHittable, 100_000),
            ("mixture", &mixture, 300_000),
            ("list", &lights, 300_000),
        ] {
            let (mut delta, mut area) = (Vec::new(), Vec::new());
            for _ in 0..count {
                let u = DVec2::new(rng.next_f64(), rng.next_f64());
                let (d, a) = estimate(sampler.sample_light(&ctx, u), n, emitted);
                delta.push(d);
                area.push(a);
            }
            let (mean, se) = mean_and_error(&delta);
            assert!(
                (mean - exact).abs() <= 4.0 * se && se < 0.05 * exact,
                "{name} at {point}: punctual {mean} +- {se} against {exact}"
            );
            assert_same_mean(
                mean_and_error(&area),
                reference,
                &format!("{name} at {point}: area part"),
            );
            // A direction toward a panel has the density its sample says, the punctual
            // lights taking their share of picks and none of the density.
            for _ in 0..200 {
                let u = DVec2::new(rng.next_f64(), rng.next_f64());
                if let Some(s) = sampler.sample_light(&ctx, u).filter(|s| !s.delta) {
                    let pdf = sampler.light_pdf(&ctx, s.direction);
                    assert!(
                        (pdf - s.pdf).abs() <= 1e-12 * s.pdf,
                        "{name}: {pdf} {}",
                        s.pdf
                    );
                }
            }
        }
    }
}

/// The book's level (`sample_direction`, `pdf_value`) leaves punctual lights out: a pick
/// of one gives no direction (a sample of weight 0), and the density counts the lights of
/// area alone, so the estimate of the panels' light is what it is without them.
#[test]
fn the_books_sampling_leaves_punctual_lights_out_unbiased() {
    let hall = hall();
    let (lights, powers) = hall.lights();
    let tree = LightTree::from_lights(lights, &powers).unwrap();
    let panels_only =
        LightTree::from_lights(hall.panels.clone(), &powers[..hall.panels.len()]).unwrap();
    let point = DVec3::new(0.3, 0.0, 0.2);
    let estimate = |light: &dyn PdfHittable, u: DVec2| {
        let d = light.sample_direction(point, u);
        if d == DVec3::ZERO {
            return 0.0;
        }
        let ray = Ray::new(point, d);
        match hall.panels.hit(&ray, Interval::FORWARD) {
            Some(hit) if hit.front_face => {
                RADIANCE * d.normalize().dot(DVec3::Y).max(0.0) / light.pdf_value(point, d)
            }
            _ => 0.0,
        }
    };
    let mut rng = SplitMix::new(9);
    let (mut with, mut without, mut none) = (Vec::new(), Vec::new(), 0);
    for _ in 0..200_000 {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        none += usize::from(tree.sample_direction(point, u) == DVec3::ZERO);
        with.push(estimate(&tree, u));
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        without.push(estimate(&panels_only, u));
    }
    assert!(none > 1000, "the punctual lights were picked {none} times");
    assert_same_mean(
        mean_and_error(&with),
        mean_and_error(&without),
        "book's sampling",
    );
}

#[test]
fn shadow_rays_reach_every_kind_at_any_offset() {
    for offset in [0.0, 1234.567, 1.1e9 + 0.3] {
        let o = DVec3::splat(offset);
        let floor = Quad::new(
            o + DVec3::new(-5.0, 0.0, -5.0),
            DVec3::X * 10.0,
            DVec3::Z * 10.0,
        )
        .unwrap();
        let down = Ray::new(o + DVec3::new(0.3, 5.0, 0.2), DVec3::NEG_Y);
        let hit = floor.hit(&down, Interval::FORWARD).unwrap();
        let ctx = ShadingContext::from(&hit);
        let between = Quad::new(
            o + DVec3::new(-1.0, 1.0, -1.0),
            DVec3::X * 2.0,
            DVec3::Z * 2.0,
        )
        .unwrap();
        let far_up = Quad::new(
            o + DVec3::new(-1e3, 1e6, -1e3),
            DVec3::X * 2e3,
            DVec3::Z * 2e3,
        )
        .unwrap();
        let beside = Quad::new(o + DVec3::new(3.0, 1.0, -1.0), DVec3::X, DVec3::Z * 2.0).unwrap();
        let point = PunctualLight::point(o + DVec3::new(0.3, 2.0, 0.2)).unwrap();
        let sun = PunctualLight::sun(DVec3::NEG_Y).unwrap();
        for (light, blockers) in [(point, [&between, &beside]), (sun, [&far_up, &beside])] {
            let s = light.sample_light(&ctx, DVec2::ZERO).unwrap();
            let (ray, range) = hit.spawn_ray_to(&s.record);
            assert!(
                !floor.occluded(&ray, range),
                "the floor it leaves, at {offset}"
            );
            assert!(
                blockers[0].occluded(&ray, range),
                "{light:?} at {offset}: not blocked"
            );
            assert!(!blockers[1].occluded(&ray, range), "{light:?} at {offset}");
        }
        // Past the point light, nothing occludes it.
        let s = point.sample_light(&ctx, DVec2::ZERO).unwrap();
        let (ray, range) = hit.spawn_ray_to(&s.record);
        assert!(!far_up.occluded(&ray, range));
    }
}

#[test]
fn a_reflecting_surface_never_picks_a_lamp_behind_it() {
    let under = PunctualLight::point(DVec3::new(0.0, -1.0, 0.0)).unwrap();
    let over = PunctualLight::point(DVec3::new(0.0, 1.0, 0.0)).unwrap();
    let tree = LightTree::from_lights(vec![under, over], &[1.0, 1.0]).unwrap();
    let floor = ShadingContext::on_surface(DVec3::new(0.2, 0.0, 0.1), DVec3::Y);
    assert_eq!(tree.probability_reflecting(&floor, 0), 0.0);
    assert_eq!(tree.probability_reflecting(&floor, 1), 1.0);
    for k in 0..100 {
        let u = DVec2::new(f64::from(k) / 100.0, 0.5);
        let s = tree.sample_light_reflecting(&floor, u).unwrap();
        assert_eq!((s.light, s.delta), (1, true));
    }
    // A tree bounds a spot by its cone: one whose cone misses the floor point (though the
    // point lies on the side its axis faces) is never picked there.
    let aside = PunctualLight::spot(DVec3::Y, DVec3::X, 0.1, 0.2).unwrap();
    let tree = LightTree::from_lights(vec![aside, over], &[1.0, 1.0]).unwrap();
    assert_eq!(tree.probability(&floor, 0), 0.0);
    assert_eq!(
        tree.lights()[0].emission(),
        Emission::Cone {
            axis: DVec3::X,
            angle: 0.2
        }
    );
    // A spot seen from outside its cone gives no sample; so does its own position.
    let spot = PunctualLight::spot(DVec3::Y, DVec3::X, 0.1, 0.2).unwrap();
    assert!(spot.sample_light(&floor, DVec2::ZERO).is_none());
    assert!(
        over.sample_light(&ShadingContext::at(DVec3::Y), DVec2::ZERO)
            .is_none()
    );
    assert!(
        over.sample_light(&ShadingContext::at(DVec3::NAN), DVec2::ZERO)
            .is_none()
    );
    // A sun alone in a tree is its infinite light.
    let sun =
        LightTree::from_lights(vec![PunctualLight::sun(DVec3::NEG_Y).unwrap()], &[1.0]).unwrap();
    let s = sun.sample_light(&floor, DVec2::new(0.7, 0.1)).unwrap();
    assert_eq!((s.direction, s.pdf, s.delta), (DVec3::Y, 1.0, true));
    assert_eq!(sun.bounding_box(), hitkit::Aabb::UNIVERSE);
    assert_eq!(sun.lights()[0].emission(), Emission::Everywhere);
}

#[test]
fn bad_input_is_an_error() {
    let nan = DVec3::new(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        PunctualLight::point(nan),
        Err(GeometryError::NonFinite { .. })
    ));
    assert!(matches!(
        PunctualLight::sun(DVec3::ZERO),
        Err(GeometryError::ZeroVector { .. })
    ));
    assert!(matches!(
        PunctualLight::sun(nan),
        Err(GeometryError::NonFinite { .. })
    ));
    let spot = |inner: f64, outer: f64| PunctualLight::spot(DVec3::ZERO, DVec3::Y, inner, outer);
    assert!(spot(0.0, 0.5).is_ok() && spot(0.5, 0.5).is_ok() && spot(0.0, PI / 2.0).is_ok());
    for (inner, outer) in [
        (0.0, 0.0),
        (0.6, 0.5),
        (-0.1, 0.5),
        (0.0, 1.6),
        (0.0, f64::NAN),
    ] {
        assert!(spot(inner, outer).is_err(), "{inner} {outer}");
    }
    assert!(PunctualLight::spot(DVec3::ZERO, DVec3::ZERO, 0.1, 0.2).is_err());
    // A cone the tree cannot bound.
    let quad = || Quad::new(DVec3::ZERO, DVec3::X, DVec3::Z).unwrap();
    for angle in [0.0, 2.0, f64::NAN] {
        let cone = Emission::Cone {
            axis: DVec3::Y,
            angle,
        };
        assert!(matches!(
            LightTree::new(vec![quad()], &[1.0], &[cone]),
            Err(GeometryError::InvalidParameter { .. })
        ));
    }
    let zero = Emission::Cone {
        axis: DVec3::ZERO,
        angle: 0.5,
    };
    assert!(LightTree::new(vec![quad()], &[1.0], &[zero]).is_err());
    // What a record at infinity makes of a hit whose ray is not valid: an empty range.
    let r = Ray::new(DVec3::ZERO, DVec3::Y);
    let hit = HitRecord::new(&r, 1.0, DVec3::Y, DVec3::NEG_Y);
    let sun = PunctualLight::sun(DVec3::NEG_Y).unwrap();
    let s = sun
        .sample_light(&ShadingContext::from(&hit), DVec2::ZERO)
        .unwrap();
    let (ray, range) = hit.spawn_ray_to(&s.record);
    assert!(ray.direction == DVec3::Y && range == Interval::FORWARD);
}

/// Through an instance, a punctual light moves with the map: under a rigid one it samples
/// as the same light placed in the world does (a point, a spot turned with it, a sun
/// turned), its `pdf` within a few ulps; under a scale, its position is the mapped one
/// and its falloff its own.
#[test]
fn an_instance_moves_a_punctual_light() {
    use hitkit::Transformed;
    use hitkit::glam::DQuat;
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
    let shift = DVec3::new(1e6 + 0.3, -2.5, 7.0);
    let local_spot =
        PunctualLight::spot(DVec3::new(0.5, 2.0, 0.0), DVec3::NEG_Y, 0.2, 0.9).unwrap();
    let cases = [
        (
            PunctualLight::point(DVec3::new(0.5, 2.0, 0.0)).unwrap(),
            PunctualLight::point(turn * DVec3::new(0.5, 2.0, 0.0) + shift).unwrap(),
        ),
        (
            local_spot,
            PunctualLight::spot(
                turn * DVec3::new(0.5, 2.0, 0.0) + shift,
                turn * DVec3::NEG_Y,
                0.2,
                0.9,
            )
            .unwrap(),
        ),
        (
            PunctualLight::sun(DVec3::new(0.3, -1.0, 0.1)).unwrap(),
            PunctualLight::sun(turn * DVec3::new(0.3, -1.0, 0.1)).unwrap(),
        ),
    ];
    let mut rng = SplitMix::new(21);
    for (local, world) in cases {
        let placed = Transformed::new(local.with_material(MaterialId(4)), turn, shift)
            .unwrap()
            .with_instance_id(9);
        for _ in 0..200 {
            let at = shift
                + turn * DVec3::new(rng.next_f64() * 2.0 - 1.0, 0.0, rng.next_f64() * 2.0 - 1.0);
            let ctx = ShadingContext::at(at);
            let (a, b) = (
                placed.sample_light(&ctx, DVec2::ZERO),
                world.sample_light(&ctx, DVec2::ZERO),
            );
            let (Some(a), Some(b)) = (a, b) else {
                // Both or neither: only a spot's edge, where a few ulps decide, may differ.
                assert!(
                    a.is_none() && b.is_none() || local == local_spot,
                    "{a:?} {b:?}"
                );
                continue;
            };
            // The two positions are rounded apart (the instance's matrix against the
            // quaternion), each within a few ulps of the 1e6 shift: 4 ulps is 1e-9 at a
            // distance of at least 1.5, twice that in the squared distance the `pdf` holds.
            assert!(
                a.delta && (a.pdf - b.pdf).abs() <= 4e-9 * b.pdf,
                "{a:?} {b:?}"
            );
            assert!((a.direction - b.direction).length() < 2e-9, "{a:?} {b:?}");
            assert_eq!(
                (a.record.material, a.record.instance),
                (MaterialId(4), Some(9))
            );
        }
    }
    // Scaled by 3 about the origin: the point light 3 times as far, the same falloff.
    let scaled = Transformed::affine(
        PunctualLight::point(DVec3::Y).unwrap(),
        hitkit::glam::DAffine3::from_scale(DVec3::splat(3.0)),
    )
    .unwrap();
    let s = scaled
        .sample_light(&ShadingContext::at(DVec3::ZERO), DVec2::ZERO)
        .unwrap();
    assert_eq!(
        (s.record.point, s.distance, s.pdf),
        (DVec3::new(0.0, 3.0, 0.0), 3.0, 9.0)
    );
    // In a tree, an instanced lamp is picked and sampled as any light.
    let tree = LightTree::from_lights(vec![scaled, scaled], &[1.0, 1.0]).unwrap();
    let s = tree
        .sample_light(&ShadingContext::at(DVec3::ZERO), DVec2::new(0.7, 0.2))
        .unwrap();
    assert!(
        s.delta && (s.pdf - 4.5).abs() < 1e-12 && s.light == 1,
        "{s:?}"
    );
}

/// Many point lights make a tree of boxes of no extent: a grid of them on one plane and a
/// crowd at one position build (the heuristic's costs of no area split them all the
/// same), and from anywhere the probabilities of the picks sum to 1.
#[test]
fn a_crowd_of_point_lights_makes_a_tree() {
    let mut lamps = Vec::new();
    for i in 0..30 {
        for j in 0..30 {
            lamps.push(PunctualLight::point(DVec3::new(f64::from(i), 3.0, f64::from(j))).unwrap());
        }
    }
    lamps.extend((0..64).map(|_| PunctualLight::point(DVec3::new(5.0, 2.0, 5.0)).unwrap()));
    let powers = vec![1.0; lamps.len()];
    let tree = LightTree::from_lights(lamps, &powers).unwrap();
    for at in [
        DVec3::new(5.0, 2.0, 5.0),
        DVec3::new(-3.0, 0.0, 40.0),
        DVec3::new(14.5, 3.0, 14.5),
    ] {
        for ctx in [
            ShadingContext::at(at),
            ShadingContext::on_surface(at, DVec3::Y),
        ] {
            let sum: f64 = (0..tree.lights().len())
                .map(|i| tree.probability(&ctx, i))
                .sum();
            // 964 products of a dozen rounded factors each: far within 1e-9 of 1.
            assert!((sum - 1.0).abs() < 1e-9, "{at}: {sum}");
            let s = tree.sample_light(&ctx, DVec2::new(0.37, 0.5));
            assert!(s.is_none_or(|s| s.delta && s.pdf.is_finite() && s.pdf > 0.0));
        }
    }
}
