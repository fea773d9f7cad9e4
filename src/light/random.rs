//! [`RandomDirection`]: sampling a light with a `rand` generator (the `rand` feature).

use glam::{DVec2, DVec3};
use rand::Rng;

use crate::PdfHittable;

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
pub trait RandomDirection: PdfHittable {
    /// A direction from `origin` toward the light, from two uniform numbers of `[0, 1)`
    /// (53 random bits each) drawn from `rng`, and its density
    /// ([`pdf_value`](PdfHittable::pdf_value)); a density of 0 means the sample failed
    /// (see [`PdfHittable::sample_direction`]) and should not be divided by.
    fn random_direction<R: Rng + ?Sized>(&self, origin: DVec3, rng: &mut R) -> (DVec3, f64) {
        let u = DVec2::new(unit(rng.next_u64()), unit(rng.next_u64()));
        let direction = self.sample_direction(origin, u);
        (direction, self.pdf_value(origin, direction))
    }
}

impl<T: PdfHittable + ?Sized> RandomDirection for T {}

/// The top 53 bits of `bits` as a uniform number of `[0, 1)`.
#[inline]
fn unit(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}
