//! Images for materials: decoded once (PNG or JPEG, through the `image` crate), kept as
//! linear RGBA, looked up bilinearly with glTF's default sampler (repeat, linear).

use std::path::Path;

use hitkit::glam::{DVec2, DVec4};

/// An image as linear RGBA, row by row from the top (glTF's `uv` (0, 0) is the image's
/// top-left corner).
#[derive(Debug)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<DVec4>,
}

impl Texture {
    /// The image at `path`; `srgb` for colour (base colour, emission: sRGB-encoded, as
    /// glTF says), not for data (alpha is always linear).
    pub fn load(path: &Path, srgb: bool) -> Result<Self, String> {
        let image = image::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(Self::from_rgba8(&image.to_rgba8(), srgb))
    }

    /// An image from encoded bytes (a `.glb`'s or a data URI's).
    pub fn decode(bytes: &[u8], srgb: bool) -> Result<Self, String> {
        let image = image::load_from_memory(bytes).map_err(|e| e.to_string())?;
        Ok(Self::from_rgba8(&image.to_rgba8(), srgb))
    }

    /// An image of 8-bit channels (1 to 4 of them: grey, grey and alpha, RGB, RGBA), as a
    /// glTF loader decodes one; `None` for another channel count or a short buffer.
    pub fn from_pixels(
        width: u32,
        height: u32,
        channels: usize,
        bytes: &[u8],
        srgb: bool,
    ) -> Option<Self> {
        let n = width as usize * height as usize;
        if !(1..=4).contains(&channels) || bytes.len() < n * channels {
            return None;
        }
        let rgba: Vec<u8> = bytes
            .chunks_exact(channels)
            .take(n)
            .flat_map(|p| match channels {
                1 => [p[0], p[0], p[0], 255],
                2 => [p[0], p[0], p[0], p[1]],
                3 => [p[0], p[1], p[2], 255],
                _ => [p[0], p[1], p[2], p[3]],
            })
            .collect();
        let image = image::RgbaImage::from_raw(width, height, rgba)?;
        Some(Self::from_rgba8(&image, srgb))
    }

    fn from_rgba8(image: &image::RgbaImage, srgb: bool) -> Self {
        let decode = |c: u8| {
            let c = f64::from(c) / 255.0;
            if !srgb {
                c
            } else if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        let texels = image
            .pixels()
            .map(|p| {
                DVec4::new(
                    decode(p[0]),
                    decode(p[1]),
                    decode(p[2]),
                    f64::from(p[3]) / 255.0,
                )
            })
            .collect();
        Self {
            width: image.width() as usize,
            height: image.height() as usize,
            texels,
        }
    }

    /// The texture at `uv`, bilinearly between the four nearest texels, the image repeated
    /// beyond `[0, 1]`.
    pub fn sample(&self, uv: DVec2) -> DVec4 {
        if self.texels.is_empty() || !uv.is_finite() {
            return DVec4::ONE;
        }
        let x = uv.x * self.width as f64 - 0.5;
        let y = uv.y * self.height as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: f64, j: f64| {
            let i = (i as i64).rem_euclid(self.width as i64) as usize;
            let j = (j as i64).rem_euclid(self.height as i64) as usize;
            self.texels[j * self.width + i]
        };
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
        let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The mean of the texture's luminance (Rec. 709) over the triangle of `uvs`, from a
    /// grid of 45 points inside it: what a textured emitter's face emits on average, for
    /// its power among the lights.
    pub fn mean_luminance(&self, uvs: [DVec2; 3]) -> f64 {
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
                let t = self.sample(uv);
                sum += 0.2126 * t.x + 0.7152 * t.y + 0.0722 * t.z;
                count += 1;
            }
        }
        sum / count as f64
    }
}
