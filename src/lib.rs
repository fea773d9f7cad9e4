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
//! let hit = scene.hit(&ray, Interval::new(0.0, f64::INFINITY)).expect("the disk is in front");
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
//!   `(alpha, beta)` space and include their edges, widened by the rounding-error bound
//!   of the coordinates so that shapes sharing an edge leave no crack.
//! - Constructors validate their input and return [`GeometryError`]; `hit` on a NaN,
//!   infinite or zero-direction ray returns `None`. Nothing panics on any `f64` input.
//!
//! # Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | float functions from the standard library |
//! | `libm` | no | float functions from `libm`, for `no_std` (+ `alloc`) targets |
//! | `approx` | no | `approx` 0.5's comparison traits for the value types |
//!
//! One of `std` and `libm` must be enabled.
//!
//! # MSRV
//! Rust 1.88 (the `rust-version` in Cargo.toml); raising it is a minor-version change.
#![cfg_attr(not(feature = "std"), no_std)]
#![cfg_attr(docsrs, feature(doc_cfg))]
#![deny(missing_docs)]

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("hitkit needs float functions: enable the `std` feature (default) or `libm`");

extern crate alloc;

mod aabb;
mod bvh;
mod cuboid;
mod error;
mod hittable;
mod interior;
mod interval;
mod math;
mod mixture;
mod plane;
mod quad;
mod ray;
mod sampling;
mod sphere;
mod spherical;
mod transform;

#[cfg(feature = "approx")]
mod impl_approx;

pub use glam;

pub use aabb::Aabb;
pub use bvh::Bvh;
pub use cuboid::Cuboid;
pub use error::GeometryError;
pub use hittable::{HitRecord, Hittable, MaterialId, PdfHittable};
pub use interior::{Disk, Exact, Interior, Meets, Parallelogram, Ring, Triangle};
pub use interval::Interval;
pub use mixture::Mixture;
pub use plane::{CrossingRegion, Plane, PlaneHit};
pub use quad::Quad;
pub use ray::Ray;
pub use sampling::{SampleInterior, Sampling};
pub use sphere::Sphere;
pub use transform::Transformed;

/// The README's code blocks, run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
