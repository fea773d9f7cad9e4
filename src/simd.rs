//! The hot queries compiled a second time for AVX2 and FMA, picked at run time: eight `f32`
//! lanes in one instruction where the x86-64 baseline (SSE2) has four, so that a node's
//! eight boxes are one test ([`Boxes`]: arrays the compiler vectorizes, or AVX's own,
//! `Avx8`, with a fused multiply-add, in a mesh's queries); and four `f64` lanes
//! ([`Lanes`]) for a mesh's face test, AVX's own where the CPU has it ([`Avx4`]), `wide`'s
//! portable ones elsewhere. AVX's lanes are the crate's one use of `unsafe`. The rest of
//! the crate is written once, as portable code.

use glam::DVec3;

/// Runs `$query` compiled for AVX2 and FMA with `$B` AVX's eight lanes ([`Boxes`]) and
/// `$token` the proof that makes them, where the CPU has both (detected at run time with
/// the `std` feature, a cached load after the first call; without it, where the build
/// targets them); and for the target's baseline, with arrays, otherwise. The `Bvh`'s
/// queries (a mesh picks its kernel once, when it is built). Either way the answer is the
/// same, bit for bit: the node test's two kinds of lanes are both conservative against the
/// crate's one box test, and the rest is the same arithmetic (Rust never fuses a multiply
/// and an add unless asked to); the trees' tests compare both paths on adversarial rays.
///
/// `$query` and what it calls are compiled into the AVX2 copy only where they are inlined
/// into it: the queries passed here are `#[inline(always)]` down to the node test.
macro_rules! boxes {
    (|$token:ident, $B:ident| $query:expr) => {
        match $crate::simd::Avx2::detect() {
            #[cfg(target_arch = "x86_64")]
            Some($token) => {
                type $B = $crate::simd::Avx8;
                $token.run(
                    #[inline(always)]
                    || $query,
                )
            }
            _ => {
                type $B = [f32; 8];
                let $token = ();
                $query
            }
        }
    };
}
pub(crate) use boxes;

/// Four `f64` lanes, as the mesh's face test computes on them: the portable `wide::f64x4`
/// (two SSE2 instructions an operation on x86-64), and [`Avx4`] where the CPU has AVX2.
/// Every operation is IEEE's, lane by lane, with no fused multiply-add, so both give the
/// scalar arithmetic's bits (comparisons ordered: false for NaN, as Rust's).
pub(crate) trait Lanes:
    Copy
    + core::ops::Add<Output = Self>
    + core::ops::Sub<Output = Self>
    + core::ops::Mul<Output = Self>
    + core::ops::Div<Output = Self>
    + core::ops::Neg<Output = Self>
{
    /// What making lanes takes: the proof that the CPU can compute on them.
    type Token: Copy;
    /// The eight `f32` lanes the same proof makes, for the node test of the walk that
    /// calls the face test.
    type Boxes: Boxes<Token = Self::Token>;
    /// The outcome of a comparison, lane by lane.
    type Mask: Copy + core::ops::BitAnd<Output = Self::Mask> + core::ops::BitOr<Output = Self::Mask>;
    fn splat(token: Self::Token, x: f64) -> Self;
    fn to_array(self) -> [f64; 4];
    /// Four points' coordinates lane by lane: `[x, y, z]`, lane `i` of each point `i`'s.
    fn transpose(token: Self::Token, points: [&DVec3; 4]) -> [Self; 3];
    fn abs(self) -> Self;
    /// The larger of each pair, for numbers (neither NaN, nor two zeros of either sign).
    fn max(self, other: Self) -> Self;
    fn gt(self, other: Self) -> Self::Mask;
    fn lt(self, other: Self) -> Self::Mask;
    /// Bit `i` for lane `i` where `mask` holds.
    fn bits(mask: Self::Mask) -> u32;
}

impl Lanes for wide::f64x4 {
    type Token = ();
    type Boxes = [f32; 8];
    type Mask = Self;
    #[inline(always)]
    fn splat((): (), x: f64) -> Self {
        wide::f64x4::splat(x)
    }
    #[inline(always)]
    fn to_array(self) -> [f64; 4] {
        wide::f64x4::to_array(self)
    }
    #[inline(always)]
    fn transpose((): (), [p, q, r, s]: [&DVec3; 4]) -> [Self; 3] {
        [
            wide::f64x4::from([p.x, q.x, r.x, s.x]),
            wide::f64x4::from([p.y, q.y, r.y, s.y]),
            wide::f64x4::from([p.z, q.z, r.z, s.z]),
        ]
    }
    #[inline(always)]
    fn abs(self) -> Self {
        wide::f64x4::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.fast_max(other)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Self {
        wide::CmpGt::cmp_gt(self, other)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> Self {
        wide::CmpLt::cmp_lt(self, other)
    }
    #[inline(always)]
    fn bits(mask: Self) -> u32 {
        mask.move_mask() as u32
    }
}

/// Eight `f32` lanes, as the walk tests a node's eight boxes on: an array, whose loops the
/// compiler vectorizes for the target it compiles them for, and `Avx8`, one AVX register,
/// where the CPU has AVX2 and FMA.
pub(crate) trait Boxes: Copy {
    /// What making lanes takes (see [`Lanes::Token`]).
    type Token: Copy;
    fn splat(token: Self::Token, x: f32) -> Self;
    fn load(token: Self::Token, x: &[f32; 8]) -> Self;
    fn to_array(self) -> [f32; 8];
    /// `self * a + b`, rounded twice, or once where the CPU fuses them (AVX2's lanes): the
    /// walk's pads hold for either.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Lane by lane, `self` where it is the larger (the smaller, for `min`), `other`
    /// otherwise: for numbers, which no lane of the walk's is not.
    fn max(self, other: Self) -> Self;
    fn min(self, other: Self) -> Self;
    /// Bit `k` set where `self[k] <= other[k]`.
    fn le_bits(self, other: Self) -> u32;
}

impl Boxes for [f32; 8] {
    type Token = ();
    #[inline(always)]
    fn splat((): (), x: f32) -> Self {
        [x; 8]
    }
    #[inline(always)]
    fn load((): (), x: &[f32; 8]) -> Self {
        *x
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        self
    }
    // (Loops the compiler turns into one instruction per step for all eight lanes, two
    // with SSE alone.)
    #[inline(always)]
    fn mul_add(mut self, a: Self, b: Self) -> Self {
        for k in 0..8 {
            self[k] = self[k] * a[k] + b[k];
        }
        self
    }
    #[inline(always)]
    fn max(mut self, other: Self) -> Self {
        for k in 0..8 {
            self[k] = if self[k] > other[k] {
                self[k]
            } else {
                other[k]
            };
        }
        self
    }
    #[inline(always)]
    fn min(mut self, other: Self) -> Self {
        for k in 0..8 {
            self[k] = if self[k] < other[k] {
                self[k]
            } else {
                other[k]
            };
        }
        self
    }
    /// A comparison and a mask per four lanes, through the `wide` crate (SSE's `cmpleps`
    /// and `movmskps`). (Tried: a loop of `m | (a[k] <= b[k]) << k`, which LLVM compiles
    /// to scalar instructions, one per lane and more; `wide::f32x8`, more instructions a
    /// ray in the mesh's walk.)
    #[inline(always)]
    fn le_bits(self, other: Self) -> u32 {
        let mut bits = 0;
        for i in (0..8).step_by(4) {
            let a = wide::f32x4::from([self[i], self[i + 1], self[i + 2], self[i + 3]]);
            let b = wide::f32x4::from([other[i], other[i + 1], other[i + 2], other[i + 3]]);
            bits |= (wide::CmpLe::cmp_le(a, b).move_mask() as u32) << i;
        }
        bits
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::{Avx2, Avx4, Avx8};

/// No AVX2 off x86-64: a proof that cannot be made.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy, Debug)]
pub(crate) enum Avx2 {}

#[cfg(not(target_arch = "x86_64"))]
impl Avx2 {
    pub(crate) fn detect() -> Option<Self> {
        None
    }
}

/// AVX2's four `f64` lanes in one register, behind a proof that the CPU has them: the one
/// module of the crate with `unsafe`, for the intrinsics' calls (safe to make only where
/// the CPU has the feature, which no function here can say to the compiler).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx {
    use core::arch::x86_64::{
        __m256, __m256d, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _mm256_add_pd, _mm256_and_pd,
        _mm256_andnot_pd, _mm256_cmp_pd, _mm256_cmp_ps, _mm256_div_pd, _mm256_fmadd_ps,
        _mm256_loadu_ps, _mm256_maskload_pd, _mm256_max_pd, _mm256_max_ps, _mm256_min_ps,
        _mm256_movemask_pd, _mm256_movemask_ps, _mm256_mul_pd, _mm256_or_pd,
        _mm256_permute2f128_pd, _mm256_set_epi64x, _mm256_set1_pd, _mm256_set1_ps, _mm256_sub_pd,
        _mm256_unpackhi_pd, _mm256_unpacklo_pd, _mm256_xor_pd,
    };
    use glam::DVec3;

    /// Proof that the CPU has AVX2 and FMA: made only by [`Avx2::detect`].
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Avx2(());

    impl Avx2 {
        /// The proof, where the CPU gives it: detected at run time with `std` (a cached
        /// load after the first call), where the build targets both features without.
        #[inline(always)]
        pub(crate) fn detect() -> Option<Self> {
            #[cfg(feature = "std")]
            let found = std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma");
            #[cfg(not(feature = "std"))]
            let found = cfg!(all(target_feature = "avx2", target_feature = "fma"));
            found.then_some(Self(()))
        }

        /// `query`, compiled for AVX2 and FMA (where it is inlined, as the queries that
        /// `boxes!` and the mesh's kernel pass are).
        #[inline(always)]
        pub(crate) fn run<R>(self, query: impl FnOnce() -> R) -> R {
            // SAFETY: `self` proves the CPU has AVX2 and FMA, all that `with_avx2` enables.
            unsafe { with_avx2(query) }
        }
    }

    #[target_feature(enable = "avx2,fma")]
    fn with_avx2<R>(query: impl FnOnce() -> R) -> R {
        query()
    }

    /// Four `f64` lanes in an AVX register. Only [`Avx2`] makes one (`splat`,
    /// `transpose`), and every operation takes one in, so no value of this type exists on
    /// a CPU without AVX2: that is what makes each intrinsic's call below sound.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Avx4(__m256d);

    /// An intrinsic's call on lanes that exist (see [`Avx4`]).
    macro_rules! avx {
        ($e:expr) => {
            // SAFETY: an `Avx4` or `Avx8` (an argument here, or the `Avx2` proof for a new
            // one) exists only where the CPU has AVX2 and FMA, so their instructions run.
            unsafe { $e }
        };
    }

    macro_rules! operator {
        ($trait:ident, $method:ident, $intrinsic:ident) => {
            impl core::ops::$trait for Avx4 {
                type Output = Self;
                #[inline(always)]
                fn $method(self, other: Self) -> Self {
                    Self(avx!($intrinsic(self.0, other.0)))
                }
            }
        };
    }
    operator!(Add, add, _mm256_add_pd);
    operator!(Sub, sub, _mm256_sub_pd);
    operator!(Mul, mul, _mm256_mul_pd);
    operator!(Div, div, _mm256_div_pd);
    operator!(BitAnd, bitand, _mm256_and_pd);
    operator!(BitOr, bitor, _mm256_or_pd);

    impl core::ops::Neg for Avx4 {
        type Output = Self;
        #[inline(always)]
        fn neg(self) -> Self {
            Self(avx!(_mm256_xor_pd(self.0, _mm256_set1_pd(-0.0))))
        }
    }

    impl super::Lanes for Avx4 {
        type Token = Avx2;
        type Boxes = Avx8;
        type Mask = Self;
        #[inline(always)]
        fn splat(_: Avx2, x: f64) -> Self {
            Self(avx!(_mm256_set1_pd(x)))
        }
        #[inline(always)]
        fn to_array(self) -> [f64; 4] {
            // SAFETY: four `f64` in 32 bytes either way, and every bit pattern is one.
            unsafe { core::mem::transmute::<__m256d, [f64; 4]>(self.0) }
        }
        /// Each point loaded whole into a register and the four transposed (Embree's way
        /// with a leaf of indexed triangles): four loads and five shuffles, where lanes
        /// filled one coordinate at a time take twelve loads and nine inserts.
        #[inline(always)]
        fn transpose(_: Avx2, [p, q, r, s]: [&DVec3; 4]) -> [Self; 3] {
            // `x y z` of a point, and a fourth lane of zero that is never read.
            let load = |v: &DVec3| {
                let mask = avx!(_mm256_set_epi64x(0, -1, -1, -1));
                // SAFETY: `DVec3` is `repr(C)`, three `f64` (glam), so `v` points at three
                // readable ones; the mask's fourth lane is clear, and a masked load neither
                // reads nor faults on a lane whose mask is clear (Intel's SDM, VMASKMOV).
                // AVX, which the `Avx2` proof covers.
                Self(unsafe { _mm256_maskload_pd(core::ptr::from_ref(v).cast::<f64>(), mask) })
            };
            let (a, b, c, d) = (load(p).0, load(q).0, load(r).0, load(s).0);
            // Within each 128-bit half: (a.x b.x | a.z b.z), (a.y b.y | 0 0), and so for c, d.
            let (xz_ab, y_ab) = avx!((_mm256_unpacklo_pd(a, b), _mm256_unpackhi_pd(a, b)));
            let (xz_cd, y_cd) = avx!((_mm256_unpacklo_pd(c, d), _mm256_unpackhi_pd(c, d)));
            avx!([
                Self(_mm256_permute2f128_pd::<0x20>(xz_ab, xz_cd)),
                Self(_mm256_permute2f128_pd::<0x20>(y_ab, y_cd)),
                Self(_mm256_permute2f128_pd::<0x31>(xz_ab, xz_cd)),
            ])
        }
        #[inline(always)]
        fn abs(self) -> Self {
            Self(avx!(_mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0)))
        }
        #[inline(always)]
        fn max(self, other: Self) -> Self {
            Self(avx!(_mm256_max_pd(self.0, other.0)))
        }
        #[inline(always)]
        fn gt(self, other: Self) -> Self {
            Self(avx!(_mm256_cmp_pd::<_CMP_GT_OQ>(self.0, other.0)))
        }
        #[inline(always)]
        fn lt(self, other: Self) -> Self {
            Self(avx!(_mm256_cmp_pd::<_CMP_LT_OQ>(self.0, other.0)))
        }
        #[inline(always)]
        fn bits(mask: Self) -> u32 {
            avx!(_mm256_movemask_pd(mask.0)) as u32
        }
    }

    /// Eight `f32` lanes in an AVX register, made only with an [`Avx2`] proof (as [`Avx4`]):
    /// the walk's node test in one instruction a step, its multiply and add fused.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Avx8(__m256);

    impl super::Boxes for Avx8 {
        type Token = Avx2;
        #[inline(always)]
        fn splat(_: Avx2, x: f32) -> Self {
            Self(avx!(_mm256_set1_ps(x)))
        }
        #[inline(always)]
        fn load(_: Avx2, x: &[f32; 8]) -> Self {
            // SAFETY: `x` is eight readable `f32`, and an unaligned load asks no more; AVX,
            // which the proof covers.
            Self(unsafe { _mm256_loadu_ps(x.as_ptr()) })
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 8] {
            // SAFETY: eight `f32` in 32 bytes either way, and every bit pattern is one.
            unsafe { core::mem::transmute::<__m256, [f32; 8]>(self.0) }
        }
        #[inline(always)]
        fn mul_add(self, a: Self, b: Self) -> Self {
            // (FMA, which the `Avx2` proof covers with AVX2.)
            Self(avx!(_mm256_fmadd_ps(self.0, a.0, b.0)))
        }
        #[inline(always)]
        fn max(self, other: Self) -> Self {
            // (`maxps` gives its second operand unless the first is larger.)
            Self(avx!(_mm256_max_ps(self.0, other.0)))
        }
        #[inline(always)]
        fn min(self, other: Self) -> Self {
            Self(avx!(_mm256_min_ps(self.0, other.0)))
        }
        #[inline(always)]
        fn le_bits(self, other: Self) -> u32 {
            avx!(_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(
                self.0, other.0
            ))) as u32
        }
    }
}
