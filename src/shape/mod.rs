//! The shapes: the infinite [`Plane`] and the flat shapes on it ([`Quad`] with its
//! interiors), [`Sphere`] and [`Cuboid`]. The plane's exact-crossing machinery, which the
//! flat shapes decide by, sits apart in `crossing.rs`.

mod area;
mod crossing;
mod cuboid;
mod interior;
mod plane;
mod quad;
mod sphere;
mod spherical;

pub use area::{Polygon, SampleInterior};
pub use crossing::CrossingRegion;
pub(crate) use crossing::{Crossing, Decided, Pending};
pub use cuboid::Cuboid;
pub use interior::{Disk, Exact, Interior, Meets, Parallelogram, Ring, Triangle};
pub use plane::{Plane, PlaneHit};
pub use quad::{Quad, Sampling};
pub use sphere::Sphere;
pub(crate) use spherical::{Spherical, View};
