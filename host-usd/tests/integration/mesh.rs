//! Mesh import rules on small hand-written stages: fan triangulation, `holeIndices`,
//! `orientation = leftHanded`, mirroring transforms, normals in every interpolation with
//! `:indices`, `primvars:normals` over `normals`, subdivision meshes, visibility and purpose.

use glam::Vec3;
use host_usd::UsdScene;

fn import(body: &str) -> UsdScene {
    let dir = tempfile::Builder::new().prefix("ppis-usd-mesh-").tempdir().unwrap();
    let file = dir.path().join("m.usda");
    std::fs::write(&file, format!("#usda 1.0\n(\n    upAxis = \"Y\"\n)\n{body}\n")).unwrap();
    host_usd::load(&file).unwrap()
}

const QUADS: &str = r#"
        point3f[] points = [(0, 0, 0), (1, 0, 0), (2, 0, 0), (0, 1, 0), (1, 1, 0), (2, 1, 0)]
        int[] faceVertexCounts = [4, 4]
        int[] faceVertexIndices = [0, 1, 4, 3, 1, 2, 5, 4]
        uniform token subdivisionScheme = "none""#;

fn face_normal(s: &UsdScene, m: usize, t: usize) -> Vec3 {
    let mesh = &s.meshes[m];
    let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
    (b - a).cross(c - a).normalize()
}

#[test]
fn fan_triangulation_holes_and_orientation() {
    let s = import(&format!("def Mesh \"M\"\n{{{QUADS}\n}}"));
    assert_eq!(s.meshes[0].triangles.len(), 4);
    assert!(face_normal(&s, 0, 0).abs_diff_eq(Vec3::Z, 1e-6));
    let s = import(&format!("def Mesh \"M\"\n{{{QUADS}\n        int[] holeIndices = [0]\n}}"));
    assert_eq!(s.meshes[0].triangles.len(), 2, "the hole's two triangles are gone");
    let s = import(&format!("def Mesh \"M\"\n{{{QUADS}\n        uniform token orientation = \"leftHanded\"\n}}"));
    assert!(face_normal(&s, 0, 0).abs_diff_eq(-Vec3::Z, 1e-6), "left-handed faces face −Z");
    // A mirroring transform flips the winding back to what the viewer sees.
    let s = import(&format!(
        "def Mesh \"M\"\n{{{QUADS}\n        float3 xformOp:scale = (1, 1, -1)\n        uniform token[] xformOpOrder = [\"xformOp:scale\"]\n}}"
    ));
    assert!(face_normal(&s, 0, 0).abs_diff_eq(-Vec3::Z, 1e-6));
}

#[test]
fn normals_in_every_interpolation() {
    let n = |s: &UsdScene| s.meshes[0].normals.clone();
    // faceVarying with indices: corner k of face f takes normals[indices[fv]].
    let s = import(&format!(
        "def Mesh \"M\"\n{{{QUADS}\n        normal3f[] primvars:normals = [(0, 0, 1), (1, 0, 0)] (interpolation = \"faceVarying\")\n        int[] primvars:normals:indices = [0, 0, 0, 0, 1, 1, 1, 1]\n}}"
    ));
    let normals = n(&s);
    assert_eq!(normals.len(), 4);
    assert!(normals[0].iter().all(|v| v.abs_diff_eq(Vec3::Z, 1e-6)));
    assert!(normals[3].iter().all(|v| v.abs_diff_eq(Vec3::X, 1e-6)));
    // uniform: one per face.
    let s = import(&format!(
        "def Mesh \"M\"\n{{{QUADS}\n        normal3f[] primvars:normals = [(0, 1, 0), (0, 0, 1)] (interpolation = \"uniform\")\n}}"
    ));
    assert!(n(&s)[1][2].abs_diff_eq(Vec3::Y, 1e-6) && n(&s)[2][0].abs_diff_eq(Vec3::Z, 1e-6));
    // vertex (the default of the plain `normals` attribute): per point.
    let s = import(&format!(
        "def Mesh \"M\"\n{{{QUADS}\n        normal3f[] normals = [(0,0,1),(0,0,1),(1,0,0),(0,0,1),(0,0,1),(1,0,0)]\n}}"
    ));
    // The second face's first fan triangle: points (1, 0, 0), (2, 0, 0), (2, 1, 0).
    let t = s.meshes[0].triangles[2].map(|i| s.meshes[0].positions[i as usize]);
    assert_eq!(t, [Vec3::X, Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)]);
    assert!(n(&s)[2][1].abs_diff_eq(Vec3::X, 1e-6) && n(&s)[2][0].abs_diff_eq(Vec3::Z, 1e-6));
    // constant; and primvars:normals wins over normals.
    let s = import(&format!(
        "def Mesh \"M\"\n{{{QUADS}\n        normal3f[] normals = [(1,0,0),(1,0,0),(1,0,0),(1,0,0),(1,0,0),(1,0,0)]\n        normal3f[] primvars:normals = [(0, 1, 0)] (interpolation = \"constant\")\n}}"
    ));
    assert!(n(&s).iter().flatten().all(|v| v.abs_diff_eq(Vec3::Y, 1e-6)));
    // Normals are transformed by the inverse transpose: a non-uniform scale tilts them.
    let s = import(&format!(
        "def Mesh \"M\"\n{{{QUADS}\n        normal3f[] primvars:normals = [(1, 1, 0)] (interpolation = \"constant\")\n        float3 xformOp:scale = (2, 1, 1)\n        uniform token[] xformOpOrder = [\"xformOp:scale\"]\n}}"
    ));
    assert!(n(&s)[0][0].abs_diff_eq(Vec3::new(1.0, 2.0, 0.0).normalize(), 1e-6));
}

#[test]
fn subdivision_meshes_render_their_cage_with_smooth_normals() {
    let body = QUADS.replace("\"none\"", "\"catmullClark\"");
    let s = import(&format!(
        "def Mesh \"M\"\n{{{body}\n        normal3f[] primvars:normals = [(1, 0, 0)] (interpolation = \"constant\")\n}}"
    ));
    // Authored normals are ignored on subdivision surfaces; a flat cage's smooth normals are
    // its face normal.
    assert_eq!(s.meshes[0].triangles.len(), 4);
    assert!(s.meshes[0].normals.iter().flatten().all(|v| v.abs_diff_eq(Vec3::Z, 1e-6)));
}

#[test]
fn invisible_guides_and_proxies_are_not_rendered() {
    let s = import(&format!(
        "def Xform \"Hidden\" {{\n    token visibility = \"invisible\"\n    def Mesh \"A\" {{{QUADS}\n    }}\n}}\ndef Mesh \"Guide\" {{{QUADS}\n    uniform token purpose = \"guide\"\n}}\ndef Mesh \"Proxy\" {{{QUADS}\n    uniform token purpose = \"proxy\"\n}}\ndef Mesh \"Render\" {{{QUADS}\n    uniform token purpose = \"render\"\n}}"
    ));
    assert_eq!(s.meshes.len(), 1);
    assert_eq!(s.meshes[0].path, "/Render");
    assert_eq!(s.counts.hidden, 3);
}

#[test]
fn bad_topology_is_an_error_naming_the_prim() {
    let dir = tempfile::Builder::new().prefix("ppis-usd-bad-").tempdir().unwrap();
    let file = dir.path().join("bad.usda");
    let body = QUADS.replace("[0, 1, 4, 3, 1, 2, 5, 4]", "[0, 1, 4, 3, 1, 2, 5, 40]");
    std::fs::write(&file, format!("#usda 1.0\ndef Mesh \"Broken\"\n{{{body}\n}}\n")).unwrap();
    let e = host_usd::load(&file).unwrap_err().to_string();
    assert!(e.contains("bad.usda") && e.contains("/Broken") && e.contains("40"), "{e}");
}

/// A prim name that is not an identifier is a clean error. (Found by the mutation test: a
/// flipped byte made `"Own"` into `"}wn"`, whose path was its own parent, and openusd's
/// instancing walk recursed until the stack overflowed.)
#[test]
fn prim_names_that_are_not_identifiers_are_errors() {
    let dir = tempfile::Builder::new().prefix("ppis-usd-name-").tempdir().unwrap();
    let file = dir.path().join("name.usda");
    let body = "def Xform \"Root\"\n{\n    def Cube \"}wn\"\n    {\n        double size = 1\n    }\n}\n";
    std::fs::write(&file, format!("#usda 1.0\n{body}")).unwrap();
    let e = host_usd::load(&file).unwrap_err().to_string();
    assert!(e.contains("name.usda") && e.contains("}wn"), "{e}");
}

#[test]
fn unbound_gprims_show_their_display_color() {
    let s = import(&format!(
        "def Mesh \"Red\" {{{QUADS}\n    color3f[] primvars:displayColor = [(0.8, 0.1, 0.1)] (interpolation = \"constant\")\n}}\ndef Mesh \"Plain\" {{{QUADS}\n}}"
    ));
    let name = |path: &str| &s.materials[s.meshes.iter().find(|m| m.path == path).unwrap().material];
    assert!((name("/Red").diffuse_color - Vec3::new(0.8, 0.1, 0.1)).length() < 1e-6);
    assert_eq!(name("/Plain").diffuse_color, Vec3::splat(0.18));
}
