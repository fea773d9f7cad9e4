//! How a [`Quad`](crate::Quad) light chooses directions toward itself: [`Sampling`].

/// How a [`Quad`](crate::Quad) light chooses directions toward itself ([`Quad::with_sampling`](crate::Quad::with_sampling)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum Sampling {
    /// Rectangles and triangles uniformly in the solid angle they subtend (Ureña et al.
    /// 2013, Arvo 1995) where it lies between 3e-4 and 6.22 steradians (pbrt-v4's
    /// bounds, where those samplers are accurate); everything else uniformly over its area.
    /// Lower variance near a light, for several times the cost per sample.
    #[default]
    SolidAngle,
    /// Uniformly over the shape's area, for every shape and origin: the cheapest sample, and
    /// as good as solid angle for lights that are small or far.
    Area,
}
