//! The guide: how to use hitkit, a topic a page, each with examples that run (they are
//! doctests).
//!
//! - [`shapes`]: planes, quads and their interiors, spheres, boxes; what a hit reports;
//!   bad input.
//! - [`trees`]: the [`Bvh`](crate::Bvh), triangle meshes, instances and motion.
//! - [`updates`]: scenes that change: refits, inserts, removes, and when to rebuild.
//! - [`lights`]: sampling lights, next-event estimation with shadow rays that need no
//!   epsilon, many lights.
//! - [`own_shapes`]: writing your own shape, interior or light.
//! - [`scene_files`]: from a glTF or OBJ file to a traced scene: scaled instances,
//!   cut-outs, visibility masks and lights (the `gltf` and `obj` features).

#[doc = include_str!("guide/shapes.md")]
pub mod shapes {}

#[doc = include_str!("guide/trees.md")]
pub mod trees {}

#[doc = include_str!("guide/updates.md")]
pub mod updates {}

#[doc = include_str!("guide/lights.md")]
pub mod lights {}

#[doc = include_str!("guide/own_shapes.md")]
pub mod own_shapes {}

#[doc = include_str!("guide/scene_files.md")]
pub mod scene_files {}
