//! A small path tracer shared by the examples, their tests and the render bench: the book's
//! camera and materials, an integrator that simulates only the effects a scene calls for,
//! parallel rendering with a progress bar, and PNG output.
//!
//! Not part of the library: hitkit stays free of rendering.

#![allow(dead_code)] // each example uses its own part

pub mod camera;
pub mod cli;
pub mod material;
pub mod medium;
pub mod render;
pub mod scenes;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Hittable, LightTree, Mixture, PdfHittable};

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

/// The lights a render aims at, and how it picks one: what a renderer swaps to trade one
/// of hitkit's samplers for another.
pub enum Lights {
    /// Each equally often: hitkit's uniform mixture over a list.
    Uniform(Vec<Box<dyn PdfHittable>>),
    /// By fixed weights (their power, say): a `Mixture`.
    Weighted(Mixture<Box<dyn PdfHittable>>),
    /// By their importance from the shading point and normal: a `LightTree`.
    Tree(LightTree<Box<dyn PdfHittable>>),
}

impl Default for Lights {
    fn default() -> Self {
        Lights::Uniform(Vec::new())
    }
}

impl Lights {
    /// The lights themselves, in the order given.
    pub fn list(&self) -> &[Box<dyn PdfHittable>] {
        match self {
            Lights::Uniform(lights) => lights,
            Lights::Weighted(mixture) => mixture.lights(),
            Lights::Tree(tree) => tree.lights(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.list().is_empty()
    }

    /// A direction toward a light from `point` on a surface facing `normal`.
    #[inline]
    pub fn sample(&self, point: DVec3, normal: DVec3, u: DVec2) -> DVec3 {
        match self {
            Lights::Uniform(lights) => lights.as_slice().sample_direction(point, u),
            Lights::Weighted(mixture) => mixture.sample_direction(point, u),
            Lights::Tree(tree) => tree.with_normal(normal).sample_direction(point, u),
        }
    }

    /// The density of [`Lights::sample`]'s directions.
    #[inline]
    pub fn pdf(&self, point: DVec3, normal: DVec3, direction: DVec3) -> f64 {
        match self {
            Lights::Uniform(lights) => lights.as_slice().pdf_value(point, direction),
            Lights::Weighted(mixture) => mixture.pdf_value(point, direction),
            Lights::Tree(tree) => tree.with_normal(normal).pdf_value(point, direction),
        }
    }
}

/// A scene: what to trace, what it is made of, its lights, its background and its camera.
pub struct Scene<W> {
    pub world: W,
    /// Indexed by the hit record's `MaterialId`.
    pub materials: Vec<Material>,
    /// Shapes to sample directions toward (usually the emissive ones), and how to pick
    /// among them.
    pub lights: Lights,
    pub background: Background,
    pub camera: CameraSettings,
}

impl<W: Hittable> Scene<W> {
    /// The effects this scene calls for.
    pub fn effects(&self) -> Effects {
        Effects {
            background: self.background != Background::Solid(Color::ZERO),
            emission: self
                .materials
                .iter()
                .any(|m| matches!(m, Material::Light(_))),
            light_sampling: !self.lights.is_empty(),
            defocus: self.camera.defocus_angle > 0.0,
        }
    }
}
