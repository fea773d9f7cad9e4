//! The uniform mixture of lights: a slice or `Vec` of lights picks each with the same
//! probability. [`Mixture`](crate::Mixture) weighs them.

use alloc::vec::Vec;

use glam::{DVec2, DVec3};

use crate::{HitRecord, Interval, LightSample, PdfHittable, Ray, ShadingContext};

/// A uniform mixture of lights: `sample_direction` picks one with probability `1 / n` (by
/// `u.x`, whose remaining digits are reused for the light's own sample, so one point of
/// `[0, 1)^2` still makes one direction), and `pdf_value` is the mean of their densities,
/// which is the mixture's density. An empty list has density 0 everywhere and samples
/// the zero direction, which hits nothing.
impl<T: PdfHittable> PdfHittable for [T] {
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        // Each density divided first: the sum of the quotients cannot overflow, as the sum
        // of densities near f64::MAX can.
        let n = self.len() as f64;
        self.iter()
            .map(|light| light.pdf_value(origin, direction) / n)
            .sum::<f64>()
    }

    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        pick(self, u).map_or(DVec3::ZERO, |(index, rest)| {
            self[index].sample_direction(origin, rest)
        })
    }

    /// The light [`sample_direction`](PdfHittable::sample_direction) picks, sampled: its
    /// surface along the direction and the list's density (the provided way), or where it
    /// has no density (a [`PunctualLight`](crate::PunctualLight)), its own delta sample
    /// with `pdf` times `1 / n`.
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        let (index, rest) = pick(self, u)?;
        let direction = self[index].sample_direction(at.point, rest);
        if direction == DVec3::ZERO {
            let p = 1.0 / self.len() as f64;
            return crate::sample::delta_pick(self[index].sample_light(at, rest), p, index);
        }
        LightSample::along(self, at, direction)
    }

    /// The nearest of the lights' [`light_hit`](PdfHittable::light_hit)s (of hits at the
    /// same `t`, the first light's, as `hit` keeps them), and that light's index.
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        let mut closest: Option<(usize, HitRecord)> = None;
        for (i, light) in self.iter().enumerate() {
            let max = closest.map_or(ray_t.max, |(_, h)| h.t);
            if let Some((_, h)) = light.light_hit(ray, Interval::new(ray_t.min, max))
                && closest.is_none_or(|(_, c)| h.t < c.t)
            {
                closest = Some((i, h));
            }
        }
        closest
    }
}

/// The light `u.x` picks from `lights` (each alike) and the point for its own sample:
/// what is left of `u.x`, rescaled to `[0, 1]`, and `u.y`; `None` for no light.
#[inline]
fn pick<T>(lights: &[T], u: DVec2) -> Option<(usize, DVec2)> {
    let last = lights.len().checked_sub(1)?;
    let scaled = u.x.clamp(0.0, 1.0) * lights.len() as f64;
    let index = (scaled as usize).min(last);
    Some((
        index,
        DVec2::new((scaled - index as f64).clamp(0.0, 1.0), u.y),
    ))
}

impl<T: PdfHittable> PdfHittable for Vec<T> {
    #[inline]
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.as_slice().pdf_value(origin, direction)
    }
    #[inline]
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.as_slice().sample_direction(origin, u)
    }
    #[inline]
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        self.as_slice().sample_light(at, u)
    }
    #[inline]
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        self.as_slice().light_hit(ray, ray_t)
    }
}
