//! Bad USD files never panic: the fixtures and files of the Pixar-written corpus (usda, usdc,
//! usdz; usdc above all), truncated at random and with bytes flipped (proptest), import to
//! `Ok` or to a clean error naming the file, and no single allocation made while importing
//! exceeds a bound tied to the file's size (unpatched, openusd 0.6 let a flipped count ask for
//! terabytes and abort — see vendor/openusd).

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

/// The largest single allocation allowed while importing a file of `len` bytes. The usdc
/// reader allocates what the file can back: LZ4 writes at most 255 bytes per byte of its
/// input, a coded integer takes at least 2 bits of that, and one decoded integer becomes at
/// most 32 bytes of any one allocation (a path, a spec) — 255 · 4 · 32 bytes per byte of the
/// file. The floor covers what the import itself allocates (a tessellated sphere, buffers).
fn max_allocation(len: usize) -> usize {
    (64 << 20usize).max(len.saturating_mul(255 * 4 * 32))
}

/// The files mutated: usdc weighs most; each imports in milliseconds, so 400 cases take seconds.
const FILES: [&str; 11] = [
    "fixtures/materials.usda",
    "fixtures/instancing.usdc",
    "fixtures/transforms.usdc",
    "fixtures/textured.usdz",
    "corpus/spheres_10.usdc",
    "corpus/instancer_10.usdc",
    "corpus/variants_10.usdc",
    "corpus/references_10.usdc",
    "corpus/deep_10.usdc",
    "corpus/meshes_identical_1000.usdc",
    "corpus/payloads_10.usdz",
];

fn fixture(which: usize) -> (String, Vec<u8>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join(FILES[which]);
    (path.file_name().unwrap().to_string_lossy().into(), std::fs::read(path).unwrap())
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
        which in 0usize..FILES.len(),
        cut in 0.0f64..1.2,
        flips in proptest::collection::vec((0.0f64..1.0, 1u8..=255), 0..8),
    ) {
        let (name, mut bytes) = fixture(which);
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
        // The corpus's references and payloads name this asset beside the file.
        std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus/asset.usda"), dir.path().join("asset.usda")).unwrap();
        PEAK.with(|p| p.set(0));
        ARMED.with(|a| a.set(true));
        let result = std::panic::catch_unwind(|| host_usd::load(&path).map(|s| s.counts.triangles));
        ARMED.with(|a| a.set(false));
        let peak = PEAK.with(|p| p.get());
        prop_assert!(result.is_ok(), "{name}: the importer panicked");
        prop_assert!(peak <= max_allocation(bytes.len()), "{name}: one allocation of {peak} bytes for a {}-byte file", bytes.len());
        if let Ok(Err(e)) = result {
            prop_assert!(e.to_string().contains(path.file_name().unwrap().to_str().unwrap()), "{e}");
        }
    }
}

/// The sections of a usdc file: (name, start), from its table of contents.
fn sections(bytes: &[u8]) -> Vec<(String, usize)> {
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    let toc = u64_at(16);
    (0..u64_at(toc))
        .map(|k| {
            let entry = toc + 8 + 32 * k;
            let name = bytes[entry..entry + 16].iter().take_while(|&&b| b != 0).map(|&b| b as char).collect();
            (name, u64_at(entry + 16))
        })
        .collect()
}

/// Each structural section's leading counts set to what no decoding can back: a clean error,
/// and no allocation beyond the cap. A Pixar-written file of many similar prims included, whose
/// valid counts far exceed 256 × its compressed bytes.
#[test]
fn counts_the_file_cannot_back_are_errors() {
    for file in ["corpus/meshes_identical_1000.usdc", "corpus/spheres_10.usdc", "fixtures/instancing.usdc"] {
        let original = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join(file)).unwrap();
        let found = sections(&original);
        for section in ["TOKENS", "FIELDS", "FIELDSETS", "PATHS", "SPECS"] {
            let &(_, start) = found.iter().find(|(n, _)| n == section).unwrap();
            for (at, value) in [(0, 1u64 << 33), (0, u64::MAX), (8, 1 << 40), (8, u64::MAX >> 1)] {
                let mut bytes = original.clone();
                bytes[start + at..start + at + 8].copy_from_slice(&value.to_le_bytes());
                let dir = scratch();
                let path = dir.path().join("x.usdc");
                std::fs::write(&path, &bytes).unwrap();
                PEAK.with(|p| p.set(0));
                ARMED.with(|a| a.set(true));
                let result = host_usd::load(&path);
                ARMED.with(|a| a.set(false));
                let peak = PEAK.with(|p| p.get());
                let what = format!("{file}: {section} + {at} = {value}");
                let e = result.err().unwrap_or_else(|| panic!("{what}: imported"));
                assert!(e.to_string().contains("x.usdc"), "{what}: {e}");
                assert!(peak <= max_allocation(bytes.len()), "{what}: one allocation of {peak} bytes");
            }
        }
    }
}
