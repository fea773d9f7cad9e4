//! What a textured material looks up at a hit: its albedo and emission there. The lookup
//! is the scene's (a glTF scene's through `hitkit::load::GltfScene::surface`): the
//! renderer knows no image format.

use std::fmt::Debug;

use hitkit::HitRecord;

use crate::Color;

/// A material's albedo and emission at a hit (or a light's sample), looked up.
pub trait Textures: Send + Sync + Debug {
    /// The diffuse albedo at `hit`.
    fn albedo(&self, hit: &HitRecord) -> Color;
    /// The radiance emitted at `hit` toward the ray (zero from a side that emits nothing).
    fn emission(&self, hit: &HitRecord) -> Color;
    /// Whether it emits anywhere (for the effects a scene calls for).
    fn emits(&self) -> bool;
}
