//! host-usd against Pixar's answers over a corpus written by Pixar's own library
//! (`tests/corpus/make_corpus.py`, usd-core 26.11): spheres, meshes with varying and with
//! identical points, a PointInstancer, deep hierarchies, references, payloads and variants, in
//! usda, usdc (Pixar's `Export`) and usdz. The small files are committed in `tests/corpus/`;
//! with `PPIS_USD_CORPUS=DIR` every file in DIR (CI generates up to 100 000 prims there) is
//! checked too, and DIR must hold a corpus.
//!
//! Each file must match Pixar's world matrices to 1e-9, its bound materials, mesh counts,
//! PointInstancer instances and transforms, and how many gprims, meshes and instances a
//! renderer draws.

use host_usd::conformance;
use std::path::{Path, PathBuf};

/// Corpus files that do not match Pixar's answers yet, with the reason; each must still fail
/// (so that a fix removes it from here). Empty: every kind passes.
const PENDING: &[(&str, &str)] = &[];

/// The stack a conformance check runs on: that of a process's main thread, as in `ppis`.
const STACK: usize = 8 << 20;

fn committed() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

/// Checks every pair on two threads; returns, per file, its mismatches (empty when it matches)
/// and the number of instance transforms compared.
fn check_all(pairs: &[(PathBuf, PathBuf)]) -> Vec<(PathBuf, Vec<String>, usize)> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            std::thread::Builder::new()
                .stack_size(STACK)
                .spawn_scoped(s, || {
                    while let Some((usd, expected)) = pairs.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
                    {
                        let outcome = match conformance::check(usd, expected) {
                            Ok(r) if r.max_matrix_error > conformance::MATRIX_TOLERANCE => {
                                (vec![format!("max matrix error {:e}", r.max_matrix_error)], r.instances)
                            }
                            Ok(r) => (r.mismatches, r.instances),
                            Err(e) => (vec![e], 0),
                        };
                        results.lock().unwrap().push((usd.clone(), outcome.0, outcome.1));
                    }
                })
                .unwrap();
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort();
    results
}

/// Every file matches Pixar, but the pending ones, which must not.
fn assert_conformance(pairs: &[(PathBuf, PathBuf)]) -> usize {
    let mut failures = Vec::new();
    let mut instances = 0;
    for (usd, mismatches, n) in check_all(pairs) {
        instances += n;
        let name = usd.file_name().unwrap().to_string_lossy().to_string();
        let pending = PENDING.iter().any(|(stem, _)| name.starts_with(&format!("{stem}.")));
        match (mismatches.is_empty(), pending) {
            (true, true) => failures.push(format!("{name}: matches Pixar now; remove it from PENDING")),
            (false, false) => failures.push(format!("{name}: {:#?}", &mismatches[..mismatches.len().min(8)])),
            _ => {}
        }
    }
    assert!(failures.is_empty(), "{} files:\n{}", failures.len(), failures.join("\n"));
    instances
}

#[test]
fn committed_corpus_matches_pixar() {
    let pairs = conformance::pairs(&committed());
    let names: Vec<String> = pairs.iter().map(|(p, _)| p.file_name().unwrap().to_string_lossy().into()).collect();
    let kinds = ["spheres", "meshes_varying", "meshes_identical", "instancer", "references", "payloads", "variants"];
    for kind in kinds {
        for file in [
            format!("{kind}_10.usda"),
            format!("{kind}_10.usdc"),
            format!("{kind}_10.usdz"),
            format!("{kind}_1000.usdc"),
        ] {
            assert!(names.contains(&file), "{file} is missing from the committed corpus");
        }
    }
    for file in ["deep_10.usda", "deep_10.usdc", "deep_10.usdz", "deep_100.usdc"] {
        assert!(names.contains(&file.to_string()), "{file} is missing from the committed corpus");
    }
    let instances = assert_conformance(&pairs);
    // The instancer files' transforms are compared, not only their counts.
    assert!(instances >= 800, "only {instances} instance transforms compared");
}

#[test]
fn generated_corpus_matches_pixar() {
    let Some(dir) = std::env::var_os("PPIS_USD_CORPUS") else {
        // The committed corpus is checked by the test above; CI sets the variable.
        return;
    };
    let dir = PathBuf::from(dir);
    assert!(dir.is_dir(), "PPIS_USD_CORPUS={}: not a folder", dir.display());
    let pairs = conformance::pairs(&dir);
    assert!(!pairs.is_empty(), "PPIS_USD_CORPUS={}: no USD file with Pixar's answers beside it", dir.display());
    assert_conformance(&pairs);
}

/// The check can fail: a wrong count, matrix or material in Pixar's answers is reported.
#[test]
fn a_wrong_answer_is_a_mismatch() {
    let dir = tempfile::tempdir().unwrap();
    let usd = dir.path().join("spheres_10.usdc");
    std::fs::copy(committed().join("spheres_10.usdc"), &usd).unwrap();
    let text = std::fs::read_to_string(committed().join("spheres_10.expected.json")).unwrap();
    let right: serde_json::Value = serde_json::from_str(&text).unwrap();
    let expected = dir.path().join("spheres_10.expected.json");
    type Edit = fn(&mut serde_json::Value);
    let edits: [(&str, Edit); 3] = [
        ("gprims", |w| w["counts"]["gprims"] = 9.into()),
        ("world matrix", |w| w["prims"]["/World/Sphere_3"]["world"][3][0] = 7.6.into()),
        ("material", |w| w["prims"]["/World/Sphere_3"]["material"] = "/World/Looks/M1".into()),
    ];
    for (what, edit) in edits {
        let mut wrong = right.clone();
        edit(&mut wrong);
        std::fs::write(&expected, wrong.to_string()).unwrap();
        let r = conformance::check(&usd, &expected).unwrap();
        assert_eq!(r.mismatches.len(), 1, "{what}: {:?}", r.mismatches);
    }
}
