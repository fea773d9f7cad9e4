//! The images a glTF scene's textures read: decoded (behind the `gltf-images` feature)
//! into 8-bit RGBA, and looked up with a texture's sampler.

use std::sync::Arc;
use std::vec::Vec;

use glam::{DVec2, DVec4};

use super::{Filter, GltfTexture, Wrap};

/// An image of a glTF file, as its texels (8-bit RGBA, row by row from the top: glTF's
/// `uv` (0, 0) is the image's top-left corner), kept as stored, four bytes a texel; colour
/// is decoded from sRGB on lookup.
///
/// ```
/// use hitkit::glam::{DVec2, DVec4};
/// use hitkit::load::GltfImage;
///
/// // Two texels side by side: black and white, opaque.
/// let image = GltfImage::new(2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 255]]).unwrap();
/// assert_eq!(image.texel(1, 0), [255, 255, 255, 255]);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GltfImage {
    width: usize,
    height: usize,
    texels: Vec<[u8; 4]>,
}

/// sRGB's 256 codes as linear values (the IEC 61966-2-1 curve).
fn srgb_table() -> &'static [f64; 256] {
    static TABLE: std::sync::OnceLock<[f64; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        core::array::from_fn(|i| {
            let c = i as f64 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
    })
}

impl GltfImage {
    /// An image of `width` x `height` texels, row by row from the top; `None` where
    /// `texels` holds another number of them (or none).
    #[must_use]
    pub fn new(width: usize, height: usize, texels: Vec<[u8; 4]>) -> Option<Self> {
        (width > 0 && height > 0 && width.checked_mul(height) == Some(texels.len())).then_some(
            Self {
                width,
                height,
                texels,
            },
        )
    }

    /// Its width in texels.
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Its height in texels.
    #[must_use]
    pub fn height(&self) -> usize {
        self.height
    }

    /// The texel in column `x`, row `y` (from the top), as stored; clamped to the image.
    #[must_use]
    pub fn texel(&self, x: usize, y: usize) -> [u8; 4] {
        self.texels[y.min(self.height - 1) * self.width + x.min(self.width - 1)]
    }

    /// The bytes its texels take.
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        self.texels.capacity() * 4
    }

    /// The image at `uv` as `texture` reads it: wrapped and filtered by its sampler, its
    /// colour linear (decoded from sRGB where `texture.colour`), alpha linear; `uv` not
    /// finite reads the origin.
    #[must_use]
    pub fn sample(&self, uv: DVec2, texture: &GltfTexture) -> DVec4 {
        let uv = if uv.is_finite() { uv } else { DVec2::ZERO };
        let decode = |t: [u8; 4]| {
            let alpha = f64::from(t[3]) / 255.0;
            if texture.colour {
                let table = srgb_table();
                DVec4::new(
                    table[usize::from(t[0])],
                    table[usize::from(t[1])],
                    table[usize::from(t[2])],
                    alpha,
                )
            } else {
                DVec4::new(
                    f64::from(t[0]) / 255.0,
                    f64::from(t[1]) / 255.0,
                    f64::from(t[2]) / 255.0,
                    alpha,
                )
            }
        };
        let sampler = texture.sampler;
        let (x, y) = (uv.x * self.width as f64, uv.y * self.height as f64);
        match sampler.filter {
            Filter::Nearest => {
                let i = wrap(x.floor(), self.width, sampler.wrap_u);
                let j = wrap(y.floor(), self.height, sampler.wrap_v);
                decode(self.texels[j * self.width + i])
            }
            Filter::Linear => {
                // Between the four texel centres around the point.
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let (i0, i1) = (
                    wrap(x0, self.width, sampler.wrap_u),
                    wrap(x0 + 1.0, self.width, sampler.wrap_u),
                );
                let (j0, j1) = (
                    wrap(y0, self.height, sampler.wrap_v),
                    wrap(y0 + 1.0, self.height, sampler.wrap_v),
                );
                let at = |i: usize, j: usize| decode(self.texels[j * self.width + i]);
                let top = at(i0, j0) * (1.0 - fx) + at(i1, j0) * fx;
                let bottom = at(i0, j1) * (1.0 - fx) + at(i1, j1) * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }

    /// The mean of the image's luminance (Rec. 709, linear) over the triangle of `uvs`
    /// (already under the texture's transform), as `texture` reads it, from a grid of 45
    /// points inside it: what a textured emitter's face emits on average, for its power
    /// among the lights.
    #[must_use]
    pub fn mean_luminance(&self, uvs: [DVec2; 3], texture: &GltfTexture) -> f64 {
        const N: usize = 8;
        let mut sum = 0.0;
        let mut count = 0;
        for i in 0..=N {
            for j in 0..=N - i {
                let (a, b) = (
                    (i as f64 + 1.0 / 3.0) / (N as f64 + 1.0),
                    (j as f64 + 1.0 / 3.0) / (N as f64 + 1.0),
                );
                let uv = uvs[0] * (1.0 - a - b) + uvs[1] * a + uvs[2] * b;
                let t = self.sample(uv, texture);
                sum += 0.2126 * t.x + 0.7152 * t.y + 0.0722 * t.z;
                count += 1;
            }
        }
        sum / f64::from(count)
    }
}

/// Texel coordinate `i` (whole, any value) of an axis of `n` texels, wrapped as `mode` says.
fn wrap(i: f64, n: usize, mode: Wrap) -> usize {
    // Past `i64`'s range (and NaN, which `as` makes 0), the cast saturates: still a texel.
    let (i, n) = (i as i64, n as i64);
    let k = match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let k = i.rem_euclid(2 * n);
            if k < n { k } else { 2 * n - 1 - k }
        }
    };
    k as usize
}

/// The images the materials' base colour and emissive textures read, decoded, in the
/// file's order (`None` for the rest); an image that cannot be decoded is left out, named.
#[cfg(feature = "gltf-images")]
pub(super) fn decode(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    base: Option<&std::path::Path>,
    materials: &[super::GltfMaterial],
    left_out: &mut Vec<super::LeftOut>,
) -> Vec<Option<Arc<GltfImage>>> {
    let count = document.images().count();
    let mut wanted = std::vec![false; count];
    for m in materials {
        for t in [m.base_color_texture, m.emissive_texture]
            .into_iter()
            .flatten()
        {
            if let Some(w) = wanted.get_mut(t.image) {
                *w = true;
            }
        }
    }
    // Those the first stage found unreadable are listed already.
    for left in left_out.iter() {
        if let super::LeftOut::Image { image, .. } = left
            && let Some(w) = wanted.get_mut(*image)
        {
            *w = false;
        }
    }
    let images: Vec<gltf::Image> = document.images().collect();
    // Decoding is most of a textured file's set-up: the images are decoded on every core,
    // each thread taking the next image in turn.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let mut results: Vec<Option<Result<GltfImage, std::string::String>>> = std::vec![None; count];
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads.min(count))
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(image) = images.get(i) else { break };
                        if wanted[i] {
                            let decoded =
                                gltf::image::Data::from_source(image.source(), base, buffers)
                                    .map_err(|e| std::format!("{}: {e}", named(image, base)))
                                    .and_then(|d| rgba(&d));
                            done.push((i, decoded));
                        }
                    }
                    done
                })
            })
            .collect();
        for worker in workers {
            // A decoder that panicked leaves its images undecoded (listed below).
            for (i, decoded) in worker.join().unwrap_or_default() {
                results[i] = Some(decoded);
            }
        }
    });
    for (i, result) in results.iter_mut().enumerate() {
        if wanted[i] && result.is_none() {
            *result = Some(Err("its decoder stopped".into()));
        }
    }
    results
        .into_iter()
        .enumerate()
        .map(|(image, result)| match result? {
            Ok(decoded) => Some(Arc::new(decoded)),
            Err(reason) => {
                left_out.push(super::LeftOut::Image { image, reason });
                None
            }
        })
        .collect()
}

/// An image as a message names it: its file (beside the glTF file) or its buffer view,
/// and its type where the file gives one.
#[cfg(feature = "gltf-images")]
fn named(image: &gltf::Image, base: Option<&std::path::Path>) -> std::string::String {
    use std::string::ToString;
    match image.source() {
        gltf::image::Source::Uri { uri, mime_type } if !uri.starts_with("data:") => {
            let file = super::read::decoded(uri);
            let file = base.map_or(file.clone(), |b| b.join(&file).display().to_string());
            match mime_type {
                Some(mime) => std::format!("{file} ({mime})"),
                None => file,
            }
        }
        gltf::image::Source::Uri { mime_type, .. } => {
            std::format!("an inline image ({})", mime_type.unwrap_or("no type given"))
        }
        gltf::image::Source::View { view, mime_type } => {
            std::format!("buffer view {} ({mime_type})", view.index())
        }
    }
}

/// Without the `gltf-images` feature, no image is decoded.
#[cfg(not(feature = "gltf-images"))]
pub(super) fn decode(
    document: &gltf::Document,
    _: &[gltf::buffer::Data],
    _: Option<&std::path::Path>,
    _: &[super::GltfMaterial],
    _: &mut Vec<super::LeftOut>,
) -> Vec<Option<Arc<GltfImage>>> {
    std::vec![None; document.images().count()]
}

/// A decoded image as 8-bit RGBA: grey, grey and alpha, RGB and RGBA of 8 or 16 bits (the
/// high byte kept) or of floats (clamped to `[0, 1]`).
#[cfg(feature = "gltf-images")]
fn rgba(data: &gltf::image::Data) -> Result<GltfImage, std::string::String> {
    use gltf::image::Format;
    let (channels, bytes) = match data.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        Format::R32G32B32FLOAT => (3, 4),
        Format::R32G32B32A32FLOAT => (4, 4),
    };
    let value = |p: &[u8]| -> u8 {
        match bytes {
            1 => p[0],
            // Little-endian 16 bits, as the `gltf` crate lays them out: the high byte.
            2 => p[1],
            _ => {
                let f = f32::from_le_bytes([p[0], p[1], p[2], p[3]]);
                (f.clamp(0.0, 1.0) * 255.0).round() as u8
            }
        }
    };
    let (width, height) = (data.width as usize, data.height as usize);
    let texel = channels * bytes;
    if data.pixels.len() < width * height * texel {
        return Err(std::format!(
            "{} bytes for {width} x {height} texels",
            data.pixels.len()
        ));
    }
    let texels = data
        .pixels
        .chunks_exact(texel)
        .take(width * height)
        .map(|p| {
            let c = |k: usize| value(&p[k * bytes..]);
            match channels {
                1 => [c(0), c(0), c(0), 255],
                2 => [c(0), c(0), c(0), c(1)],
                3 => [c(0), c(1), c(2), 255],
                _ => [c(0), c(1), c(2), c(3)],
            }
        })
        .collect();
    GltfImage::new(width, height, texels).ok_or_else(|| "an image of no texels".into())
}

#[cfg(test)]
mod tests {
    use super::{Wrap, wrap};

    #[test]
    fn wrapping_lands_on_a_texel_for_any_coordinate() {
        let n = 3;
        let repeat: std::vec::Vec<usize> = (-4..5)
            .map(|i| wrap(f64::from(i), n, Wrap::Repeat))
            .collect();
        assert_eq!(repeat, [2, 0, 1, 2, 0, 1, 2, 0, 1]);
        let mirror: std::vec::Vec<usize> = (-4..7)
            .map(|i| wrap(f64::from(i), n, Wrap::MirroredRepeat))
            .collect();
        assert_eq!(mirror, [2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0]);
        let clamp: std::vec::Vec<usize> = (-2..5)
            .map(|i| wrap(f64::from(i), n, Wrap::ClampToEdge))
            .collect();
        assert_eq!(clamp, [0, 0, 0, 1, 2, 2, 2]);
        for mode in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
            for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300] {
                assert!(wrap(x, n, mode) < n);
            }
        }
    }
}
