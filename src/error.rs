//! [`GeometryError`]: why a shape, light or scene could not be built.

use core::fmt;

/// Why a shape could not be built. Every constructor that takes numbers returns it rather
/// than building something that would hit nothing or produce NaN.
///
/// ```
/// use hitkit::{glam::DVec3, GeometryError, Quad};
/// let err = Quad::new(DVec3::ZERO, DVec3::X, 2.0 * DVec3::X).unwrap_err();
/// assert_eq!(err, GeometryError::ParallelEdges);
/// assert_eq!(err.to_string(), "edge vectors u and v are parallel: they span no plane");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum GeometryError {
    /// An input is NaN or infinite.
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// An edge vector is zero.
    ZeroVector {
        /// Which vector.
        what: &'static str,
    },
    /// The edge vectors are parallel (to within rounding), so they span no plane.
    ParallelEdges,
    /// The edge vectors are so large or so small that `|u| |v|` or `u x v` overflows or
    /// underflows `f64` (for edges of equal length: past about 1e154 or below about 1e-154).
    OutOfRange,
    /// A shape parameter lies outside its domain.
    InvalidParameter {
        /// Which parameter.
        what: &'static str,
        /// The value given.
        value: f64,
        /// The domain it must lie in, for the message.
        domain: &'static str,
    },
    /// An element of a list (a mesh's vertex, say) is NaN or infinite.
    NonFiniteElement {
        /// Which list.
        what: &'static str,
        /// The element's position in it.
        index: usize,
    },
    /// A face names a vertex that does not exist.
    IndexOutOfRange {
        /// The face's position in the list of faces.
        face: usize,
        /// The vertex index it names.
        index: u32,
        /// How many vertices there are.
        vertices: usize,
    },
    /// A list is longer than the structure can number (`u32` indices).
    TooMany {
        /// Which list.
        what: &'static str,
        /// Its length.
        count: usize,
        /// The most it may hold.
        max: usize,
    },
    /// Two inputs that must be equally long are not (one weight per light, say).
    LengthMismatch {
        /// The input whose length is off.
        what: &'static str,
        /// The length it must have.
        expected: usize,
        /// The length it has.
        found: usize,
    },
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { what } => write!(f, "{what} is not finite (NaN or infinite)"),
            Self::ZeroVector { what } => write!(f, "{what} is the zero vector"),
            Self::ParallelEdges => f.write_str("edge vectors u and v are parallel: they span no plane"),
            Self::OutOfRange => f.write_str(
                "edge vectors u and v are too large or too small: their cross product overflows or underflows f64",
            ),
            Self::InvalidParameter { what, value, domain } => {
                write!(f, "{what} = {value} lies outside {domain}")
            }
            Self::NonFiniteElement { what, index } => {
                write!(f, "{what} {index} is not finite (NaN or infinite)")
            }
            Self::IndexOutOfRange {
                face,
                index,
                vertices,
            } => write!(
                f,
                "face {face} names vertex {index}, but there are {vertices} vertices"
            ),
            Self::TooMany { what, count, max } => {
                write!(f, "{count} {what} is more than the {max} that can be numbered")
            }
            Self::LengthMismatch {
                what,
                expected,
                found,
            } => write!(f, "{what} has {found} elements where {expected} are needed"),
        }
    }
}

impl core::error::Error for GeometryError {}
