//! The pinned images (`image_cases/mod.rs`) rendered with the portable paths in place of the
//! AVX2 ones (`sampler_core::cpu::use_portable_paths`): the SSE2 and scalar forms of the env
//! descents, the Sobol points, the densities and the ray tests give the same bits, so the same
//! hashes. A binary of its own, since the choice is the whole process's.

#[path = "integration/common/mod.rs"]
#[allow(dead_code)]
mod common;
#[path = "image_cases/mod.rs"]
mod image_cases;

use image_cases::{EXPECTED, cases};

#[test]
fn portable_paths_render_the_recorded_images() {
    sampler_core::cpu::use_portable_paths();
    #[cfg(target_arch = "x86_64")]
    assert!(!sampler_core::cpu::has_avx2(), "the portable paths are taken");
    let actual = cases();
    let differ: Vec<String> = actual
        .iter()
        .zip(EXPECTED)
        .filter(|((_, a), (_, e))| a != e)
        .map(|((case, a), (_, e))| format!("{case}: 0x{a:016x}, recorded 0x{e:016x}"))
        .collect();
    assert_eq!(actual.len(), EXPECTED.len(), "one hash per case");
    assert!(differ.is_empty(), "the portable paths render other images:\n{}", differ.join("\n"));
}
