//! What the CPU the code runs on can do, asked once: the core is `no_std`, so it reads CPUID
//! itself (as `std::is_x86_feature_detected!` does) rather than leaving the choice to the host.
//! Paths chosen by it compute the same results as the portable ones, bit for bit.

/// Whether AVX2 instructions may run here: the CPU has them and the OS saves the YMM registers.
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn has_avx2() -> bool {
    use core::sync::atomic::{AtomicU8, Ordering};
    /// 0: not asked yet; 1: no; 2: yes.
    static ANSWER: AtomicU8 = AtomicU8::new(0);
    match ANSWER.load(Ordering::Relaxed) {
        1 => false,
        2 => true,
        _ => {
            let yes = detect_avx2();
            ANSWER.store(if yes { 2 } else { 1 }, Ordering::Relaxed);
            yes
        }
    }
}

/// CPUID leaf 1 (AVX, OSXSAVE), XCR0 (XMM and YMM state enabled), leaf 7 (AVX2).
#[cfg(target_arch = "x86_64")]
fn detect_avx2() -> bool {
    use core::arch::x86_64::{__cpuid, __cpuid_count};
    // CPUID is always available on x86-64 and only reads identification registers.
    #[allow(unused_unsafe)]
    let (max_leaf, leaf1) = unsafe { (__cpuid(0).eax, __cpuid(1)) };
    let (avx, osxsave) = (leaf1.ecx & (1 << 28) != 0, leaf1.ecx & (1 << 27) != 0);
    if !(avx && osxsave) || max_leaf < 7 {
        return false;
    }
    // SAFETY: OSXSAVE is set, so XGETBV is enabled.
    let xcr0 = unsafe { xcr0() };
    #[allow(unused_unsafe)]
    let leaf7 = unsafe { __cpuid_count(7, 0) };
    xcr0 & 0b110 == 0b110 && leaf7.ebx & (1 << 5) != 0
}

/// The OS-enabled state components (XCR0).
///
/// # Safety
/// The CPU must report OSXSAVE.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "xsave")]
unsafe fn xcr0() -> u64 {
    // SAFETY: the caller checked OSXSAVE.
    unsafe { core::arch::x86_64::_xgetbv(0) }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    #[test]
    fn agrees_with_std() {
        assert_eq!(super::has_avx2(), std::is_x86_feature_detected!("avx2"));
        assert_eq!(super::has_avx2(), std::is_x86_feature_detected!("avx2"), "the cached answer");
    }
}
