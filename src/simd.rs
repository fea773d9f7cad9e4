//! The hot queries compiled a second time for AVX2 and FMA, picked at run time: eight `f32`
//! lanes in one instruction where the x86-64 baseline (SSE2) has four, so that a node's
//! eight boxes are one test. The rest of the crate is written once, as portable code.

use multiversion::multiversion;

/// Runs `query` compiled for AVX2 and FMA where the CPU has both (detected at run time with
/// the `std` feature; without it, where the build targets them), and for the target's
/// baseline otherwise. The answer is the same either way, bit for bit: Rust never fuses a
/// multiply and an add unless asked to, so wider instructions change how fast `query` runs,
/// not what it computes (the trees' tests compare both paths on adversarial rays).
///
/// `query` and what it calls are compiled into each version only where they are inlined
/// into it: the queries passed here are `#[inline(always)]` down to the node test (a
/// mesh's face tests stay out of line, in the baseline's instructions).
#[multiversion(targets("x86_64+avx2+fma"))]
pub(crate) fn dispatch<R>(query: impl FnOnce() -> R) -> R {
    query()
}
