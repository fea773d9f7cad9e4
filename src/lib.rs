//! Ray-tracing geometry that stays exact where a scene gets large, small, grazing or
//! degenerate.
//!
//! hitkit follows the quadrilateral chapter of *Ray Tracing: The Next Week* (a plane
//! spanned by `q`, `u`, `v`; a hit reported as `(t, alpha, beta)`; an interior predicate
//! that decides) and goes past it: no absolute epsilons, well-conditioned formulas, a box
//! test that does not lose rays lying in a slab plane, and errors instead of NaN.
//!
//! ```
//! use hitkit::glam::DVec3;
//! use hitkit::{Disk, Hittable, Interval, Plane, Quad, Ray};
//!
//! # fn main() -> Result<(), hitkit::GeometryError> {
//! let scene: Vec<Box<dyn Hittable>> = vec![
//!     Box::new(Quad::new(DVec3::new(-1.0, -1.0, -5.0), DVec3::X * 2.0, DVec3::Y * 2.0)?),
//!     Box::new(Quad::with_interior(DVec3::new(0.0, 0.0, -3.0), DVec3::X, DVec3::Y, Disk)?),
//!     Box::new(Plane::new(DVec3::new(0.0, -2.0, 0.0), DVec3::Z, DVec3::X)?),
//! ];
//! let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
//! let hit = scene.hit(&ray, Interval::FORWARD).expect("the disk is in front");
//! assert_eq!(hit.t, 3.0);
//! assert_eq!(hit.normal, DVec3::Z); // faces against the ray
//! # Ok(())
//! # }
//! ```
//!
//! # Conventions
//! - Vectors are [`glam::DVec3`] / [`glam::DVec2`]; everything is `f64`.
//! - A [`HitRecord`]'s `normal` is unit length and faces against the ray; `front_face`
//!   says whether the ray came from the side `u x v` points to.
//! - Points on a plane or quad are `q + alpha * u + beta * v`; interior predicates
//!   ([`Parallelogram`], [`Triangle`], [`Disk`], [`Ring`], or your own) decide in
//!   `(alpha, beta)` space and include their edges. The built-in ones decide by the region
//!   where the ray's exact crossing can be ([`CrossingRegion`], [`Interior::meets`]), so
//!   that shapes sharing an edge leave no crack and nothing beside a shape is hit.
//! - A [`TriangleMesh`] shares its vertices between faces and decides by edge functions in
//!   a frame of the ray (watertight by construction); its hits name the face
//!   ([`HitRecord::primitive`]), and a [`Transformed`] with an id names the instance
//!   ([`HitRecord::instance`]). [`Moving`] objects are where the ray's `time` puts them.
//! - Constructors validate their input and return [`GeometryError`]; `hit` on a NaN,
//!   infinite or zero-direction ray returns `None`. Nothing panics on any `f64` input.
//!
//! # The contract
//! What hitkit promises, for every ray a renderer may trace (any direction, of any length
//! `f64` holds, any origin, grazing or from far away) and every shape it may build (rotated, far from the origin,
//! from `1e-6` to `1e6` in size); each clause is held by `tests/contract.rs`.
//!
//! 1. **No false hits.** Every hit a planar shape reports lies within `2^-43 M / s^2` of the
//!    exact shape, `M = |q|_inf + |u|_inf + |v|_inf` and `s` the sine of the angle between
//!    `u` and `v`: a few hundred ulps of its corners' magnitude for a well-shaped quad,
//!    whatever the angle of the ray. A grazing ray beside a shape is not a hit.
//! 2. **No leaks.** A ray through an edge shared by two shapes hits one of them, whether
//!    their shared corners are bitwise equal (meshes, [`Cuboid`], tiles built from `q + u`)
//!    or were computed apart and rounded differently (the faces of a rotated box built one
//!    by one in world space): shapes widen by [`Plane::tolerance`], `2^-48 M` in world
//!    space, which covers such rounding. For rays within `2^-52` radians of parallel to
//!    the shapes, the widening along the ray stops growing, and sub-ulp steps between
//!    coplanar neighbours may then let a ray through.
//! 3. **Boxes agree with shapes.** A shape never reports a hit outside its own
//!    [`bounding_box`](Hittable::bounding_box)'s span along the ray, and its `t` does not
//!    depend on the range's upper end: a [`Bvh`] returns exactly what a loop over its
//!    objects returns, on every ray from any distance.
//! 4. **No NaN.** Nothing returned (hit record, box, density, direction, spawned ray) is
//!    NaN or infinite, for any input; bad input is a [`GeometryError`] at construction, and
//!    a ray that cannot be traced hits nothing.
//!
//! And speed does not depend on where a scene sits: a [`Bvh`]'s node boxes are relative to
//! the scene's centre, so a scene at 1e9 costs the same tests per ray as at the origin (as
//! long as its shapes are wider than the tolerance, `2^-48` of their coordinates).
//!
//! # Flush-to-zero and denormals-are-zero
//! Embree and many renderers turn on the CPU's flush-to-zero and denormals-are-zero modes
//! (x86-64's MXCSR bits 15 and 6): a result that would be a subnormal number is zero, and
//! a subnormal operand is read as zero. The contract above is stated for IEEE arithmetic
//! as Rust specifies it, with gradual underflow. With the modes on it holds, answer for
//! answer, for scenes and rays whose non-zero coordinates, extents and direction
//! components lie within about `1e-100` to `1e100` in magnitude (zeros included: walls on
//! the coordinate planes): hitkit makes no subnormal number on the paths a renderer takes
//! (a spawned ray's origin steps off zero to about `1.5e-271`, a tree's `f32` boxes and its
//! box test's distances hold none), and where a product may still underflow (the depths
//! of a crossing near a wall at zero), its error bound carries the smallest normal number
//! per operation, which a flushed result is within. `tests/flush_to_zero.rs` traces a
//! path tracer's rays through rooms of such walls at four scales and compares every
//! answer, bit for bit, with the modes on and off. An input that is itself subnormal is
//! read as zero with the modes on, and the answer is then the one for that zero. The
//! modes make hitkit neither faster nor slower (`docs/performance.md`, the triad).
//!
//! # Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | float functions from the standard library |
//! | `libm` | no | float functions from `libm`, for `no_std` (+ `alloc`) targets |
//! | `approx` | no | `approx` 0.5's comparison traits for the value types |
//! | `serde` | no | `Serialize` / `Deserialize` for the value types, and for `Plane`, `Quad`, `Sphere` as what builds them (through their constructors) |
//! | `rand` | no | `RandomDirection`: sample a light with any `rand` 0.10 generator |
//! | `rayon` | no | `Bvh::new_parallel` and `TriangleMesh::new_parallel`: trees built on every core (the same trees); needs `std` |
//!
//! One of `std` and `libm` must be enabled.
//!
//! # MSRV
//! Rust 1.88 (the `rust-version` in Cargo.toml); raising it is a minor-version change.
#![cfg_attr(not(feature = "std"), no_std)]
#![cfg_attr(docsrs, feature(doc_cfg))]
#![deny(missing_docs)]
#![forbid(unsafe_code)]

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("hitkit needs float functions: enable the `std` feature (default) or `libm`");

extern crate alloc;

mod aabb;
mod bvh;
mod cuboid;
mod error;
mod hittable;
mod instance;
mod interior;
mod interval;
mod light;
mod list;
mod math;
mod mesh;
mod moving;
mod plane;
mod quad;
mod ray;
mod record;
mod sphere;
mod transform;

#[cfg(feature = "approx")]
mod impl_approx;
#[cfg(feature = "serde")]
mod impl_serde;

pub use glam;

pub use aabb::Aabb;
pub use bvh::{Bvh, TreeCost, Visits};
pub use cuboid::Cuboid;
pub use error::GeometryError;
pub use hittable::{Hittable, PdfHittable};
pub use interior::{Disk, Exact, Interior, Meets, Parallelogram, Ring, Triangle};
pub use interval::Interval;
#[cfg(feature = "rand")]
#[cfg_attr(docsrs, doc(cfg(feature = "rand")))]
pub use light::RandomDirection;
pub use light::{Emission, LightTree, Mixture, Polygon, SampleInterior, Sampling, WithNormal};
pub use mesh::{Face, TriangleMesh};
pub use moving::Moving;
pub use plane::{CrossingRegion, Plane, PlaneHit};
pub use quad::Quad;
pub use ray::Ray;
pub use record::{Found, HitRecord, MaterialId};
pub use sphere::Sphere;
pub use transform::Transformed;

/// The README's code blocks, run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
