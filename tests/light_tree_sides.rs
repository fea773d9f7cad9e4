//! `LightTree` keeps its word on the context's normal: it is a line, not a side. A normal
//! and its opposite give the same probabilities and samples bit for bit, every light that
//! can light the point on either side can be picked, and the probabilities sum to 1; and
//! emission normals and emitters of any finite size are accepted.

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::{Emission, LightTree, PdfHittable, Quad, ShadingContext, Sphere, TriangleMesh};
use hitkit_render::workloads::SplitMix;

mod support;
use proptest::prelude::*;

/// Whether every corner of a light's box lies strictly below the plane through `p` normal
/// to `n`: checked corner by corner.
fn wholly_below(light: &dyn PdfHittable, p: DVec3, n: DVec3) -> bool {
    let b = light.bounding_box();
    (0..8).all(|i| {
        let corner = DVec3::new(
            if i & 1 == 0 { b.min().x } else { b.max().x },
            if i & 2 == 0 { b.min().y } else { b.max().y },
            if i & 4 == 0 { b.min().z } else { b.max().z },
        );
        n.dot(corner - p) < 0.0
    })
}

/// A light of one of three kinds at `at`, of size `size`, turned by `turn`, as a scene
/// builds it: panels facing one way or both, and spheres.
fn light(kind: u8, at: DVec3, size: f64, turn: DQuat) -> (Box<dyn PdfHittable>, Emission) {
    let (u, v) = (turn * DVec3::X * size, turn * DVec3::Z * size);
    match kind % 3 {
        0 => (
            Box::new(Quad::new(at, u, v).unwrap()),
            Emission::OneSide(v.cross(u)),
        ),
        1 => (
            Box::new(Quad::new(at, u, v).unwrap()),
            Emission::BothSides(u.cross(v)),
        ),
        _ => (
            Box::new(Sphere::new(at, 0.5 * size).unwrap()),
            Emission::Everywhere,
        ),
    }
}

/// A light's kind, place, size, axis and angle of turn, and power.
type Spec = (u8, [f64; 3], f64, [f64; 3], f64, f64);

/// A room's worth of lights around the origin: ceiling panels, lamps on the floor and
/// walls, at random places, sizes and turns.
fn lights() -> impl Strategy<Value = Vec<Spec>> {
    prop::collection::vec(
        (
            any::<u8>(),
            prop::array::uniform3(-10.0f64..10.0),
            prop_oneof![Just(1e-3), 0.1f64..3.0],
            prop::array::uniform3(-1.0f64..1.0),
            0.0f64..std::f64::consts::TAU,
            (-3.0f64..3.0).prop_map(|e| 10f64.powf(e)),
        ),
        2..60,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Seen from a surface of any orientation: the normal's opposite gives the same
    /// probabilities and the same sample, bit for bit; the probabilities sum to 1 within
    /// their rounding (each a product of at most `2 n` shares, an ulp each, and the sum
    /// `n` more); and a light wholly below the horizon that faces the point (a sphere, or
    /// a panel with the point on its emitting side by a margin) has a positive
    /// probability: it lights the surface's other side.
    #[test]
    fn the_normals_side_never_matters(
        specs in lights(),
        p in prop::array::uniform3(-8.0f64..8.0),
        n in prop::array::uniform3(-1.0f64..1.0),
        u in prop::array::uniform2(0.0f64..1.0),
    ) {
        let (p, n) = (DVec3::from(p), DVec3::from(n));
        let Some(n) = n.try_normalize() else { return Ok(()) };
        let (mut built, mut emission, mut powers) = (Vec::new(), Vec::new(), Vec::new());
        for &(kind, at, size, axis, angle, power) in &specs {
            let turn = DQuat::from_axis_angle(DVec3::from(axis).normalize_or(DVec3::Y), angle);
            let (l, e) = light(kind, DVec3::from(at), size, turn);
            built.push(l);
            emission.push(e);
            powers.push(power);
        }
        let tree = LightTree::new(built, &powers, &emission).unwrap();
        let (up, down) = (ShadingContext::on_surface(p, n), ShadingContext::on_surface(p, -n));
        let mut sum = 0.0;
        for (i, light) in tree.lights().iter().enumerate() {
            let probability = tree.probability(&up, i);
            prop_assert_eq!(probability, tree.probability(&down, i), "light {}", i);
            sum += probability;
            let faces_p = match emission[i] {
                Emission::Everywhere => true,
                Emission::OneSide(m) => {
                    let b = light.bounding_box();
                    let centre = 0.5 * (b.min() + b.max());
                    m.normalize().dot(p - centre) > 0.1 * (b.max() - b.min()).length()
                        + 1e-3 * (p - centre).length()
                }
                Emission::BothSides(_) | Emission::Cone { .. } => false,
            };
            if wholly_below(light.as_ref(), p, n) && faces_p {
                prop_assert!(probability > 0.0, "light {} below the horizon, facing {}", i, p);
            }
        }
        let rounding = (3 * specs.len()) as f64 * f64::EPSILON;
        prop_assert!((sum - 1.0).abs() <= rounding, "sum {}", sum);
        let sample = tree.sample_light(&up, DVec2::from(u));
        prop_assert_eq!(sample, tree.sample_light(&down, DVec2::from(u)));
        if let Some(sample) = sample {
            prop_assert!(sample.pdf > 0.0);
            prop_assert_eq!(sample.pdf, tree.light_pdf(&up, sample.direction));
            prop_assert_eq!(sample.pdf, tree.light_pdf(&down, sample.direction));
        }
    }
}

/// The guide's floor (`Quad::new(q, X, Z)`, whose plane's normal is `X x Z = -Y`) given as
/// the context with that normal: the lamps above it are picked and sampled as from a floor
/// facing up. (Before the normal meant the lit side, every probability there was 0.)
#[test]
fn a_floor_whose_normal_points_down_gathers_the_light_above() {
    let floor = Quad::new(
        DVec3::new(-5.0, 0.0, -5.0),
        DVec3::X * 10.0,
        DVec3::Z * 10.0,
    )
    .unwrap();
    let lamps: Vec<Quad> = (0..8)
        .map(|i| {
            Quad::new(
                DVec3::new(f64::from(i) - 4.0, 3.0, -0.5),
                DVec3::X * 0.5,
                DVec3::Z * 0.5,
            )
        })
        .collect::<Result<_, _>>()
        .unwrap();
    let tree = LightTree::new(lamps, &[1.0; 8], &[Emission::OneSide(DVec3::NEG_Y); 8]).unwrap();
    let point = DVec3::new(0.3, 0.0, 0.1);
    let down = ShadingContext::on_surface(point, floor.plane().normal());
    let up = ShadingContext::on_surface(point, DVec3::Y);
    assert_eq!(floor.plane().normal(), DVec3::NEG_Y);
    for i in 0..8 {
        assert!(tree.probability(&down, i) > 0.0);
        assert_eq!(tree.probability(&down, i), tree.probability(&up, i));
    }
    let sample = tree.sample_light(&down, DVec2::new(0.3, 0.6)).unwrap();
    assert!(sample.pdf > 0.0 && sample.record.point.y == 3.0);
    assert!(tree.pick(&down, 0.3).is_some());
}

/// A tree whose only light lies wholly below a surface facing up (a lamp under a glass
/// floor, say): picked, with a density, as it is without the normal.
#[test]
fn a_light_wholly_below_the_horizon_is_sampled() {
    let lights = vec![Sphere::new(DVec3::new(0.0, -3.0, 0.0), 1.0).unwrap()];
    let tree = LightTree::new(lights, &[1.0], &[Emission::Everywhere]).unwrap();
    let up = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
    assert_eq!(tree.probability(&up, 0), 1.0);
    let sample = tree.sample_light(&up, DVec2::new(0.3, 0.6)).unwrap();
    assert!(sample.direction.y < 0.0);
    assert_eq!(
        tree.light_pdf(&up, DVec3::NEG_Y),
        tree.pdf_value(DVec3::ZERO, DVec3::NEG_Y)
    );
    assert!(tree.light_pdf(&up, DVec3::NEG_Y) > 0.0);
}

/// An emission normal of any finite, non-zero length is a direction: the same tree as with
/// the unit normal, for lengths whose squares overflow or underflow.
#[test]
fn emission_normals_of_any_finite_length_are_accepted() {
    let panel = || Quad::new(DVec3::new(0.0, 3.0, 0.0), DVec3::X, DVec3::Z).unwrap();
    let unit = LightTree::new(
        vec![panel(), panel()],
        &[1.0, 2.0],
        &[Emission::OneSide(DVec3::NEG_Y); 2],
    )
    .unwrap();
    let p = DVec3::new(0.3, 0.0, 0.2);
    for length in [1e160, 1e-300, 5e-324, f64::MAX] {
        for emission in [
            Emission::OneSide(DVec3::NEG_Y * length),
            Emission::BothSides(DVec3::NEG_Y * length),
        ] {
            let tree = LightTree::new(vec![panel(), panel()], &[1.0, 2.0], &[emission; 2])
                .unwrap_or_else(|e| panic!("{length:e}: {e}"));
            assert_eq!(
                tree.probability(&ShadingContext::at(p), 1),
                unit.probability(&ShadingContext::at(p), 1),
                "{length:e}"
            );
        }
        // A shading normal of that length too.
        assert_eq!(
            unit.probability(&ShadingContext::on_surface(p, DVec3::Y * length), 1),
            unit.probability(&ShadingContext::on_surface(p, DVec3::Y), 1),
            "{length:e}"
        );
    }
}

/// `from_mesh` of emitters that `TriangleMesh::new` accepts, from 1e-100 to 1e80 across.
#[test]
fn emitters_of_any_finite_size_make_a_light_tree() {
    for size in [1e-100, 1e-6, 1.0, 1e6, 1e80] {
        let corners = [DVec3::ZERO, DVec3::X * size, DVec3::Z * size];
        let mesh = TriangleMesh::new(&corners, &[[0, 1, 2]]).unwrap();
        for two_sided in [false, true] {
            let tree = LightTree::from_mesh(&mesh, 1.0, two_sided)
                .unwrap_or_else(|e| panic!("{size:e}: {e}"));
            let from = DVec3::new(0.25, 1.0, 0.25) * size;
            assert_eq!(tree.probability(&ShadingContext::at(from), 0), 1.0);
            let d = tree.sample_direction(from, DVec2::new(0.3, 0.4));
            assert!(tree.pdf_value(from, d) > 0.0, "{size:e}");
        }
    }
}

/// A light says which side it emits on (`PdfHittable::emission`): a quad the side of its
/// normal; an instance its object's side in world space, under rotations, shears, scales
/// and mirrors alike, checked against the hits it reports (a ray from a point on the
/// emitting side meets the front face, from the other side the back); a sphere everywhere;
/// `Masked` and pointers forward it. `LightTree::from_lights` takes these sides: the same
/// tree, probability for probability, as `LightTree::new` given them.
#[test]
fn lights_say_which_side_they_emit_on() {
    use hitkit::glam::DAffine3;
    use hitkit::{Hittable, Interval, Masked, Ray, Transformed};

    let quad = Quad::new(DVec3::new(-0.5, 0.0, -0.5), DVec3::X, DVec3::Z).unwrap();
    assert_eq!(quad.emission(), Emission::OneSide(DVec3::NEG_Y));
    let bulb = Sphere::new(DVec3::ZERO, 1.0).unwrap();
    assert_eq!(bulb.emission(), Emission::Everywhere);
    assert_eq!(Masked::new(quad, 0).emission(), quad.emission());
    let boxed: Box<dyn PdfHittable> = Box::new(quad);
    assert_eq!(boxed.emission(), quad.emission());

    let mut rng = SplitMix::new(7);
    let mut maps = vec![
        DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
        DAffine3::from_scale(DVec3::new(1.0, -2.0, 0.5)),
    ];
    for _ in 0..40 {
        let m = hitkit::glam::DMat3::from_cols(
            rng.direction() + DVec3::X,
            rng.direction() + DVec3::Y,
            rng.direction() + DVec3::Z,
        );
        maps.push(DAffine3::from_mat3_translation(m, rng.direction() * 10.0));
    }
    let mut instances = Vec::new();
    for map in maps {
        let Ok(lamp) = Transformed::affine(quad, map) else {
            continue;
        };
        let Emission::OneSide(normal) = lamp.emission() else {
            panic!("{map:?}: not one-sided")
        };
        // Square to the quad's edges in world space (the inverse transpose's rounding: a
        // few ulps of the products, against edges of length about 1).
        let n = normal.normalize();
        for edge in [DVec3::X, DVec3::Z] {
            let e = map.transform_vector3(edge);
            assert!(n.dot(e).abs() <= 1e-12 * e.length(), "{map:?}");
        }
        let centre = map.transform_point3(DVec3::ZERO);
        for (side, front) in [(1.0, true), (-1.0, false)] {
            let from = centre + side * normal.normalize();
            let hit = lamp
                .hit(&Ray::new(from, centre - from), Interval::FORWARD)
                .expect("the lamp's centre");
            assert_eq!(hit.front_face, front, "{map:?}");
        }
        instances.push(lamp);
    }
    let rigid = Transformed::new(quad, DQuat::from_rotation_x(0.7), DVec3::Y).unwrap();
    let Emission::OneSide(n) = rigid.emission() else {
        panic!()
    };
    assert!((n - DQuat::from_rotation_x(0.7) * DVec3::NEG_Y).length() < 1e-15);

    let powers: Vec<f64> = (0..instances.len()).map(|i| 1.0 + i as f64).collect();
    let emission: Vec<Emission> = instances.iter().map(|l| l.emission()).collect();
    let given = LightTree::new(instances.clone(), &powers, &emission).unwrap();
    let own = LightTree::from_lights(instances, &powers).unwrap();
    for _ in 0..20 {
        let at = ShadingContext::on_surface(rng.direction() * 12.0, rng.direction());
        for i in 0..powers.len() {
            assert_eq!(own.probability(&at, i), given.probability(&at, i));
        }
    }
}

/// A receiver that only reflects (`LightTree::sample_light_reflecting` and its siblings) on a wall of a room whose
/// lamps sit on the other three walls, facing in: the lamps behind it (the next room's,
/// on the other side of its wall, facing it) are never picked nor sampled, and the
/// irradiance it gathers, `E = sum of L cos+ / pdf`, is the same, within the estimates'
/// errors (four standard errors), as with the either-side tree, whose samples behind the
/// wall count 0: both estimate the one integral, the one-sided one with no sample wasted.
/// (Its standard error is not smaller here: the estimate's spread comes from the lamps
/// near the receiver, seen at grazing angles, which either tree picks alike.)
#[test]
fn a_receiver_that_only_reflects_never_picks_a_lamp_behind_it() {
    // The room: x and z in [-5, 5]; lamps on three of its walls at height 2, facing in;
    // and six beyond the fourth, x = 5, facing it.
    let mut lamps = Vec::new();
    let mut behind = Vec::new();
    for k in 0..6 {
        let s = f64::from(k) * 1.5 - 4.0;
        let h = DVec3::Y * 0.4;
        // On x = -5 facing +x, z = -5 facing +z, z = 5 facing -z.
        // (A quad emits from the side `u x v` points to.)
        lamps.push(Quad::new(DVec3::new(-4.99, 2.0, s), h, DVec3::Z * 0.4).unwrap());
        lamps.push(Quad::new(DVec3::new(s, 2.0, -4.99), DVec3::X * 0.4, h).unwrap());
        lamps.push(Quad::new(DVec3::new(s, 2.0, 4.99), h, DVec3::X * 0.4).unwrap());
        behind.push(lamps.len());
        // Behind the wall x = 5, facing it from the next room's far wall, lighting its
        // back.
        lamps.push(Quad::new(DVec3::new(7.0, 0.8, s), DVec3::Z * 0.4, h).unwrap());
    }
    let n = lamps.len();
    let tree = LightTree::from_lights(lamps, &vec![1.0; n]).unwrap();
    // On the wall x = 5, facing into the room.
    let point = DVec3::new(5.0, 1.0, 0.3);
    // The same context: the tree is asked from one side or from either.
    let wall = ShadingContext::on_surface(point, DVec3::NEG_X);
    let either = wall;
    for &i in &behind {
        assert_eq!(
            tree.probability_reflecting(&wall, i),
            0.0,
            "lamp {i} behind the wall"
        );
        assert!(tree.probability(&either, i) > 0.0);
    }
    let sum: f64 = (0..n).map(|i| tree.probability_reflecting(&wall, i)).sum();
    assert!((sum - 1.0).abs() < 1e-12, "{sum}");

    let mut rng = SplitMix::new(60);
    let (mut one, mut two) = (Vec::new(), Vec::new());
    for _ in 0..20_000 {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        one.push(at_most_front(tree.sample_light_reflecting(&wall, u)));
        two.push(at_most_front(tree.sample_light(&either, u)));
    }
    // No sample of the one-sided tree lies behind the wall.
    let mut rng = SplitMix::new(61);
    for _ in 0..2_000 {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        if let Some(s) = tree.sample_light_reflecting(&wall, u) {
            assert!(s.record.point.x < 5.0, "{}", s.record.point);
            // Its density is the one-sided walk's.
            assert_eq!(s.pdf, tree.light_pdf_reflecting(&wall, s.direction));
        }
    }
    let (a, b) = (support::mean_and_error(&one), support::mean_and_error(&two));
    assert!(
        (a.0 - b.0).abs() <= 4.0 * (a.1 * a.1 + b.1 * b.1).sqrt(),
        "one-sided {a:?}, either side {b:?}"
    );
    // No sample of the one-sided tree is wasted behind the wall; the either-side tree
    // spends about a third of its samples there, each worth 0.
    let wasted = |v: &[f64]| v.iter().filter(|&&x| x == 0.0).count();
    assert!(
        wasted(&one) == 0 && wasted(&two) > one.len() / 4,
        "{} {}",
        wasted(&one),
        wasted(&two)
    );
}

/// A sample's `cos+ / pdf` at a receiver on the wall x = 5 facing -x (the radiance 1 of a
/// lamp's front, 0 of its back): 0 for no sample.
fn at_most_front(sample: Option<hitkit::LightSample>) -> f64 {
    sample.map_or(0.0, |s| {
        let cos = (-s.direction.x).max(0.0);
        if s.record.front_face {
            cos / s.pdf
        } else {
            0.0
        }
    })
}

/// A tree of one lamp, wholly behind a surface that only reflects: never picked, no
/// sample, and a density of 0 in every direction (its sampling's, which has none), while
/// from either side it is picked always and its own density is the tree's.
#[test]
fn a_single_lamp_behind_a_reflecting_surface_has_no_density() {
    let lamp = Quad::new(DVec3::new(-0.5, -2.0, -0.5), DVec3::Z, DVec3::X).unwrap(); // faces up
    let tree = LightTree::from_lights(vec![lamp], &[1.0]).unwrap();
    let floor = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
    assert_eq!(tree.probability_reflecting(&floor, 0), 0.0);
    assert!(tree.pick_reflecting(&floor, 0.3).is_none());
    assert!(
        tree.sample_light_reflecting(&floor, DVec2::new(0.3, 0.6))
            .is_none()
    );
    let down = DVec3::NEG_Y;
    assert_eq!(tree.light_pdf_reflecting(&floor, down), 0.0);
    assert_eq!(tree.probability(&floor, 0), 1.0);
    assert!(tree.light_pdf(&floor, down) > 0.0);
    assert_eq!(
        tree.light_pdf(&floor, down),
        lamp.pdf_value(DVec3::ZERO, down)
    );
}
