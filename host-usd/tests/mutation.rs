//! Bad USD files never panic: the fixtures (usda, usdc, usdz), truncated at random and with
//! bytes flipped (proptest), import to `Ok` or to a clean error naming the file, and no
//! single allocation made while importing exceeds 64 MB (the files are a few KB; unpatched,
//! openusd 0.6 let a flipped count ask for terabytes and abort — see vendor/openusd).

use proptest::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

struct PeakAlloc;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for PeakAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ARMED.with(|a| a.get()) {
            PEAK.with(|p| p.set(p.get().max(layout.size())));
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ARMED.with(|a| a.get()) {
            PEAK.with(|p| p.set(p.get().max(new_size)));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: PeakAlloc = PeakAlloc;

const MAX_ALLOCATION: usize = 64 << 20;

fn fixtures() -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    ["materials.usda", "instancing.usdc", "transforms.usdc", "textured.usdz"]
        .iter()
        .map(|n| (n.to_string(), std::fs::read(dir.join(n)).unwrap()))
        .collect()
}

/// A folder removed when the case ends, pass or fail.
fn scratch() -> tempfile::TempDir {
    tempfile::Builder::new().prefix("ppis-usd-mutation-").tempdir().unwrap()
}

/// 400 cases from a fixed seed, so that CI is reproducible: random seeds once found a crash in
/// one run of a few hundred (see vendor/openusd/PATCHED.md), which then failed an unrelated
/// landing. To search further, set `PROPTEST_RNG_SEED` (and `PROPTEST_CASES`); a case that
/// aborts the process leaves its file in `/tmp/ppis-usd-mutation-*`.
fn config() -> ProptestConfig {
    let from_env = ProptestConfig::default();
    let seeded = std::env::var_os("PROPTEST_RNG_SEED").is_some();
    let cases = if std::env::var_os("PROPTEST_CASES").is_some() { from_env.cases } else { 400 };
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_seed: if seeded { from_env.rng_seed } else { proptest::test_runner::RngSeed::Fixed(0x05ee_d5ee) },
        ..from_env
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_usd_files_fail_cleanly(
        which in 0usize..4,
        cut in 0.0f64..1.2,
        flips in proptest::collection::vec((0.0f64..1.0, 1u8..=255), 0..8),
    ) {
        let (name, mut bytes) = fixtures().swap_remove(which);
        if cut < 1.0 {
            bytes.truncate((bytes.len() as f64 * cut) as usize);
        }
        for (at, x) in flips {
            if !bytes.is_empty() {
                let i = ((bytes.len() - 1) as f64 * at) as usize;
                bytes[i] ^= x;
            }
        }
        let dir = scratch();
        let path = dir.path().join(&name);
        std::fs::write(&path, &bytes).unwrap();
        PEAK.with(|p| p.set(0));
        ARMED.with(|a| a.set(true));
        let result = std::panic::catch_unwind(|| host_usd::load(&path).map(|s| s.counts.triangles));
        ARMED.with(|a| a.set(false));
        let peak = PEAK.with(|p| p.get());
        prop_assert!(result.is_ok(), "{name}: the importer panicked");
        prop_assert!(peak <= MAX_ALLOCATION, "{name}: one allocation of {peak} bytes for a {}-byte file", bytes.len());
        if let Ok(Err(e)) = result {
            prop_assert!(e.to_string().contains(path.file_name().unwrap().to_str().unwrap()), "{e}");
        }
    }
}
