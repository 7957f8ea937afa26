//! Deep namespaces and deeply nested values: a clean error or an import, never a stack
//! overflow, on a thread with a 2 MB stack (the size of a test or worker thread).

use host_usd::UsdScene;
use std::path::Path;

const TWO_MB: usize = 2 << 20;

/// A chain of `depth` Xforms, each translated by 0.5 along x, with a sphere at its end.
fn chain(depth: usize) -> String {
    let mut s = String::from("#usda 1.0\n");
    for i in 0..depth {
        s += &format!("def Xform \"X{i}\"\n{{\ndouble3 xformOp:translate = (0.5, 0, 0)\n");
        s += "uniform token[] xformOpOrder = [\"xformOp:translate\"]\n";
    }
    s += "def Sphere \"S\"\n{\n}\n";
    s += &"}\n".repeat(depth);
    s
}

/// Writes `text` and imports it on a fresh thread with a 2 MB stack.
fn import_on_small_stack(name: &str, text: &str) -> (Result<UsdScene, String>, tempfile::TempDir) {
    let dir = tempfile::Builder::new().prefix("ppis-usd-deep-").tempdir().unwrap();
    let file = dir.path().join(name);
    std::fs::write(&file, text).unwrap();
    let result = run_small(&file);
    (result, dir)
}

fn run_small(file: &Path) -> Result<UsdScene, String> {
    let file = file.to_owned();
    std::thread::Builder::new()
        .stack_size(TWO_MB)
        .spawn(move || host_usd::load(&file).map_err(|e| e.to_string()))
        .unwrap()
        .join()
        .expect("the import panicked")
}

#[test]
fn a_namespace_past_the_limit_is_an_error_naming_the_prim() {
    let (r, _dir) = import_on_small_stack("deep.usda", &chain(10_000));
    let e = r.expect_err("a 10 000-deep namespace is refused");
    assert!(e.contains("deep.usda") && e.contains("/X0/X1/") && e.contains("namespace deeper than 4096 levels"), "{e}");
}

#[test]
fn a_thousand_deep_chain_imports_with_its_world_transform() {
    let (r, _dir) = import_on_small_stack("chain.usda", &chain(1000));
    let s = r.unwrap();
    assert_eq!(s.counts.prims, 1001);
    assert_eq!(s.spheres.len(), 1);
    assert!((s.spheres[0].center.x - 500.0).abs() < 1e-3, "{:?}", s.spheres[0].center);
}

#[test]
fn deeply_nested_dictionaries_and_arrays_are_errors() {
    let n = 20_000;
    let dict = format!("#usda 1.0\n(\n    customLayerData = {}{}\n)\n", "{ dictionary d = ".repeat(n), "}".repeat(n));
    let (r, _dir) = import_on_small_stack("dict.usda", &dict);
    let e = r.expect_err("a 20 000-deep dictionary is refused");
    assert!(e.contains("dict.usda") && e.contains("nested deeper than"), "{e}");
    let array = format!("#usda 1.0\ndef Xform \"A\"\n{{\n    int[] x = {}{}\n}}\n", "[".repeat(n), "]".repeat(n));
    let (r, _dir) = import_on_small_stack("array.usda", &array);
    let e = r.expect_err("a 20 000-deep array is refused");
    assert!(e.contains("array.usda"), "{e}");
}

/// A usdc file's values are read by recursion, one frame per level of nesting: a prim's
/// `customData` of dictionaries nested 3 000 deep (written by Pixar's library) is refused as
/// corrupt when it is read, on a 2 MB stack; 50 levels read as they are.
#[test]
fn deeply_nested_usdc_dictionaries_are_errors() {
    use openusd::sdf::{self, AbstractData};
    let read = |name: &'static str| {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name);
        let run = move || -> Result<usize, String> {
            let data = openusd::usdc::read_file(&file).map_err(|e| e.to_string())?;
            let prim = sdf::path("/P").unwrap();
            let chain = |e: &dyn std::error::Error| {
                let mut s = e.to_string();
                let mut cause = e.source();
                while let Some(c) = cause {
                    s += &format!(": {c}");
                    cause = c.source();
                }
                s
            };
            let mut value = data.get_field(&prim, "customData").map_err(|e| chain(&e))?.into_owned();
            let mut depth = 0;
            while let sdf::Value::Dictionary(d) = value {
                let Some(inner) = d.into_values().next() else { break };
                (value, depth) = (inner, depth + 1);
            }
            Ok(depth)
        };
        std::thread::Builder::new().stack_size(TWO_MB).spawn(run).unwrap().join().expect("no stack overflow")
    };
    assert_eq!(read("nested_dictionary_50.usdc"), Ok(51), "50 dictionaries inside customData's own");
    let e = read("nested_dictionary_3000.usdc").unwrap_err();
    assert!(e.contains("nested deeper than"), "{e}");
}
