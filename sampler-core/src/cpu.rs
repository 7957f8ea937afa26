//! What the CPU the code runs on can do, asked once: the core is `no_std`, so it reads CPUID
//! itself (as `std::is_x86_feature_detected!` does) rather than leaving the choice to the host.
//! Paths chosen by it compute the same results as the portable ones, bit for bit.
//!
//! A build may also assume extensions throughout (`-C target-cpu`: the workspace builds x86-64
//! for x86-64-v3, `.cargo/config.toml`); [`missing_build_feature`] names one this CPU lacks, so
//! that a program can say so before it runs an instruction the CPU does not have.

use core::ffi::CStr;

/// Whether the paths that choose between AVX2 and portable code take AVX2: the CPU has it,
/// the OS saves the YMM registers, and [`use_portable_paths`] was not called. Both forms
/// compute the same results, bit for bit.
#[cfg(target_arch = "x86_64")]
#[inline]
#[must_use]
pub fn has_avx2() -> bool {
    use core::sync::atomic::Ordering;
    match AVX2.load(Ordering::Relaxed) {
        NO => false,
        YES => true,
        _ => {
            // A build that assumes AVX2 throughout runs only where it is: no question to ask.
            let yes = cfg!(target_feature = "avx2") || detect_avx2();
            // Only where nothing was stored meanwhile: `use_portable_paths` keeps its answer.
            let _ = AVX2.compare_exchange(UNASKED, if yes { YES } else { NO }, Ordering::Relaxed, Ordering::Relaxed);
            AVX2.load(Ordering::Relaxed) == YES
        }
    }
}

/// The answer [`has_avx2`] gives: not asked yet, no, or yes.
#[cfg(target_arch = "x86_64")]
static AVX2: core::sync::atomic::AtomicU8 = core::sync::atomic::AtomicU8::new(UNASKED);
#[cfg(target_arch = "x86_64")]
const UNASKED: u8 = 0;
#[cfg(target_arch = "x86_64")]
const NO: u8 = 1;
#[cfg(target_arch = "x86_64")]
const YES: u8 = 2;

/// From now on in this process, every choice between an AVX2 path and a portable one (see
/// `has_avx2`) takes the portable one, as on a CPU without AVX2; what was built before (a
/// host's ray-tracing hierarchy, say) keeps the paths it chose. For tests and comparisons:
/// the two forms are meant to give the same bits, and this is how a machine with AVX2 checks
/// the other. The code the build compiles with its own instruction set (`-C target-cpu`) is
/// not affected. A no-op off x86-64.
pub fn use_portable_paths() {
    #[cfg(target_arch = "x86_64")]
    AVX2.store(NO, core::sync::atomic::Ordering::Relaxed);
}

/// An instruction-set extension this build assumes throughout (compiled with it enabled) that
/// the CPU it runs on lacks, by CPUID; `None` where the build runs here. Asked at run time
/// whatever the build assumes (`is_x86_feature_detected!` answers from the build where it
/// assumes the feature). The name is NUL-terminated so that the C ABI can hand it out.
#[must_use]
pub fn missing_build_feature() -> Option<&'static CStr> {
    #[cfg(target_arch = "x86_64")]
    {
        first_missing(&build_features(&Cpuid::read()))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// The first feature built in (`.1`) that the CPU lacks (`.2` false).
#[cfg(target_arch = "x86_64")]
fn first_missing(features: &[(&'static CStr, bool, bool)]) -> Option<&'static CStr> {
    features.iter().find(|(_, built, here)| *built && !*here).map(|(name, ..)| *name)
}

/// The registers of CPUID (and XCR0) that name the extensions of the x86-64 levels v2 to v4.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Default)]
struct Cpuid {
    /// Leaf 1, ECX.
    leaf1_ecx: u32,
    /// Leaf 7 sub-leaf 0, EBX.
    leaf7_ebx: u32,
    /// Leaf 0x8000_0001, ECX.
    ext1_ecx: u32,
    /// The OS-enabled register state (0 where OSXSAVE is off).
    xcr0: u64,
}

#[cfg(target_arch = "x86_64")]
impl Cpuid {
    fn read() -> Self {
        use core::arch::x86_64::{__cpuid, __cpuid_count};
        // CPUID is always available on x86-64 and only reads identification registers.
        #[allow(unused_unsafe)]
        let (max_leaf, max_ext) = unsafe { (__cpuid(0).eax, __cpuid(0x8000_0000).eax) };
        #[allow(unused_unsafe)]
        let leaf1_ecx = unsafe { __cpuid(1).ecx };
        #[allow(unused_unsafe)]
        let leaf7_ebx = if max_leaf >= 7 { unsafe { __cpuid_count(7, 0).ebx } } else { 0 };
        #[allow(unused_unsafe)]
        let ext1_ecx = if max_ext >= 0x8000_0001 { unsafe { __cpuid(0x8000_0001).ecx } } else { 0 };
        // SAFETY: XGETBV is enabled where OSXSAVE is set.
        let xcr0 = if leaf1_ecx & (1 << 27) != 0 { unsafe { xcr0() } } else { 0 };
        Self { leaf1_ecx, leaf7_ebx, ext1_ecx, xcr0 }
    }
}

/// Each extension the x86-64 levels v2 to v4 add (CMPXCHG16B, LAHF/SAHF and XSAVE aside: every
/// CPU with the others has them): its name, whether this build assumes it, whether `cpu` has it
/// (the AVX families only where the OS saves their registers).
#[cfg(target_arch = "x86_64")]
fn build_features(cpu: &Cpuid) -> [(&'static CStr, bool, bool); 18] {
    let (c1, b7, e1) = (cpu.leaf1_ecx, cpu.leaf7_ebx, cpu.ext1_ecx);
    let bit = |r: u32, n: u32| r & (1 << n) != 0;
    let ymm = cpu.xcr0 & 0b110 == 0b110;
    let zmm = ymm && cpu.xcr0 & 0b1110_0000 == 0b1110_0000;
    [
        (c"sse3", cfg!(target_feature = "sse3"), bit(c1, 0)),
        (c"ssse3", cfg!(target_feature = "ssse3"), bit(c1, 9)),
        (c"sse4.1", cfg!(target_feature = "sse4.1"), bit(c1, 19)),
        (c"sse4.2", cfg!(target_feature = "sse4.2"), bit(c1, 20)),
        (c"popcnt", cfg!(target_feature = "popcnt"), bit(c1, 23)),
        (c"avx", cfg!(target_feature = "avx"), bit(c1, 28) && ymm),
        (c"f16c", cfg!(target_feature = "f16c"), bit(c1, 29) && ymm),
        (c"fma", cfg!(target_feature = "fma"), bit(c1, 12) && ymm),
        (c"movbe", cfg!(target_feature = "movbe"), bit(c1, 22)),
        (c"avx2", cfg!(target_feature = "avx2"), bit(b7, 5) && ymm),
        (c"bmi1", cfg!(target_feature = "bmi1"), bit(b7, 3)),
        (c"bmi2", cfg!(target_feature = "bmi2"), bit(b7, 8)),
        (c"lzcnt", cfg!(target_feature = "lzcnt"), bit(e1, 5)),
        (c"avx512f", cfg!(target_feature = "avx512f"), bit(b7, 16) && zmm),
        (c"avx512bw", cfg!(target_feature = "avx512bw"), bit(b7, 30) && zmm),
        (c"avx512cd", cfg!(target_feature = "avx512cd"), bit(b7, 28) && zmm),
        (c"avx512dq", cfg!(target_feature = "avx512dq"), bit(b7, 17) && zmm),
        (c"avx512vl", cfg!(target_feature = "avx512vl"), bit(b7, 31) && zmm),
    ]
}

/// AVX and AVX2 by CPUID, with their registers saved by the OS.
#[cfg(target_arch = "x86_64")]
fn detect_avx2() -> bool {
    let here = build_features(&Cpuid::read());
    let has = |name: &CStr| here.iter().any(|f| f.0 == name && f.2);
    has(c"avx") && has(c"avx2")
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
    use super::{Cpuid, build_features, detect_avx2, first_missing};

    #[test]
    fn a_feature_built_in_and_absent_is_named() {
        let list = [(c"a", false, false), (c"b", true, true), (c"c", true, false), (c"d", true, false)];
        assert_eq!(first_missing(&list), Some(c"c"));
        assert_eq!(first_missing(&list[..2]), None);
        // A CPU without AVX state saved by the OS has none of the AVX family, whatever CPUID says.
        let cpu = Cpuid { leaf1_ecx: u32::MAX, leaf7_ebx: u32::MAX, ext1_ecx: u32::MAX, xcr0: 0 };
        let avx2 = build_features(&cpu).into_iter().find(|f| f.0 == c"avx2").unwrap();
        assert!(!avx2.2);
        let cpu = Cpuid { xcr0: 0b111, ..cpu };
        let here = build_features(&cpu);
        assert!(here.iter().filter(|f| !f.0.to_bytes().starts_with(b"avx512")).all(|f| f.2));
        assert!(here.iter().filter(|f| f.0.to_bytes().starts_with(b"avx512")).all(|f| !f.2));
    }

    #[test]
    fn this_build_runs_here() {
        assert_eq!(super::missing_build_feature(), None);
    }

    #[test]
    fn the_run_time_answer_is_the_cpus() {
        // Under a build that assumes AVX2, std answers from the build: the CPU's answer is
        // CPUID's, the same registers the feature check reads.
        let here = build_features(&Cpuid::read());
        let avx2 = here.iter().find(|f| f.0 == c"avx2").unwrap().2;
        assert_eq!(detect_avx2(), avx2);
        if !cfg!(target_feature = "avx2") {
            assert_eq!(detect_avx2(), std::is_x86_feature_detected!("avx2"));
        }
    }

    #[test]
    fn agrees_with_std() {
        assert_eq!(super::has_avx2(), std::is_x86_feature_detected!("avx2"));
        assert_eq!(super::has_avx2(), std::is_x86_feature_detected!("avx2"), "the cached answer");
    }
}
