//! The fourth stage: the materials, their textures with their samplers and
//! `KHR_texture_transform`s, and glTF's default material for primitives that name none.

use std::format;
use std::string::{String, ToString};

use glam::{DMat2, DVec2, DVec3};

use super::{Alpha, GltfMaterial, GltfTexture};

/// How a texture's lookup treats coordinates outside `[0, 1]` along one axis (glTF's
/// `wrapS`, `wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The image repeats (glTF's default).
    #[default]
    Repeat,
    /// The edge texels extend outward.
    ClampToEdge,
    /// The image repeats, every other copy mirrored.
    MirroredRepeat,
}

/// How a texture's lookup blends texels (glTF's `magFilter`; without mipmaps, the
/// minifying filter reads the same).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// Bilinear between the four nearest (glTF leaves the default to the renderer).
    #[default]
    Linear,
}

/// A texture's sampler: wrapping along `u` and `v`, and filtering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct Sampler {
    /// Along `u` (glTF's `wrapS`).
    pub wrap_u: Wrap,
    /// Along `v` (glTF's `wrapT`).
    pub wrap_v: Wrap,
    /// Between texels.
    pub filter: Filter,
}

/// A texture's `KHR_texture_transform`: texture coordinates scaled, then turned by
/// `rotation` about the origin (counterclockwise in the image, whose `v` points down), then
/// offset (glTF's `T * R * S`).
///
/// ```
/// use hitkit::glam::DVec2;
/// use hitkit::load::TextureTransform;
///
/// let transform = TextureTransform {
///     offset: DVec2::new(0.5, 0.0),
///     rotation: 0.0,
///     scale: DVec2::splat(2.0),
/// };
/// assert_eq!(transform.apply(DVec2::new(0.25, 0.25)), DVec2::new(1.0, 0.5));
///
/// // A quarter turn takes `u` to `-v`: counterclockwise in the image, whose `v` is down.
/// let turn = TextureTransform { offset: DVec2::ZERO, rotation: std::f64::consts::FRAC_PI_2, scale: DVec2::ONE };
/// assert!((turn.apply(DVec2::X) - DVec2::NEG_Y).length() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureTransform {
    /// Added last.
    pub offset: DVec2,
    /// Radians.
    pub rotation: f64,
    /// Applied first, per axis.
    pub scale: DVec2,
}

impl TextureTransform {
    /// The coordinates `uv` transformed.
    #[must_use]
    pub fn apply(&self, uv: DVec2) -> DVec2 {
        let (sin, cos) = self.rotation.sin_cos();
        // Rows (cos, sin) and (-sin, cos): the direction the Khronos sample model
        // `TextureTransformTest` marks right (the other is its red marker), as three.js
        // and the Khronos viewer turn; the extension's GLSL, read as columns, turns back.
        let turn = DMat2::from_cols(DVec2::new(cos, -sin), DVec2::new(sin, cos));
        self.offset + turn * (self.scale * uv)
    }
}

impl GltfTexture {
    /// The texture `info` (of a material's slot; `colour` for base colour and emission,
    /// whose texels are sRGB) reads, and how.
    fn of(
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<(TextureTransform, Option<u32>)>,
        colour: bool,
    ) -> Self {
        let sampler = texture.sampler();
        let wrap = |w| match w {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        Self {
            texture: texture.index(),
            image: texture.source().index(),
            tex_coord: transform.and_then(|(_, set)| set).unwrap_or(tex_coord),
            transform: transform.map(|(t, _)| t),
            sampler: Sampler {
                wrap_u: wrap(sampler.wrap_s()),
                wrap_v: wrap(sampler.wrap_t()),
                filter: match sampler.mag_filter() {
                    Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
                    _ => Filter::Linear,
                },
            },
            colour,
        }
    }

    /// The coordinates this texture reads at a point whose `TEXCOORD_n` (for the set this
    /// texture reads, [`GltfTexture::tex_coord`]) is `uv`: `uv` under the texture's
    /// transform, if it has one.
    #[must_use]
    pub fn coordinates(&self, uv: DVec2) -> DVec2 {
        self.transform.map_or(uv, |t| t.apply(uv))
    }
}

/// A `KHR_texture_transform` object as JSON (and its `texCoord` override).
fn transform_of(value: &gltf::json::Value) -> Option<(TextureTransform, Option<u32>)> {
    let pair = |key: &str, default: f64| {
        value
            .get(key)
            .and_then(|v| v.as_array())
            .map_or(DVec2::splat(default), |a| {
                let at = |i: usize| {
                    a.get(i)
                        .and_then(gltf::json::Value::as_f64)
                        .unwrap_or(default)
                };
                DVec2::new(at(0), at(1))
            })
    };
    let transform = TextureTransform {
        offset: pair("offset", 0.0),
        rotation: value
            .get("rotation")
            .and_then(|v| v.as_f64())
            .unwrap_or(0.0),
        scale: pair("scale", 1.0),
    };
    let set = value
        .get("texCoord")
        .and_then(|v| v.as_u64())
        .and_then(|s| u32::try_from(s).ok());
    Some((transform, set))
}

/// glTF's material `m` (number `i`) as hitkit reads it.
pub(super) fn material(i: usize, m: &gltf::Material) -> GltfMaterial {
    let color = m.pbr_metallic_roughness().base_color_factor();
    let emissive = m.emissive_factor();
    let info = |t: gltf::texture::Info, colour: bool| {
        let transform = t.texture_transform().map(|tt| {
            (
                TextureTransform {
                    offset: DVec2::from_array(tt.offset().map(f64::from)),
                    rotation: f64::from(tt.rotation()),
                    scale: DVec2::from_array(tt.scale().map(f64::from)),
                },
                tt.tex_coord(),
            )
        });
        GltfTexture::of(&t.texture(), t.tex_coord(), transform, colour)
    };
    GltfMaterial {
        name: m
            .name()
            .map_or_else(|| format!("material {i}"), ToString::to_string),
        index: Some(i),
        base_color: color.map(f64::from),
        alpha: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => Alpha::Opaque,
            gltf::material::AlphaMode::Mask => Alpha::Mask {
                cutoff: f64::from(m.alpha_cutoff().unwrap_or(0.5)),
            },
            gltf::material::AlphaMode::Blend => Alpha::Blend,
        },
        emissive: DVec3::from_array(emissive.map(f64::from))
            * f64::from(m.emissive_strength().unwrap_or(1.0)),
        double_sided: m.double_sided(),
        base_color_texture: m
            .pbr_metallic_roughness()
            .base_color_texture()
            .map(|t| info(t, true)),
        emissive_texture: m.emissive_texture().map(|t| info(t, true)),
        normal_texture: m.normal_texture().map(|t| {
            let transform = t
                .extensions()
                .and_then(|e| e.get("KHR_texture_transform"))
                .and_then(transform_of);
            GltfTexture::of(&t.texture(), t.tex_coord(), transform, false)
        }),
    }
}

/// glTF's default material, for primitives that name none: white, opaque, single-sided,
/// emitting nothing.
pub(super) fn default_material() -> GltfMaterial {
    GltfMaterial {
        name: String::from("default material"),
        index: None,
        base_color: [1.0; 4],
        alpha: Alpha::Opaque,
        emissive: DVec3::ZERO,
        double_sided: false,
        base_color_texture: None,
        emissive_texture: None,
        normal_texture: None,
    }
}
