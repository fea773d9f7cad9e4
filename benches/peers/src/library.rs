//! What the triad asks of every library it times (hitkit's, obvhs's and, where it is built
//! in, Embree's), and the CPU mode switch they share: apart from the triad, so that the
//! Embree row (`embree.rs`) and the triad do not import each other.

use hitkit::Ray;

use crate::Hit;

/// One library's answers: closest hits (face number, `t`) and occlusion.
pub trait Library {
    fn name(&self) -> String;
    fn closest(&self, ray: &Ray) -> Hit;
    fn occluded(&self, ray: &Ray) -> bool;
    /// (node visits, face tests) of a closest-hit query and of an any-hit one.
    fn count(&self, ray: &Ray, any: bool) -> Option<(u32, u32)>;
    /// Whether its answers are compared with the mesh's.
    fn checked(&self) -> bool {
        true
    }
}

/// Sets the CPU's flush-to-zero and denormals-are-zero modes (x86_64's MXCSR bits 15 and
/// 6) on or off, returning the register's previous value.
#[cfg(target_arch = "x86_64")]
pub fn ftz_daz(on: bool) -> u32 {
    let mut old = 0u32;
    // SAFETY: reads and writes the SSE control register only; every other bit is kept.
    unsafe {
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut old, options(nostack));
        let new = if on { old | 0x8040 } else { old & !0x8040 };
        core::arch::asm!("ldmxcsr [{}]", in(reg) &new, options(nostack));
    }
    old
}

#[cfg(not(target_arch = "x86_64"))]
pub fn ftz_daz(_: bool) -> u32 {
    0
}
