//! openusd's paths as host-usd uses them: a path made by appending equals (and hashes as)
//! the path parsed from its text, and the namespace queries answer as on the text, for
//! structured paths and for texts outside the structured grammar alike.

use openusd::sdf::Path;
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};

fn p(text: &str) -> Path {
    Path::new(text).unwrap()
}

fn hash(path: &Path) -> u64 {
    let mut h = DefaultHasher::new();
    path.hash(&mut h);
    h.finish()
}

#[test]
fn appended_paths_equal_parsed_ones() {
    let built = Path::abs_root()
        .append_path("World")
        .unwrap()
        .append_variant_selection("look", "red")
        .append_path("Mesh")
        .unwrap()
        .append_property("primvars:st")
        .unwrap();
    let parsed = p("/World{look=red}Mesh.primvars:st");
    assert_eq!(built, parsed);
    assert_eq!(hash(&built), hash(&parsed));
    assert_eq!(built.as_str(), "/World{look=red}Mesh.primvars:st");
    assert_eq!(built.to_string(), parsed.to_string());
    // Texts outside the grammar are paths too, equal to themselves only.
    assert_eq!(p("../A.rel[/T].x"), p("../A.rel[/T].x"));
    assert_ne!(p("/A/B"), p("/A/B.x"));
    assert_ne!(p("/A/B"), p("/A/Bc"));
}

#[test]
fn namespace_queries() {
    let attr = p("/A/B{v=s}C.size");
    assert_eq!(attr.parent(), Some(p("/A/B{v=s}C")));
    assert_eq!(attr.prim_path(), p("/A/B{v=s}C"));
    assert_eq!(p("/A/B{v=s}C").parent(), Some(p("/A/B{v=s}")));
    assert_eq!(p("/A/B{v=s}").parent(), Some(p("/A/B")));
    assert_eq!(p("/A").parent(), Some(Path::abs_root()));
    assert_eq!(Path::abs_root().parent(), None);
    assert_eq!(attr.property_suffix(), ".size");
    assert_eq!(attr.split_property().map(|(_, n)| n.to_string()), Some("size".into()));
    assert_eq!(p("/A/B{v=s}C").name(), Some("C"));
    assert_eq!(attr.prim_element_count(), 3);
    assert_eq!(attr.element_count(), 4);
    assert_eq!(attr.variant_set_name(), Some("v"));
    assert!(attr.contains_prim_variant_selection());
    assert_eq!(attr.strip_all_variant_selections(), p("/A/B/C.size"));
    assert!(attr.is_property_path() && !p("/A").is_property_path());
    assert!(p("/A{v=s}").is_prim_variant_selection_path());
}

#[test]
fn prefixes() {
    assert!(p("/A/B").has_prefix(&p("/A")));
    assert!(p("/A.x").has_prefix(&p("/A")));
    assert!(p("/A{v=s}B").has_prefix(&p("/A{v=s}")));
    assert!(p("/X").has_prefix(&Path::abs_root()));
    assert!(!p("/Ab").has_prefix(&p("/A")));
    assert!(p("/A.x.y").has_prefix(&p("/A.x")));
    let moved = |path: &str, old: &str, new: &str| p(path).replace_prefix(&p(old), &p(new));
    assert_eq!(moved("/Ref/Child.x", "/Ref", "/My/Prim"), Some(p("/My/Prim/Child.x")));
    assert_eq!(moved("/Ref/Child", "/Ref", "/P{v=s}"), Some(p("/P{v=s}Child")));
    assert_eq!(moved("/P{v=s}Child", "/P{v=s}", "/Q"), Some(p("/Q/Child")));
    assert_eq!(moved("/A/B", "/", "/C"), Some(p("/C/A/B")));
    assert_eq!(moved("/Other", "/Ref", "/My"), None);
    assert_eq!(moved("/Ref", "/Ref", "/My"), Some(p("/My")));
}

#[test]
fn paths_order_by_their_text() {
    // Siblings, a property beside a child (`.` sorts before `/`), variant selections
    // (`{` after letters), prims below a selection, an opaque relationship-target path,
    // and paths of different depths: every pair orders as its texts do.
    let texts = [
        "/",
        "/A",
        "/A/B",
        "/A/B2",
        "/A/Ba",
        "/A/B.x",
        "/A/B.x:y",
        "/A/B/C",
        "/A/B/C/D.z",
        "/A{v=s}",
        "/A{v=s}B",
        "/A{v=t}",
        "/A{v=s}B/C",
        "/Ab",
        "/B",
        "/A.rel[/T]",
        "/A.a",
        "/A.a.b",
        "/B/A",
    ];
    let paths: Vec<Path> = texts.iter().map(|t| p(t)).collect();
    for (a, ta) in paths.iter().zip(texts) {
        for (b, tb) in paths.iter().zip(texts) {
            assert_eq!(a.cmp(b), ta.cmp(tb), "{ta} against {tb}");
        }
    }
    let mut sorted = paths.clone();
    sorted.sort();
    let mut sorted_texts = texts.to_vec();
    sorted_texts.sort();
    assert_eq!(sorted.iter().map(Path::to_string).collect::<Vec<_>>(), sorted_texts);
}

#[test]
fn a_very_deep_path_drops_without_recursion() {
    // Run on a small stack: dropping the last reference to a chain unlinks it in a loop.
    std::thread::Builder::new()
        .stack_size(256 * 1024)
        .spawn(|| {
            let mut path = Path::abs_root();
            for i in 0..200_000 {
                path = path.append_path(format!("P{i}").as_str()).unwrap();
            }
            assert_eq!(path.prim_element_count(), 200_000);
            assert_eq!(path.parent().unwrap().prim_element_count(), 199_999);
        })
        .unwrap()
        .join()
        .unwrap();
}
