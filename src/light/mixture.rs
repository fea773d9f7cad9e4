//! Several lights as one, each picked with a probability of its own: by power, say, so that
//! samples go where the light comes from.

use alloc::vec::Vec;

use glam::{DVec2, DVec3};

use crate::math::power_of_two_scale;
use crate::{
    Aabb, GeometryError, HitRecord, Hittable, Interval, LightSample, PdfHittable, Ray,
    ShadingContext,
};

/// Lights picked with probabilities proportional to given weights, as one [`PdfHittable`]:
/// `sample_direction` picks light `i` with probability `p_i` and samples it;
/// `pdf_value` is `sum p_i pdf_i`, the density of that two-step choice (a light's samples
/// may pass through another, so every light's density counts).
///
/// Weighting by power (emitted radiance times area, for diffuse emitters) sends samples
/// where the light comes from; a slice or `Vec` of lights is the uniform mixture. As a
/// [`Hittable`], the mixture is the list of its lights (the closest hit).
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{Mixture, PdfHittable, Quad};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// // A bright panel above and a dim one to the side: 9 times the power, 9 times the samples.
/// let bright = Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0)?;
/// let dim = Quad::new(DVec3::new(3.0, -1.0, -1.0), DVec3::Y * 2.0, DVec3::Z * 2.0)?;
/// let power = |radiance: f64, light: &Quad| radiance * light.area();
/// let weights = [power(9.0, &bright), power(1.0, &dim)];
/// let lights = Mixture::new(vec![bright, dim], &weights)?;
/// assert_eq!(lights.probability(0), 0.9);
///
/// let up = DVec3::Y;
/// assert_eq!(lights.pdf_value(DVec3::ZERO, up), 0.9 * bright.pdf_value(DVec3::ZERO, up));
/// let d = lights.sample_direction(DVec3::ZERO, DVec2::new(0.95, 0.5)); // the dim one
/// assert!(d.x > 0.0 && lights.pdf_value(DVec3::ZERO, d) > 0.0);
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug)]
pub struct Mixture<T> {
    lights: Vec<T>,
    probabilities: Vec<f64>,
    /// `cumulative[i]`: the probability of lights `0..=i`; the last one is exactly 1.
    cumulative: Vec<f64>,
}

impl<T> Mixture<T> {
    /// `lights`, light `i` picked with probability `weights[i] / sum(weights)`. A light of
    /// weight 0 is never sampled (its density does not count either).
    ///
    /// # Errors
    /// [`GeometryError::LengthMismatch`] if `weights` and `lights` differ in length;
    /// [`GeometryError::InvalidParameter`] if a weight is negative, or if all are 0 (with at
    /// least one light); [`GeometryError::NonFinite`] if a weight is NaN or infinite.
    pub fn new(lights: Vec<T>, weights: &[f64]) -> Result<Self, GeometryError> {
        if weights.len() != lights.len() {
            return Err(GeometryError::LengthMismatch {
                what: "weights",
                expected: lights.len(),
                found: weights.len(),
            });
        }
        for &weight in weights {
            if !weight.is_finite() {
                return Err(GeometryError::NonFinite { what: "weight" });
            }
            if weight < 0.0 {
                return Err(GeometryError::InvalidParameter {
                    what: "weight",
                    value: weight,
                    domain: "[0, infinity)",
                });
            }
        }
        let largest = weights.iter().copied().fold(0.0, f64::max);
        if largest == 0.0 && !weights.is_empty() {
            return Err(GeometryError::InvalidParameter {
                what: "sum of weights",
                value: 0.0,
                domain: "(0, infinity)",
            });
        }
        // Scaled exactly, by a power of two, so that the sum cannot overflow.
        let scale = power_of_two_scale(largest);
        let total: f64 = weights.iter().map(|w| w * scale).sum();
        let probabilities: Vec<f64> = weights.iter().map(|w| w * scale / total).collect();
        let mut sum = 0.0;
        let mut cumulative: Vec<f64> = probabilities
            .iter()
            .map(|p| {
                sum += p;
                sum
            })
            .collect();
        // Every u.x below 1 must pick a light: the last one with a non-zero probability
        // ends the distribution exactly at 1, whatever the rounding of the sum.
        if let Some(last) = probabilities.iter().rposition(|&p| p > 0.0) {
            cumulative[last..].fill(1.0);
        }
        Ok(Self {
            lights,
            probabilities,
            cumulative,
        })
    }

    /// `lights`, each picked with the same probability: what a slice of them does.
    #[must_use]
    pub fn uniform(lights: Vec<T>) -> Self {
        let weights = alloc::vec![1.0; lights.len()];
        Self::new(lights, &weights).expect("equal positive weights are valid")
    }

    /// The lights, in the order given.
    #[inline]
    #[must_use]
    pub fn lights(&self) -> &[T] {
        &self.lights
    }

    /// The light `u` in `[0, 1)` picks (the first whose cumulative probability exceeds
    /// it), with its probability and what is left of `u`, rescaled to `[0, 1)`: what
    /// [`sample_direction`](PdfHittable::sample_direction) does before sampling the light,
    /// for next-event estimation that divides by the probability times the light's own
    /// density. `None` for an empty mixture.
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Mixture, Sphere};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// let lights = Mixture::new(
    ///     vec![Sphere::new(DVec3::Y * 5.0, 1.0)?, Sphere::new(DVec3::X * 5.0, 1.0)?],
    ///     &[3.0, 1.0],
    /// )?;
    /// let pick = lights.pick(0.8).unwrap();
    /// assert_eq!((pick.light, pick.probability), (1, 0.25));
    /// assert!((pick.rest - 0.2).abs() < 1e-12);
    /// # Ok(())
    /// # }
    /// ```
    #[must_use]
    pub fn pick(&self, u: f64) -> Option<crate::LightPick> {
        // Into [0, 1) (NaN to 0): below the last cumulative probability, exactly 1, so the
        // light found has a non-zero probability.
        let x = if u > 0.0 {
            u.min(1.0 - f64::EPSILON / 2.0)
        } else {
            0.0
        };
        let light = self.cumulative.partition_point(|&c| c <= x);
        let probability = *self.probabilities.get(light)?;
        let below = light.checked_sub(1).map_or(0.0, |i| self.cumulative[i]);
        let rest = ((x - below) / probability).clamp(0.0, 1.0 - f64::EPSILON / 2.0);
        Some(crate::LightPick {
            light,
            probability,
            rest,
        })
    }

    /// The probability with which light `i` is sampled.
    ///
    /// # Panics
    /// If `i >= self.lights().len()`.
    #[inline]
    #[must_use]
    pub fn probability(&self, i: usize) -> f64 {
        self.probabilities[i]
    }
}

impl<T: Hittable> Hittable for Mixture<T> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.lights.hit(ray, ray_t)
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.lights.bounding_box()
    }

    #[inline]
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        self.lights.occluded(ray, ray_t)
    }
}

impl<T: PdfHittable> PdfHittable for Mixture<T> {
    /// `sum p_i pdf_i` over the lights of non-zero probability; 0 for an empty mixture.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.lights
            .iter()
            .zip(&self.probabilities)
            .filter(|&(_, &p)| p > 0.0)
            .map(|(light, p)| p * light.pdf_value(origin, direction))
            .sum()
    }

    /// `u.x` picks the light (the first whose cumulative probability exceeds it) and, scaled
    /// back to `[0, 1)` within that light's share, becomes the light's own `u.x`. The zero
    /// vector for an empty mixture.
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.pick(u.x).map_or(DVec3::ZERO, |pick| {
            self.lights[pick.light].sample_direction(origin, DVec2::new(pick.rest, u.y))
        })
    }

    /// The light [`sample_direction`](PdfHittable::sample_direction) picks, sampled: its
    /// surface along the direction and the mixture's density (the provided way), or where
    /// it has no density (a [`PunctualLight`](crate::PunctualLight)), its own delta sample
    /// with `pdf` times its probability.
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        let pick = self.pick(u.x)?;
        let light = &self.lights[pick.light];
        let u = DVec2::new(pick.rest, u.y);
        let direction = light.sample_direction(at.point, u);
        if direction == DVec3::ZERO {
            return crate::sample::delta_pick(
                light.sample_light(at, u),
                pick.probability,
                pick.light,
            );
        }
        LightSample::along(self, at, direction)
    }

    #[inline]
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        self.lights.light_hit(ray, ray_t)
    }
}
