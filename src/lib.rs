//! Ray-tracing geometry that stays exact where a scene gets large, small, grazing or
//! degenerate, for renderers that take it as a dependency: planes, quads with pluggable
//! interiors, spheres, boxes, triangle meshes, instances, a BVH, and lights to sample, with
//! bounce and shadow rays that need no epsilon. `no_std` + `alloc`, `f64` throughout.
//!
//! hitkit follows the quadrilateral chapter of *Ray Tracing: The Next Week* (a plane
//! spanned by `q`, `u`, `v`; a hit reported as `(t, alpha, beta)`; an interior predicate
//! that decides) and goes past it: no absolute epsilons, watertight edges, boxes that agree
//! with their shapes, errors instead of NaN, and a contract (below) that says so exactly.
//!
//! ```
//! use hitkit::glam::{DVec2, DVec3};
//! use hitkit::{Disk, Hittable, Interval, PdfHittable, Quad, Ray, ShadingContext};
//!
//! # fn main() -> Result<(), hitkit::GeometryError> {
//! let floor = Quad::new(DVec3::new(-5.0, 0.0, -5.0), DVec3::X * 10.0, DVec3::Z * 10.0)?;
//! let lamp = Quad::with_interior(DVec3::new(0.0, 3.0, 0.0), DVec3::Z, DVec3::X, Disk)?;
//! let scene: Vec<Box<dyn Hittable>> = vec![Box::new(floor), Box::new(lamp)];
//!
//! let hit = scene.hit(&Ray::new(DVec3::new(1.0, 2.0, 1.0), DVec3::NEG_Y), Interval::FORWARD);
//! let hit = hit.expect("the floor is below");
//! assert_eq!((hit.t, hit.normal), (2.0, DVec3::Y)); // the normal faces against the ray
//!
//! // A bounce leaves the floor from t = 0: no `t_min = 0.001`.
//! let bounce = hit.spawn_ray(DVec3::new(0.0, 1.0, 1.0));
//! assert!(!floor.occluded(&bounce, Interval::FORWARD));
//!
//! // A point on the lamp, and a shadow ray to it that finds neither end.
//! let sample = lamp.sample_light(&ShadingContext::from(&hit), DVec2::new(0.3, 0.8)).unwrap();
//! let (shadow, range) = hit.spawn_ray_to(&sample.record);
//! assert!(!scene.occluded(&shadow, range) && sample.pdf > 0.0);
//! # Ok(())
//! # }
//! ```
//!
//! # The guide
//! - [`guide::shapes`]: planes, quads and their interiors, spheres, boxes; what a hit
//!   reports; bad input.
//! - [`guide::trees`]: the [`Bvh`], triangle meshes, instances (rigid or scaled) and motion.
//! - [`guide::updates`]: scenes that change: refits, inserts, removes, when to rebuild.
//! - [`guide::lights`]: sampling lights, next-event estimation, many lights.
//! - [`guide::own_shapes`]: your own shape, interior or light ([`custom`]).
//! - [`guide::scene_files`]: from a glTF or OBJ file to a traced scene: scaled instances,
//!   cut-outs, visibility masks, lights.
//!
//! # Conventions
//! - Vectors are [`glam::DVec3`] and [`glam::DVec2`] (hitkit re-exports `glam`); everything
//!   is `f64`.
//! - A [`HitRecord`]'s `normal` is unit length and faces against the ray; `front_face`
//!   says whether the ray came from the side the outward normal (`u x v` for a flat shape)
//!   points to. `t` is in units of the ray's direction, which may have any length.
//! - Points on a plane or quad are `q + alpha * u + beta * v`; interior predicates
//!   ([`Parallelogram`], [`Triangle`], [`Disk`], [`Ring`], or your own) decide in
//!   `(alpha, beta)` space and include their edges.
//! - A light's `pdf_value` is a density over solid angle; the directions its samplers
//!   return are unit vectors.
//! - Constructors validate their input and return [`GeometryError`]; `hit` on a NaN,
//!   infinite or zero-direction ray returns `None`. Nothing panics on any `f64` input.
//!
//! # The contract
//! What hitkit promises, for every ray a renderer may trace (any direction, of any length
//! `f64` holds, any origin, grazing or from far away) and every shape it may build
//! (rotated, far from the origin, from `1e-6` to `1e6` in size). Each clause is held by
//! tests whose inputs are built as renderers build them (`tests/contract.rs`,
//! `tests/peer_suite.rs` with pbrt-v4's own shape tests, `tests/next_event.rs`).
//!
//! 1. **No false hits.** Every hit a planar shape reports lies within `2^-43 M / s^2` of the
//!    exact shape, `M = |q|_inf + |u|_inf + |v|_inf` and `s` the sine of the angle between
//!    `u` and `v`: a few hundred ulps of its corners' magnitude for a well-shaped quad,
//!    whatever the angle of the ray. A grazing ray beside a shape is not a hit. Every hit
//!    lies within its own [`point_error`](HitRecord::point_error) of the surface, instances
//!    included: under [`Transformed::affine`] that is the object's bound `e` carried by
//!    the map, `|M| e`, plus the map's rounding both ways, at most `16 k` ulps of the
//!    point and the translation, `16 k u (|P|_inf + |c|_inf)` per axis, for a map
//!    `x -> M x + c` of condition number `k = |M|_inf |M^-1|_inf` (`u = 2^-53`). The
//!    derivation gives `15 k` and the inverse's computed residual; `tests/affine.rs`
//!    measures under `12 k` over maps of condition 1 to `1.8e4`. A rotation times axis
//!    scales pays a few tens of ulps whatever its `k` (at most 51 and the residual by the
//!    derivation, 33 measured). Rays spawned from such a hit
//!    leave the object in its own space (clause 5): a pane 1000 wide and 0.05 thick, `1e6`
//!    from the origin, refracts its rays through its far face.
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
//!    objects returns, on every ray from any distance. Masks too: an object under nested
//!    [`Masked`] wrappers (directly, or with trees, lists and instances between them) is
//!    seen by the rays whose mask shares a bit with all of its masks together (their
//!    AND), whether it is asked directly or through a list or a [`Bvh`]. A mask never
//!    changes how a light is sampled ([`PdfHittable::light_hit`]).
//! 4. **No NaN.** Nothing returned (hit record, box, density, direction, spawned ray) is
//!    NaN or infinite, for any input, subnormals, `f64::MAX`, infinities and NaN included:
//!    bad input is a [`GeometryError`] at construction, a ray that cannot be traced hits
//!    nothing, and `occluded` answers exactly as `hit(..).is_some()`. (Infinite where
//!    that is the answer: an unbounded shape's box, and a sun's sample, whose light lies at
//!    an infinite distance: [`LightSample::delta`].)
//! 5. **Spawned rays leave.** A ray from [`HitRecord::spawn_ray`], in any direction, never
//!    finds the surface it leaves (pbrt-v4's "Reintersect" property), nor, from a convex
//!    shape on its outer side, any part of that shape: a crossing counts only where its
//!    `t` lies beyond `ray_t.min` whatever its rounding. A shadow ray from
//!    [`HitRecord::spawn_ray_to`] finds neither the surface it leaves nor the light's
//!    surface at its far end, and finds what lies between (but for occluders within `2^-46`
//!    of the coordinates' magnitude of the light's surface).
//! 6. **Every sample has a density.** Every direction `sample_direction` returns, for any
//!    `u` in `[0, 1)^2` (corners included: a sampler's first point is often `(0, 0)`), has a
//!    positive, finite `pdf_value`, wherever the light can be aimed at from the origin at
//!    all; every [`LightSample`] has a positive, finite density.
//!
//! **The domain.** Clauses 1 to 4 and 6 hold for a scene of any size anywhere. Clause 5's
//! shadow rays ask for room: `spawn_ray_to` ends its ray `2^-46` of the coordinates'
//! magnitude short of the light's surface, which tilts the ray by that much at its far
//! end. The tests keep to scenes at least `2^20` ulps of their distance from the origin
//! across (`2^-32` of it: features down to 0.25 at 1e9), where the tilt is under `2^-14`
//! of a shadow ray's length; in a smaller scene (1e-3 across at 1.3e9, about 4,000 ulps)
//! a shadow ray can pass beside an occluder a fiftieth of its length wide near the light.
//! Move such a scene nearer the origin (or trace it in a frame of its own, under a
//! [`Transformed`]), where `f64` has the digits for it.
//!
//! And speed does not depend on where a scene sits: a [`Bvh`]'s node boxes are relative to
//! the scene's centre, so a scene at 1e9 costs the same tests per ray as at the origin (as
//! long as its shapes are wider than the tolerance, `2^-48` of their coordinates). What the
//! contract costs in time is measured in the repository's `docs/performance.md` and
//! `docs/accuracy.md`.
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
//! | `std` | yes | float functions from the standard library; the trees' queries compiled for AVX2 too, picked at run time where the CPU has it (without `std`, where the build targets it) |
//! | `libm` | no | float functions from `libm`, for `no_std` (+ `alloc`) targets |
//! | `approx` | no | `approx` 0.5's comparison traits for the value types |
//! | `serde` | no | `Serialize` / `Deserialize` for the value types, and for `Plane`, `Quad`, `Sphere` as what builds them (through their constructors) |
//! | `rand` | no | `RandomDirection`: sample a light with any `rand` 0.10 generator |
//! | `rand09` | no | `RandomDirection09`: the same with a `rand` 0.9 generator |
//! | `rayon` | no | `Bvh::new_parallel` and `TriangleMesh::new_parallel`: trees built on every core (the same trees); needs `std` |
//! | `obj` | no | `load::load_obj`: an OBJ file's objects as `TriangleMesh`es with their materials' names (through `tobj`); needs `std` |
//! | `gltf` | no | `load::load_gltf`: a glTF file's meshes (lists, strips and fans of triangles, sparse accessors, every texture-coordinate set), instances under their composed transforms, materials' alpha modes, textures (with their samplers and `KHR_texture_transform`) and emitters as a `LightTree` (through `gltf`); the surface at a hit; what it leaves out listed; needs `std` |
//! | `gltf-images` | no | with `gltf`: the images the materials' colour and emission textures read, decoded (PNG, JPEG) on every core, and looked up by `GltfScene::texel` |
//!
//! One of `std` and `libm` must be enabled.
//!
//! # MSRV
//! Rust 1.88 (the `rust-version` in Cargo.toml); raising it is a minor-version change.
#![cfg_attr(not(feature = "std"), no_std)]
#![cfg_attr(docsrs, feature(doc_cfg))]
#![deny(missing_docs)]
// `unsafe` in one module only, `simd::avx` (AVX intrinsics behind a proof that the CPU has
// them), each block with its `SAFETY:` comment.
#![deny(unsafe_code)]

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("hitkit needs float functions: enable the `std` feature (default) or `libm`");

extern crate alloc;

mod aabb;
mod bvh;
mod error;
mod features;
pub mod guide;
mod hittable;
mod instance;
mod interval;
mod light;
mod list;
mod masked;
mod math;
mod mesh;
mod ray;
mod record;
mod sample;
mod shape;
mod simd;
mod tree;

pub use glam;

pub use aabb::Aabb;
pub use bvh::{Bvh, ObjectCandidate};
pub use error::GeometryError;
pub use hittable::{Hittable, PdfHittable};
pub use instance::{Affine, Moving, Rigid, Transformed};
pub use interval::Interval;
#[cfg(feature = "rand")]
#[cfg_attr(docsrs, doc(cfg(feature = "rand")))]
pub use light::RandomDirection;
#[cfg(feature = "rand09")]
#[cfg_attr(docsrs, doc(cfg(feature = "rand09")))]
pub use light::RandomDirection09;
pub use light::{Light, LightPick, LightTree, Mixture, PunctualLight};
pub use masked::Masked;
pub use mesh::{Candidate, Face, Filtered, TriangleMesh};
pub use ray::Ray;
pub use record::{HitRecord, MaterialId};
pub use sample::{Emission, LightSample, ShadingContext};
pub use shape::{
    Cuboid, Disk, Exact, Interior, Parallelogram, Plane, PlaneHit, Quad, Ring, SampleInterior,
    Sampling, Sphere, Triangle,
};
pub use tree::{TreeCost, Visits};

/// Scene files as hitkit's types, behind the `obj` and `gltf` features:
/// [`load_obj`](load::load_obj) reads an OBJ file's objects as [`TriangleMesh`]es,
/// [`load_gltf`](load::load_gltf) a glTF file's meshes, instances (with their composed
/// transforms), materials (alpha, emission, textures) and emitters, and with the
/// `gltf-images` feature its images; a glTF scene answers what shading asks at a hit
/// ([`GltfScene::surface`](load::GltfScene::surface)). Errors name the file and what is
/// wrong ([`LoadError`](load::LoadError)). See the guide's
/// [scene files](guide::scene_files).
#[cfg(any(feature = "obj", feature = "gltf"))]
#[cfg_attr(docsrs, doc(cfg(any(feature = "obj", feature = "gltf"))))]
pub mod load {
    #[cfg(feature = "gltf")]
    pub use crate::features::gltf::{
        Alpha, Emitter, Filter, GltfCamera, GltfImage, GltfInstance, GltfLights, GltfMaterial,
        GltfMesh, GltfOptions, GltfPunctual, GltfScene, GltfSurface, GltfTexture, LeftOut,
        Projection, Sampler, Scenes, TextureTransform, Wrap, load_gltf, load_gltf_slice,
        load_gltf_with,
    };
    pub use crate::features::load::{LoadError, LoadErrorKind};
    #[cfg(feature = "obj")]
    pub use crate::features::obj::{ObjMesh, ObjScene, load_obj};
}

/// [`custom::Found`], under the name a shape author tries first: `use hitkit::Found` then
/// compiles, with a warning that names where it lives.
#[doc(hidden)]
#[deprecated(note = "`Found` lives in `hitkit::custom`: `use hitkit::custom::Found`")]
pub type Found = record::Found;

/// [`custom::Made`], under the name a shape author tries first (as `Found`).
#[doc(hidden)]
#[deprecated(note = "`Made` lives in `hitkit::custom`: `use hitkit::custom::Made`")]
pub type Made = record::Made;

/// What writing your own shape or interior takes beyond the traits at the root: the
/// closest-hit search's [`Found`](custom::Found) and [`Made`](custom::Made) (for
/// [`Hittable::find`] and [`Hittable::record`]), the region where a ray's exact crossing
/// of a plane can lie ([`CrossingRegion`](custom::CrossingRegion)) and an interior's
/// answer about it ([`Meets`](custom::Meets), for [`Interior::meets`]), the polygons with
/// a solid-angle sampler ([`Polygon`](custom::Polygon), for [`SampleInterior::polygon`]),
/// and what an instance's linear part does ([`Frame`](custom::Frame)). See the guide's
/// [own shapes](guide::own_shapes).
pub mod custom {
    pub use crate::instance::Frame;
    pub use crate::record::{Found, Made};
    pub use crate::shape::{CrossingRegion, Meets, Polygon};
}

/// The README's code blocks, run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
