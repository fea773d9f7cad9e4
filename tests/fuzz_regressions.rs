//! What coverage-guided fuzzing (`fuzz/`, `cargo +nightly fuzz run TARGET`) found, each kept
//! as the input it failed on, so that the fix stays.

use hitkit::glam::{DVec2, DVec3};
use hitkit::{PdfHittable, Quad, Triangle};

/// Clause 6, seen edge on: a triangle whose plane passes within rounding of the origin
/// (the origin is its point `alpha = beta = 1/3`, to within an ulp or two of each corner).
/// Its middle sample reaches it by a grazing crossing with a finite density, so it can be
/// aimed at; the corner `u = (0, 0)` drew a direction that crossed it too, but with a
/// density past `f64`'s range, which is 0, and was returned (the sampler asked only
/// whether its samples reach the shape, not whether their density is finite).
#[test]
fn a_light_seen_edge_on_samples_only_directions_with_a_density() {
    let q = DVec3::splat(1.000_000_000_000_002_9);
    let u = DVec3::new(0.999_999_999_999_999_8, -8.0, -4.0);
    let v = DVec3::new(-4.0, 5.0, 1.000_000_000_000_001);
    let light = Quad::with_interior(q, u, v, Triangle).unwrap();
    let origin = DVec3::ZERO;
    let middle = light.sample_direction(origin, DVec2::splat(0.5));
    assert!(
        light.pdf_value(origin, middle) > 0.0,
        "the case needs a reachable light"
    );
    let edges = [0.0, 1e-9, 0.25, 0.5, 0.75, 1.0f64.next_down()];
    for x in edges {
        for y in edges {
            let d = light.sample_direction(origin, DVec2::new(x, y));
            let pdf = light.pdf_value(origin, d);
            assert!(pdf > 0.0 && pdf.is_finite(), "u ({x}, {y}): {d}, pdf {pdf}");
        }
    }
}

/// Clause 4 at a corner: a triangle sampled by solid angle from a point within ulps of its
/// corner `q`; the spherical sampler's arithmetic gave NaN for some `u`, and so did the
/// direction returned. Every direction is finite now (such a sample is drawn by area).
#[test]
fn a_light_sampled_from_beside_its_corner_returns_no_nan() {
    let q = DVec3::splat(1.000_000_000_000_002_9);
    let u = DVec3::new(1.000_000_000_000_002_9, 1.0, 2.199_216_474_544_724_7e-52);
    let v = DVec3::splat(1.000_000_000_000_011_8);
    let light = Quad::with_interior(q, u, v, Triangle).unwrap();
    let origin = DVec3::splat(1.000_000_000_000_011_8);
    let edges = [
        0.0,
        0.207_839_965_820_312_5,
        0.25,
        0.5,
        0.75,
        1.0f64.next_down(),
    ];
    for x in edges {
        for y in edges {
            let d = light.sample_direction(origin, DVec2::new(x, y));
            let pdf = light.pdf_value(origin, d);
            assert!(
                d.is_finite() && pdf.is_finite() && pdf >= 0.0,
                "u ({x}, {y}): {d}, {pdf}"
            );
        }
    }
}

/// Clauses 3 and 4 under maps of extreme condition (entries from 1e-12 to 1e174): a hit's
/// error bound, moved to the world, overflowed. `hit` turned that hit away, but a tree's
/// two-step search (`find`, then `record`) kept it, with an infinite error bound: a tree
/// of the instance answered what the instance did not. The moved bound now saturates at
/// `f64::MAX`, and every query finds the same hit. (The second case is a hit `5e306`
/// along the ray, whose error in object space is already far past the object's size.)
#[test]
fn an_instance_whose_error_bound_overflows_answers_alike_in_a_tree() {
    use hitkit::glam::{DAffine3, DMat3};
    use hitkit::{Bvh, Hittable, Interval, Ray, Transformed};
    let long = DVec3::new(
        2.435_572_344_854_152_5e64,
        1.000_000_000_000_017,
        1.525_878_906_25e-5,
    );
    let quad = Quad::new(
        DVec3::splat(0.811_752_319_335_937_5),
        DVec3::splat(0.811_752_319_335_937_5),
        long,
    )
    .unwrap();
    let stretched = DMat3::from_cols(
        DVec3::new(1.858_423_848_185_522_3e63, 161.578_125, 1_689_389_744_000.3),
        DVec3::new(0.999_999_999_999_982_7, 1.397_688_586_966_101_6e174, 1.0),
        DVec3::new(
            2.050_781_25e-12,
            1.000_000_000_000_022_4,
            1.000_000_000_000_017,
        ),
    );
    let sheared = DMat3::from_cols(
        DVec3::new(1.858_423_848_185_522_3e63, 1.0, 1.000_000_000_000_008_2),
        DVec3::new(1.000_000_000_000_014, -8.0, -2.877_773_982_515_652_2e76),
        DVec3::splat(0.811_752_319_335_937_5),
    );
    let cases = [
        (
            stretched,
            DVec3::new(1.000_000_000_000_017, 4.0, 1.0),
            Ray::new(
                DVec3::new(0.999_999_999_999_982_7, 0.301_055_908_203_125, -8.0),
                DVec3::new(0.698_028_564_453_125, 1.0, 0.999_999_999_999_984_2),
            ),
        ),
        (
            sheared,
            DVec3::splat(0.811_752_319_335_937_5),
            Ray::new(
                DVec3::new(7.0, -5.093_866_197_874_78e306, 3.051_757_812_5e-5),
                DVec3::new(2.052_017_879_604_187e-289, 1.0, 0.0),
            ),
        ),
    ];
    for (matrix, offset, ray) in cases {
        let map = DAffine3::from_mat3_translation(matrix, offset);
        let instance = Transformed::affine(quad, map).unwrap();
        let alone = instance.hit(&ray, Interval::FORWARD);
        let tree = Bvh::new(vec![instance]);
        let found = tree.hit(&ray, Interval::FORWARD);
        assert!(alone.is_some(), "the case needs a hit");
        assert_eq!(found.map(|h| h.t), alone.map(|h| h.t));
        assert_eq!(tree.occluded(&ray, Interval::FORWARD), alone.is_some());
        for hit in [found, alone].into_iter().flatten() {
            assert!(
                hit.point.is_finite() && hit.point_error.is_finite(),
                "{hit:?}"
            );
        }
    }
}

/// Clause 3 (the tree answers as the loop over its objects): a disk as an ellipse a
/// trillion times longer than wide, met by a ray along its length. Its crossing's region,
/// far wider in the long coordinate than the disk's scale along it, met the disk while the
/// ray passed ten billion units outside its box; the box's clamp then moved `t` from 1.0
/// to 0.984, a hit that a search whose `ray_t.max` had fallen below 1 (a tree's, after a
/// hit on another object) refused early. Such a crossing is now no hit whatever the range,
/// and every range gives the answer of the widest one cut to it.
#[test]
fn a_crossing_far_outside_its_box_is_no_hit_whatever_the_range() {
    use hitkit::{Disk, Hittable, Interval, Ray};
    let disk = Quad::with_interior(
        DVec3::new(
            -539_937_249_081.146_6,
            387_941_406_760.040_34,
            299_636_644_211.651_5,
        ),
        DVec3::new(
            539_937_249_082.273_2,
            -387_941_406_766.913_76,
            1_378_090_431_788.775_1,
        ),
        DVec3::new(
            1.555_652_769_514_461_5,
            0.449_538_826_293_889_5,
            2.554_805_962_785_422_5,
        ),
        Disk,
    )
    .unwrap();
    let ray = Ray::new(
        DVec3::new(
            0.309_799_194_335_937_5,
            0.309_799_194_335_937_5,
            0.811_752_319_335_937_5,
        ),
        DVec3::new(
            0.690_200_805_664_079_6,
            -7.309_799_194_335_937_5,
            1_677_727_075_999.488_3,
        ),
    );
    let widest = disk
        .hit(&ray, Interval::new(0.390_625, f64::INFINITY))
        .map(|h| h.t);
    for max in [1.0, 0.9995, 0.999_34, 0.99, 0.985, 0.984_3, 0.98] {
        let cut = widest.filter(|&t| t <= max);
        assert_eq!(
            disk.hit(&ray, Interval::new(0.390_625, max)).map(|h| h.t),
            cut,
            "max {max}"
        );
    }
    // The crossing is at t = 1, 0.12 outside the box in y: no hit.
    assert_eq!(widest, None);
}
