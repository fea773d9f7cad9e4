//! The padded box and its slab test: rays lying in a slab plane, zero and negative-zero
//! direction components, flat boxes, and padding that scales with the box.

use hitkit::glam::DVec3;
use hitkit::{Aabb, Interval, Ray};

const FORWARD: Interval = Interval::FORWARD;

fn unit_box() -> Aabb {
    Aabb::new(DVec3::ZERO, DVec3::ONE)
}

#[test]
fn corners_in_any_order_give_the_same_box() {
    let a = DVec3::new(1.0, -2.0, 3.0);
    let b = DVec3::new(-1.0, 2.0, 0.5);
    let mixed = DVec3::new(a.x, b.y, a.z);
    let other = DVec3::new(b.x, a.y, b.z);
    assert_eq!(Aabb::new(a, b), Aabb::new(b, a));
    assert_eq!(Aabb::new(a, b), Aabb::new(mixed, other));
    assert_eq!(Aabb::new(a, b).min(), DVec3::new(-1.0, -2.0, 0.5));
    assert_eq!(Aabb::new(a, b).max(), DVec3::new(1.0, 2.0, 3.0));
}

#[test]
fn empty_is_the_identity_of_union_and_universe_absorbs() {
    let b = unit_box();
    assert_eq!(b.union(&Aabb::EMPTY), b);
    assert_eq!(Aabb::EMPTY.union(&b), b);
    assert_eq!(b.union(&Aabb::UNIVERSE), Aabb::UNIVERSE);
    assert!(Aabb::EMPTY.is_empty() && !Aabb::EMPTY.is_bounded());
    assert!(!Aabb::UNIVERSE.is_bounded() && !Aabb::UNIVERSE.is_empty());
    assert!(b.is_bounded());
    let u = b.union(&Aabb::new(DVec3::splat(2.0), DVec3::splat(3.0)));
    assert_eq!((u.min(), u.max()), (DVec3::ZERO, DVec3::splat(3.0)));
}

#[test]
fn the_empty_box_is_hit_by_no_ray_even_axis_parallel_ones() {
    for d in [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::new(0.0, -0.0, 1.0),
        DVec3::new(1.0, 2.0, 3.0),
    ] {
        let ray = Ray::new(DVec3::ZERO, d);
        assert!(!Aabb::EMPTY.hit(&ray, FORWARD), "{d}");
        assert!(!Aabb::EMPTY.hit(&ray, Interval::UNIVERSE), "{d}");
        assert!(Aabb::UNIVERSE.hit(&ray, FORWARD), "{d}");
    }
}

/// The book's slab test computes `(min - o) / d`: with `d = 0` and `o` on the face, that is
/// `0 / 0 = NaN`, and its `max`/`min` against NaN drop the box.
#[test]
fn rays_lying_in_a_slab_plane_with_zero_or_negative_zero_direction_hit() {
    let b = unit_box();
    for zero in [0.0, -0.0] {
        for face in [0.0, 1.0] {
            // In the plane x = face, moving along +z (and -z) with a zero x component.
            for dz in [1.0, -1.0] {
                let origin = DVec3::new(face, 0.5, if dz > 0.0 { -1.0 } else { 2.0 });
                let ray = Ray::new(origin, DVec3::new(zero, 0.0, dz));
                assert!(
                    b.hit(&ray, FORWARD),
                    "face x = {face}, dx = {zero:?}, dz = {dz}"
                );
                // Along an edge: two zero components, origin on two faces.
                let edge = Ray::new(DVec3::new(face, face, origin.z), DVec3::new(zero, zero, dz));
                assert!(
                    b.hit(&edge, FORWARD),
                    "edge at {face}, zeros {zero:?}, dz = {dz}"
                );
            }
        }
    }
}

#[test]
fn rays_parallel_to_a_slab_and_outside_it_miss_even_with_infinite_range() {
    let b = unit_box();
    for zero in [0.0, -0.0] {
        for x in [-0.5, 1.5] {
            let ray = Ray::new(DVec3::new(x, 0.5, -1.0), DVec3::new(zero, 0.0, 1.0));
            assert!(!b.hit(&ray, FORWARD), "x = {x}, dx = {zero:?}");
            assert!(!b.hit(&ray, Interval::UNIVERSE), "x = {x}, dx = {zero:?}");
        }
    }
}

#[test]
fn zero_thickness_boxes_are_hit_head_on_and_edge_on() {
    // The union of unpadded flat boxes can be flat: build one from the infinite slab of a
    // plane at z = 0, whose padding is zero because every coordinate is 0 or infinite.
    let flat = Aabb::new(
        DVec3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, 0.0),
        DVec3::new(f64::INFINITY, f64::INFINITY, 0.0),
    );
    assert_eq!(flat.min().z, flat.max().z, "this box really is flat");
    let head_on = Ray::new(DVec3::new(0.3, 0.3, 2.0), DVec3::new(0.0, 0.0, -1.0));
    assert!(flat.hit(&head_on, FORWARD));
    let edge_on = Ray::new(DVec3::new(-5.0, 0.3, 0.0), DVec3::new(1.0, 0.0, -0.0));
    assert!(flat.hit(&edge_on, FORWARD));
    let oblique = Ray::new(DVec3::new(-5.0, 0.3, 1.0), DVec3::new(1.0, 1.0, -1.0));
    assert!(flat.hit(&oblique, FORWARD));
    let above = Ray::new(DVec3::new(-5.0, 0.3, 1.0), DVec3::new(1.0, 0.0, 0.0));
    assert!(!flat.hit(&above, FORWARD));
}

#[test]
fn flat_sides_are_padded_so_that_the_padding_survives_at_1e12() {
    for offset in [0.0, 1.0, 1e6, 1e12, -1e12, 1e15] {
        let lo = DVec3::new(offset, offset, offset);
        let b = Aabb::new(lo, lo + DVec3::new(1.0, 1.0, 0.0));
        assert!(
            b.max().z > b.min().z,
            "flat side at {offset} lost its padding"
        );
        // The padded box still contains the flat quad, and a ray through it hits it.
        assert!(b.min().z < offset && offset < b.max().z);
        let ray = Ray::new(
            DVec3::new(offset + 0.5, offset + 0.5, offset + 10.0),
            DVec3::NEG_Z,
        );
        assert!(b.hit(&ray, FORWARD), "offset {offset}");
    }
}

#[test]
fn padding_does_not_swell_a_micrometre_object() {
    let size = 1e-6;
    let b = Aabb::new(DVec3::ZERO, DVec3::new(size, size, 0.0));
    let thickness = b.max().z - b.min().z;
    assert!(thickness > 0.0);
    // The book's fixed 0.0001 would make it 100 times thicker than it is wide.
    assert!(
        thickness < 1e-3 * size,
        "thickness {thickness} for a {size} object"
    );
    // Sides already wider than the minimum are left exactly as given.
    assert_eq!((b.min().x, b.max().x), (0.0, size));
}

#[test]
fn nan_corners_give_an_unbounded_axis_not_a_lost_box() {
    let b = Aabb::new(DVec3::new(f64::NAN, 0.0, 0.0), DVec3::ONE);
    assert_eq!(b.min().x, f64::NEG_INFINITY);
    assert!(!b.is_bounded());
    let ray = Ray::new(DVec3::new(-100.0, 0.5, 0.5), DVec3::X);
    assert!(b.hit(&ray, FORWARD));
}

#[test]
fn invalid_rays_hit_no_box() {
    let b = unit_box();
    for ray in [
        Ray::new(DVec3::splat(f64::NAN), DVec3::X),
        Ray::new(DVec3::ZERO, DVec3::new(f64::NAN, 1.0, 1.0)),
        Ray::new(DVec3::ZERO, DVec3::ZERO),
        Ray::new(DVec3::new(f64::INFINITY, 0.5, 0.5), DVec3::NEG_X),
    ] {
        assert!(!b.hit(&ray, FORWARD), "{ray:?}");
    }
}

#[test]
fn from_points_contains_every_point() {
    let pts = [
        DVec3::new(1.0, 5.0, -2.0),
        DVec3::new(-3.0, 0.0, 2.0),
        DVec3::new(0.0, 0.0, 0.0),
    ];
    let b = Aabb::from_points(&pts);
    assert!(pts.iter().all(|p| b.contains(*p)));
    assert_eq!(Aabb::from_points(&[]), Aabb::EMPTY);
}
