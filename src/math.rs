//! The float functions `core` lacks, and the rounding-error arithmetic shared by every
//! module: one place for each piece of numerical machinery.

/// Unit roundoff of `f64` (half the machine epsilon), as pbrt-v4's `MachineEpsilon`.
pub(crate) const UNIT_ROUNDOFF: f64 = f64::EPSILON * 0.5;

/// `gamma(n) = n u / (1 - n u)`: bounds the relative error of `n` chained roundings
/// (Higham, *Accuracy and Stability of Numerical Algorithms*, 3.1; pbrt-v4 section 6.8.1).
#[inline]
#[must_use]
pub(crate) const fn gamma(n: u32) -> f64 {
    let nu = n as f64 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

#[inline]
#[must_use]
pub(crate) fn sqrt(x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.sqrt()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sqrt(x)
    }
}

/// `v / |v|` and `|v|`, without overflow or underflow in the squares: where `|v|^2` is
/// far from both (in `[2^-960, 2^960]`: the book's normalization, no dearer), as it is;
/// else `v` is first scaled by the power of two (an exact scaling) that brings its largest
/// component near 1, which gives the same bits but for the squares the first way lost to
/// underflow (each below `2^-1074`, against a sum of at least `2^-960`). For a zero vector,
/// `(NaN, 0)`.
#[inline]
#[must_use]
pub(crate) fn unit_and_length(v: glam::DVec3) -> (glam::DVec3, f64) {
    let squared = v.dot(v);
    if (SQUARED_LOW..=SQUARED_HIGH).contains(&squared) {
        let length = sqrt(squared);
        return (v / length, length);
    }
    unit_and_length_scaled(v)
}

/// The range of `|v|^2` in which [`unit_and_length`] and [`length`] need no scaling.
const SQUARED_LOW: f64 = f64::from_bits((1023 - 960) << 52);
const SQUARED_HIGH: f64 = f64::from_bits((1023 + 960) << 52);

/// [`unit_and_length`] by the scaling.
#[cold]
#[inline(never)]
fn unit_and_length_scaled(v: glam::DVec3) -> (glam::DVec3, f64) {
    let scale = power_of_two_scale(v.abs().max_element());
    let scaled = v * scale;
    let length = scaled.length();
    (scaled / length, length / scale)
}

/// `|v|`, as [`unit_and_length`] gives it (the same bits), for the price of a length: the
/// scaling undone by multiplying by its reciprocal, also a power of two, not by a division.
#[inline]
#[must_use]
pub(crate) fn length(v: glam::DVec3) -> f64 {
    let squared = v.dot(v);
    if (SQUARED_LOW..=SQUARED_HIGH).contains(&squared) {
        return sqrt(squared);
    }
    let exponent = ((v.abs().max_element().to_bits() >> 52) & 0x7ff) as i64 - 1023;
    let exponent = exponent.clamp(-1022, 1022);
    let scale = f64::from_bits(((1023 - exponent) as u64) << 52);
    let unscale = f64::from_bits(((1023 + exponent) as u64) << 52);
    (v * scale).length() * unscale
}

/// The power of two that brings finite `largest >= 0` into `[1, 2)` (clamped to the normal
/// range): multiplying by it is exact, so sums and squares of the scaled values neither
/// overflow nor underflow.
#[inline]
#[must_use]
pub(crate) fn power_of_two_scale(largest: f64) -> f64 {
    let exponent = ((largest.to_bits() >> 52) & 0x7ff) as i64 - 1023;
    f64::from_bits(((1023 - exponent.clamp(-1022, 1022)) as u64) << 52)
}

/// The power of two by which a ray's direction is scaled before tests whose arithmetic
/// over- or underflows for directions far from unit length (reciprocals, squares, the
/// `f32` lanes): 1 for an [`ordinary`] direction (every ordinary ray, which so pays
/// nothing), and otherwise the one that brings its largest component into `[1, 2)`
/// (or to `2^-52` and up, for a subnormal one), where that scaling is exact; 1 where it is
/// not (a huge direction whose smallest components would turn subnormal), and for a
/// direction that cannot be traced (zero, infinite or NaN). A scaled direction needs no
/// further scaling. Since the scaling is exact, a `t` found along the scaled direction is
/// exactly `1 / scale` times the one along the given direction, barring over- and
/// underflow.
#[inline]
#[must_use]
pub(crate) fn direction_scale(d: glam::DVec3) -> f64 {
    if ordinary(d) {
        return 1.0;
    }
    let largest = d.abs().max_element();
    // (Nor is a zero, infinite or NaN direction scaled: it cannot be traced.)
    if !(largest > 0.0 && largest < f64::INFINITY) {
        return 1.0;
    }
    let scale = power_of_two_scale(largest);
    if d * scale * (1.0 / scale) == d {
        scale
    } else {
        1.0
    }
}

/// Whether a direction needs no scaling ([`direction_scale`] is 1 for it): `|d|_1` lies
/// in `[2^-32, 2^32]` (so it is also finite, non-zero and not NaN, which the sum
/// propagates).
#[inline(always)]
#[must_use]
pub(crate) fn ordinary(d: glam::DVec3) -> bool {
    ordinary_length(d.abs().element_sum())
}

/// [`ordinary`] of a direction whose `|d|_1` is `d1`.
#[inline(always)]
#[must_use]
pub(crate) fn ordinary_length(d1: f64) -> bool {
    const SMALL: f64 = 1.0 / (1u64 << 32) as f64;
    const LARGE: f64 = (1u64 << 32) as f64;
    (SMALL..=LARGE).contains(&d1)
}

/// `x * factor` for a power of two `factor`, rounded down (`down`) or up: exact in the
/// normal range; where the product under- or overflows, the float on that side of the
/// exact product. (Scaled back, the rounded product tells which side it fell on: that
/// scaling is exact.)
#[inline]
#[must_use]
pub(crate) fn scaled_outward(x: f64, factor: f64, down: bool) -> f64 {
    let y = x * factor;
    let back = y / factor;
    if down && back > x {
        y.next_down()
    } else if !down && back < x {
        y.next_up()
    } else {
        y
    }
}

/// `(sin x, cos x)`.
#[inline]
#[must_use]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    #[cfg(feature = "std")]
    {
        x.sin_cos()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sincos(x)
    }
}

#[inline]
#[must_use]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        y.atan2(x)
    }
    #[cfg(not(feature = "std"))]
    {
        libm::atan2(y, x)
    }
}

#[inline]
#[must_use]
pub(crate) fn acos(x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.acos()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::acos(x)
    }
}

/// `a * b + c` with one rounding.
#[inline]
#[must_use]
pub(crate) fn mul_add(a: f64, b: f64, c: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        a.mul_add(b, c)
    }
    #[cfg(not(feature = "std"))]
    {
        libm::fma(a, b, c)
    }
}

/// An unevaluated sum `hi + lo` with `|lo| <= ulp(hi) / 2`: about 106 significant bits, for
/// the rare decisions that `f64` cannot settle (double-double arithmetic: Dekker 1971;
/// Hida, Li and Bailey 2001, "Algorithms for quad-double precision floating point
/// arithmetic"). Each operation below has a relative error of at most `4 u^2` of the
/// magnitudes it combines (`u` the unit roundoff), which is all the callers rely on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Dd {
    pub(crate) hi: f64,
    pub(crate) lo: f64,
}

impl Dd {
    /// `a - b`, exactly (Knuth's two-sum).
    #[inline]
    pub(crate) fn diff(a: f64, b: f64) -> Self {
        two_sum(a, -b)
    }

    /// `a * b`, exactly (barring underflow): the error of the rounded product is itself a
    /// float. A fused multiply-add recovers it where the target has one; elsewhere (the
    /// default x86-64 target, where `mul_add` is a slow library call) Dekker's product of
    /// Veltkamp-split halves does, in plain arithmetic, for factors below 2^995 (whose
    /// split cannot overflow).
    #[inline]
    pub(crate) fn product(a: f64, b: f64) -> Self {
        let hi = a * b;
        #[cfg(not(target_feature = "fma"))]
        {
            const SPLITTABLE: f64 = 3.2e299; // below 2^995
            if a.abs() < SPLITTABLE && b.abs() < SPLITTABLE {
                let (a1, a2) = split(a);
                let (b1, b2) = split(b);
                return Self {
                    hi,
                    lo: ((a1 * b1 - hi) + a1 * b2 + a2 * b1) + a2 * b2,
                };
            }
        }
        Self {
            hi,
            lo: mul_add(a, b, -hi),
        }
    }

    #[inline]
    pub(crate) fn add(self, other: Self) -> Self {
        let s = two_sum(self.hi, other.hi);
        let t = two_sum(self.lo, other.lo);
        let s = quick_two_sum(s.hi, s.lo + t.hi);
        quick_two_sum(s.hi, s.lo + t.lo)
    }

    #[inline]
    pub(crate) fn neg(self) -> Self {
        Self {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    #[inline]
    pub(crate) fn mul(self, other: Self) -> Self {
        let p = Self::product(self.hi, other.hi);
        quick_two_sum(p.hi, p.lo + (self.hi * other.lo + self.lo * other.hi))
    }

    #[inline]
    pub(crate) fn mul_f64(self, b: f64) -> Self {
        let p = Self::product(self.hi, b);
        quick_two_sum(p.hi, p.lo + self.lo * b)
    }

    /// `self / other`: a quotient, corrected once by its remainder.
    #[inline]
    pub(crate) fn div(self, other: Self) -> Self {
        let q1 = self.hi / other.hi;
        let r = self.add(other.mul_f64(q1).neg());
        let q2 = r.hi / other.hi;
        let r = r.add(other.mul_f64(q2).neg());
        let q3 = r.hi / other.hi;
        let q = quick_two_sum(q1, q2);
        q.add(Self { hi: q3, lo: 0.0 })
    }

    /// `x . y` of three double-double components and three floats.
    #[inline]
    pub(crate) fn dot(x: [Self; 3], y: glam::DVec3) -> Self {
        x[0].mul_f64(y.x)
            .add(x[1].mul_f64(y.y))
            .add(x[2].mul_f64(y.z))
    }
}

/// `a` as the sum of two halves of 26 significant bits each (Veltkamp), whose products
/// are exact.
#[cfg(not(target_feature = "fma"))]
#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let high = c - (c - a);
    (high, a - high)
}

/// `a + b` as a rounded sum and its exact error.
#[inline]
fn two_sum(a: f64, b: f64) -> Dd {
    let hi = a + b;
    let bb = hi - a;
    Dd {
        hi,
        lo: (a - (hi - bb)) + (b - bb),
    }
}

/// `a + b` for `|a| >= |b|` (or `a == 0`).
#[inline]
fn quick_two_sum(a: f64, b: f64) -> Dd {
    let hi = a + b;
    Dd {
        hi,
        lo: b - (hi - a),
    }
}

/// `|v|_1`: the norm rounding bounds are stated in.
#[inline(always)]
pub(crate) fn l1(v: glam::DVec3) -> f64 {
    v.abs().element_sum()
}

/// A xorshift stream for the crate's own tests: uniform numbers in `[0, 1)` and what the
/// tests draw from them.
#[cfg(test)]
pub(crate) struct Stream(pub(crate) u64);

#[cfg(test)]
impl Stream {
    pub(crate) fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    /// `10^k` for a whole `k` in `[lo, hi]`.
    pub(crate) fn power(&mut self, lo: i32, hi: i32) -> f64 {
        10f64.powi(lo + (self.uniform() * f64::from(hi - lo + 1)) as i32)
    }
    /// A point of the cube `[-1, 1)^3`.
    pub(crate) fn vector(&mut self) -> glam::DVec3 {
        glam::DVec3::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        )
    }
    /// A unit vector, uniform over the sphere (drawn in the ball, not too near its centre).
    pub(crate) fn unit(&mut self) -> glam::DVec3 {
        loop {
            let v = self.vector();
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
    pub(crate) fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[(self.uniform() * from.len() as f64) as usize % from.len()]
    }
}

#[cfg(test)]
mod tests {
    use super::{Dd, mul_add};

    /// The error term of a product is exact: it equals what a correctly rounded fused
    /// multiply-add recovers (exactly representable, so no rounding is involved), over
    /// factors of every size the split handles and past it.
    #[test]
    fn products_are_exact() {
        let a = 1.0 + f64::EPSILON; // 1 + 2^-52
        let p = Dd::product(a, a); // 1 + 2^-51 + 2^-104
        assert_eq!(
            (p.hi, p.lo),
            (1.0 + 2.0 * f64::EPSILON, f64::EPSILON * f64::EPSILON)
        );
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            // Mantissas from the stream, exponents from 2^-400 to 2^1000.
            let f = |bits: u64, e: i32| {
                let m = f64::from_bits(0x3ff0_0000_0000_0000 | (bits & 0x000f_ffff_ffff_ffff));
                m * 2f64.powi(e)
            };
            let (a, b) = (
                f(x, (x >> 52) as i32 % 700 - 400),
                -f(x.rotate_left(29), (x >> 40) as i32 % 700 + 300),
            );
            // (Products that overflow, or whose error underflows, are outside the claim.)
            if !((a * b).abs() > 1e-280 && (a * b).is_finite()) {
                continue;
            }
            let p = Dd::product(a, b);
            assert_eq!(
                (p.hi, p.lo),
                (a * b, mul_add(a, b, -(a * b))),
                "{a:e} * {b:e}"
            );
        }
    }
}
