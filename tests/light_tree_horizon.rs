//! `LightTree` keeps its word: seen from a surface (`with_normal`), no light whose box lies
//! wholly below the horizon is ever picked, and emission normals and emitters of any finite
//! size are accepted.

use hitkit::glam::{DQuat, DVec2, DVec3};
use hitkit::{Emission, LightTree, PdfHittable, Quad, ShadingContext, Sphere, TriangleMesh};
use proptest::prelude::*;

/// Whether every corner of a light's box lies strictly below the plane through `p` normal
/// to `n`: checked corner by corner, apart from how the tree decides it.
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

    /// Seen from a shading point on a surface of any orientation, every light whose box
    /// lies wholly below the horizon has probability 0, and a sample drawn there reaches a
    /// light above it or is the zero vector.
    #[test]
    fn no_light_wholly_below_the_horizon_is_picked(
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
        let at = ShadingContext::on_surface(p, n);
        let mut below = 0;
        for (i, light) in tree.lights().iter().enumerate() {
            if wholly_below(light.as_ref(), p, n) {
                below += 1;
                prop_assert_eq!(tree.probability(&at, i), 0.0, "light {} of {}", i, specs.len());
            }
        }
        let sample = tree.sample_light(&at, DVec2::from(u));
        if let Some(sample) = sample {
            prop_assert!(sample.pdf > 0.0);
            prop_assert_eq!(sample.pdf, tree.light_pdf(&at, sample.direction));
        }
        // Every light below: nothing to pick.
        if below == specs.len() {
            prop_assert_eq!(sample, None);
        }
    }
}

/// The reproducer: a sphere above and two panels facing up below the horizon of a
/// surface at the origin facing up; their cluster's bounding sphere reaches above it.
#[test]
fn two_panels_below_the_horizon_are_never_picked() {
    let up = Emission::OneSide(DVec3::Y);
    let lights: Vec<Box<dyn PdfHittable>> = vec![
        Box::new(Sphere::new(DVec3::new(-3.0, 3.0, -3.0), 0.5).unwrap()),
        Box::new(Quad::new(DVec3::new(3.0, -1.0, 0.0), DVec3::Z * 0.2, DVec3::X * 0.2).unwrap()),
        Box::new(Quad::new(DVec3::new(3.0, -1.0, 6.0), DVec3::Z * 0.2, DVec3::X * 0.2).unwrap()),
    ];
    let tree = LightTree::new(lights, &[1.0; 3], &[Emission::Everywhere, up, up]).unwrap();
    let up = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
    assert_eq!(tree.probability(&up, 1), 0.0);
    assert_eq!(tree.probability(&up, 2), 0.0);
    assert_eq!(tree.probability(&up, 0), 1.0);
    // Seen from a surface facing down, the sphere is below and the panels are not.
    let down = ShadingContext::on_surface(DVec3::ZERO, DVec3::NEG_Y);
    assert_eq!(tree.probability(&down, 0), 0.0);
}

/// A single light whose bounding sphere reaches above the horizon while its box does not.
#[test]
fn a_wide_flat_light_below_the_horizon_is_never_picked() {
    let panel = Quad::new(
        DVec3::new(-5.0, -0.5, -5.0),
        DVec3::X * 10.0,
        DVec3::Z * 10.0,
    )
    .unwrap();
    let lights: Vec<Box<dyn PdfHittable>> = vec![
        Box::new(panel),
        Box::new(Sphere::new(DVec3::new(0.0, 4.0, 0.0), 0.5).unwrap()),
    ];
    let tree = LightTree::new(lights, &[1.0, 1e-6], &[Emission::Everywhere; 2]).unwrap();
    let up = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
    assert_eq!(tree.probability(&up, 0), 0.0);
    assert_eq!(tree.probability(&up, 1), 1.0);
}

/// Every light below the horizon: the walk picks none, and every density is 0.
#[test]
fn a_tree_wholly_below_the_horizon_picks_nothing() {
    let lights = vec![Sphere::new(DVec3::new(0.0, -3.0, 0.0), 1.0).unwrap()];
    let tree = LightTree::new(lights, &[1.0], &[Emission::Everywhere]).unwrap();
    let up = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
    assert_eq!(tree.probability(&up, 0), 0.0);
    assert_eq!(tree.sample_light(&up, DVec2::new(0.3, 0.6)), None);
    assert_eq!(tree.light_pdf(&up, DVec3::NEG_Y), 0.0);
    // Without the normal, it is picked.
    assert!(tree.pdf_value(DVec3::ZERO, DVec3::NEG_Y) > 0.0);
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
            // From above, and (one-sided: the side the normal faces) from below.
            let from = DVec3::new(0.25, 1.0, 0.25) * size;
            assert_eq!(tree.probability(&ShadingContext::at(from), 0), 1.0);
            let d = tree.sample_direction(from, DVec2::new(0.3, 0.4));
            assert!(tree.pdf_value(from, d) > 0.0, "{size:e}");
        }
    }
}
