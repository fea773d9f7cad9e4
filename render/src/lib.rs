//! A small path tracer shared by hitkit's examples, their tests and the render bench: the
//! book's camera and materials, an integrator that simulates only the effects a scene
//! calls for, parallel rendering with a progress bar, and PNG output; and the workloads
//! (scenes and rays) that the tests, the benches, the peers comparison and the accuracy
//! tables all trace.
//!
//! An unpublished workspace crate: hitkit itself stays free of rendering.

pub mod camera;
pub mod cli;
pub mod distance;
pub mod halls;
pub mod material;
pub mod medium;
pub mod pbrt_lights;
pub mod render;
pub mod scenes;
pub mod texture;
pub mod workloads;

use hitkit::glam::DVec3;
use hitkit::{Hittable, PdfHittable};

pub use camera::CameraSettings;
pub use material::Material;

/// Linear RGB.
pub type Color = DVec3;

/// What a ray that escapes the scene sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Background {
    /// The book's white-to-blue gradient.
    Sky,
    /// One colour; black costs nothing.
    Solid(Color),
}

impl Background {
    #[inline]
    pub fn color(&self, direction: DVec3) -> Color {
        match *self {
            Background::Sky => {
                let a = 0.5 * (direction.normalize().y + 1.0);
                (1.0 - a) * Color::ONE + a * Color::new(0.5, 0.7, 1.0)
            }
            Background::Solid(c) => c,
        }
    }
}

/// The effects a render simulates. Derived from the scene ([`Scene::effects`]) so that
/// nothing unused costs time; decided once per render, not per ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Effects {
    /// A background other than black is looked up for escaping rays.
    pub background: bool,
    /// Materials may emit: emission is looked up at every hit.
    pub emission: bool,
    /// Directions are drawn from a mixture of the lights' and the material's densities.
    pub light_sampling: bool,
    /// The lens is sampled (defocus blur).
    pub defocus: bool,
}

impl Effects {
    /// Every effect on, whatever the scene needs: what a renderer that does not ask pays.
    pub const ALL: Self = Self {
        background: true,
        emission: true,
        light_sampling: true,
        defocus: true,
    };
}

/// A scene: what to trace, what it is made of, its lights, its background and its camera.
pub struct Scene<W> {
    pub world: W,
    /// Indexed by the hit record's `MaterialId`.
    pub materials: Vec<Material>,
    /// The shapes to sample directions toward (the emissive ones), and how to pick among
    /// them: a list (uniformly), a `Mixture` (by weight) or a `LightTree` (by importance
    /// from the shading point and normal).
    pub lights: Option<Box<dyn PdfHittable>>,
    /// How a diffuse hit gathers light from `lights`: by next-event estimation (a shadow
    /// ray to a sampled point on a light, and a material-sampled bounce, weighed by
    /// multiple importance sampling: for many or small lights), or, where false, as the
    /// book does (one direction from an even mixture of the lights' and the material's
    /// densities).
    pub next_event: bool,
    pub background: Background,
    pub camera: CameraSettings,
}

impl<W: Hittable> Scene<W> {
    /// The effects this scene calls for.
    pub fn effects(&self) -> Effects {
        Effects {
            background: self.background != Background::Solid(Color::ZERO),
            emission: self.materials.iter().any(|m| match m {
                Material::Light(_) => true,
                Material::Textured(t) => t.emits(),
                _ => false,
            }),
            light_sampling: self.lights.is_some(),
            defocus: self.camera.defocus_angle > 0.0,
        }
    }
}
