//! Sampling a light with a `rand` generator: [`RandomDirection`] for `rand` 0.10 (the
//! `rand` feature) and [`RandomDirection09`] for `rand` 0.9 (the `rand09` feature). One
//! trait cannot take both: their generators implement two versions of `rand_core`'s traits.

use glam::{DVec2, DVec3};

use crate::{LightSample, PdfHittable, ShadingContext};

/// Samples any [`PdfHittable`] (a `dyn` one too) with a `rand` 0.10 generator, beside the
/// [`sample_direction`](PdfHittable::sample_direction) that takes a point of `[0, 1)^2`
/// (which keeps the trait object safe and lets stratified or low-discrepancy samplers
/// drive it). Implemented for every `PdfHittable`; needs the `rand` feature.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{PdfHittable, Quad, RandomDirection};
/// use rand::SeedableRng;
///
/// let lamp = Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0).unwrap();
/// let light: &dyn PdfHittable = &lamp;
/// let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
/// let (direction, pdf) = light.random_direction(DVec3::ZERO, &mut rng);
/// assert!(direction.y > 0.0 && pdf > 0.0);
/// assert_eq!(pdf, light.pdf_value(DVec3::ZERO, direction));
/// ```
#[cfg(feature = "rand")]
pub trait RandomDirection: PdfHittable {
    /// A direction from `origin` toward the light, from two uniform numbers of `[0, 1)`
    /// (53 random bits each) drawn from `rng`, and its density
    /// ([`pdf_value`](PdfHittable::pdf_value)); a density of 0 means the sample failed
    /// (see [`PdfHittable::sample_direction`]) and should not be divided by.
    fn random_direction<R: rand::Rng + ?Sized>(&self, origin: DVec3, rng: &mut R) -> (DVec3, f64) {
        drawn(self, origin, || rng.next_u64())
    }

    /// A point on the light seen from `at`, for next-event estimation
    /// ([`sample_light`](PdfHittable::sample_light)), from two uniform numbers of `[0, 1)`
    /// drawn from `rng`: the direction, distance, the light's surface and the density.
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Quad, RandomDirection, ShadingContext};
    /// use rand::SeedableRng;
    ///
    /// let lamp = Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0).unwrap();
    /// let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
    /// let at = ShadingContext::on_surface(DVec3::ZERO, DVec3::Y);
    /// let sample = lamp.random_light(&at, &mut rng).unwrap();
    /// assert!(sample.pdf > 0.0 && sample.record.point.y == 2.0);
    /// ```
    fn random_light<R: rand::Rng + ?Sized>(
        &self,
        at: &ShadingContext,
        rng: &mut R,
    ) -> Option<LightSample> {
        lit(self, at, || rng.next_u64())
    }
}

#[cfg(feature = "rand")]
impl<T: PdfHittable + ?Sized> RandomDirection for T {}

/// [`RandomDirection`] for a `rand` 0.9 generator (the `rand09` feature): the same
/// directions from the same random bits.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{PdfHittable, Quad, RandomDirection09};
///
/// /// A stand-in for any `rand` 0.9 generator: a counter, through `rand_core` 0.9's trait.
/// struct Counter(u64);
/// impl rand09::RngCore for Counter {
///     fn next_u32(&mut self) -> u32 {
///         self.next_u64() as u32
///     }
///     fn next_u64(&mut self) -> u64 {
///         self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
///         self.0
///     }
///     fn fill_bytes(&mut self, dest: &mut [u8]) {
///         dest.iter_mut().for_each(|b| *b = self.next_u32() as u8);
///     }
/// }
///
/// let lamp = Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0).unwrap();
/// let (direction, pdf) = lamp.random_direction(DVec3::ZERO, &mut Counter(7));
/// assert!(direction.y > 0.0 && pdf > 0.0);
/// ```
#[cfg(feature = "rand09")]
pub trait RandomDirection09: PdfHittable {
    /// As [`RandomDirection::random_direction`], from a `rand` 0.9 generator.
    fn random_direction<R: rand09::RngCore + ?Sized>(
        &self,
        origin: DVec3,
        rng: &mut R,
    ) -> (DVec3, f64) {
        drawn(self, origin, || rng.next_u64())
    }

    /// As [`RandomDirection::random_light`], from a `rand` 0.9 generator.
    fn random_light<R: rand09::RngCore + ?Sized>(
        &self,
        at: &ShadingContext,
        rng: &mut R,
    ) -> Option<LightSample> {
        lit(self, at, || rng.next_u64())
    }
}

#[cfg(feature = "rand09")]
impl<T: PdfHittable + ?Sized> RandomDirection09 for T {}

/// A direction toward `light` from two uniform numbers made of `next`'s bits, and its
/// density.
fn drawn<L: PdfHittable + ?Sized>(
    light: &L,
    origin: DVec3,
    mut next: impl FnMut() -> u64,
) -> (DVec3, f64) {
    let u = DVec2::new(uniform(next()), uniform(next()));
    let direction = light.sample_direction(origin, u);
    (direction, light.pdf_value(origin, direction))
}

/// A point on `light` seen from `at`, from two uniform numbers made of `next`'s bits.
fn lit<L: PdfHittable + ?Sized>(
    light: &L,
    at: &ShadingContext,
    mut next: impl FnMut() -> u64,
) -> Option<LightSample> {
    let u = DVec2::new(uniform(next()), uniform(next()));
    light.sample_light(at, u)
}

/// The top 53 bits of `bits` as a uniform number of `[0, 1)`.
#[inline]
fn uniform(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}
