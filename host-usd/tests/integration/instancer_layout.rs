//! A PointInstancer's prototypes render only through it wherever they lie in the
//! namespace: before the instancer in traversal order (the import walks once, so this one
//! walks again), below it (the usual layout), or after it.

use host_usd::UsdScene;

fn import(body: &str) -> UsdScene {
    let dir = tempfile::Builder::new().prefix("ppis-usd-instancer-").tempdir().unwrap();
    let file = dir.path().join("stage.usda");
    std::fs::write(&file, format!("#usda 1.0\n(\n    upAxis = \"Y\"\n)\n{body}\n")).unwrap();
    host_usd::load(&file).unwrap()
}

const PROTOTYPE: &str = r#"def Xform "Protos" {
    def Sphere "Ball" { double radius = 0.5 }
}
"#;

fn instancer(prototype: &str, children: &str) -> String {
    format!(
        r#"def PointInstancer "Inst" {{
    rel prototypes = [<{prototype}>]
    int[] protoIndices = [0, 0]
    point3f[] positions = [(10, 0, 0), (20, 0, 0)]
{children}}}
"#
    )
}

/// The spheres' centres, sorted by x, and their names.
fn spheres(scene: &UsdScene) -> Vec<(f32, String)> {
    let mut s: Vec<(f32, String)> = scene.spheres.iter().map(|s| (s.center.x, s.path.clone())).collect();
    s.sort_by(|a, b| a.0.total_cmp(&b.0));
    s
}

fn assert_two_instances(scene: &UsdScene, ball: &str) {
    let want = vec![(10.0, format!("{ball}[/Inst:0]")), (20.0, format!("{ball}[/Inst:1]"))];
    assert_eq!(spheres(scene), want);
    assert_eq!(scene.counts.instances, 2);
}

#[test]
fn a_prototype_before_its_instancer_is_not_rendered_in_place() {
    let scene = import(&format!("{PROTOTYPE}{}", instancer("/Protos/Ball", "")));
    assert_two_instances(&scene, "/Protos/Ball");
}

#[test]
fn a_prototype_below_or_after_its_instancer_is_not_rendered_in_place() {
    let below = instancer("/Inst/Protos/Ball", &PROTOTYPE.replace('\n', "\n    "));
    assert_two_instances(&import(&below), "/Inst/Protos/Ball");
    let after = format!("{}{PROTOTYPE}", instancer("/Protos/Ball", ""));
    assert_two_instances(&import(&after), "/Protos/Ball");
}

#[test]
fn an_instancer_inside_a_prototype_renders_only_through_the_outer_one() {
    // /Outer instances /Outer/Protos/Inner, an instancer of /Outer/Protos/Inner/Protos/Ball.
    let inner = instancer("/Outer/Protos/Inst/Protos/Ball", &PROTOTYPE.replace('\n', "\n    "));
    let body = format!(
        r#"def PointInstancer "Outer" {{
    rel prototypes = [</Outer/Protos/Inst>]
    int[] protoIndices = [0]
    point3f[] positions = [(100, 0, 0)]
    def Xform "Protos" {{
        {}
    }}
}}
"#,
        inner.replace('\n', "\n        ")
    );
    let scene = import(&body);
    // The inner instancer lies in a prototype, so it draws nothing in place; the outer
    // instance draws the prototype's gprims (the ball, in the prototype's own frame).
    let want = vec![(100.0, "/Outer/Protos/Inst/Protos/Ball[/Outer:0]".to_string())];
    assert_eq!(spheres(&scene), want);
}

#[test]
fn what_a_prototype_holds_and_an_instance_cannot_carry_is_a_note() {
    let prototype = PROTOTYPE.replace(
        "}\n",
        "    def GeometryLight \"Glow\" { rel geometry = </Protos/Ball> }\n    def DomeLight \"Sky\" {}\n}\n",
    );
    let scene = import(&format!("{prototype}{}", instancer("/Protos", "")));
    for (path, t) in [("/Protos/Glow", "GeometryLight"), ("/Protos/Sky", "DomeLight")] {
        let notes: Vec<&str> = scene.skipped.iter().filter(|k| k.path == path).map(|k| k.what.as_str()).collect();
        assert_eq!(notes, [format!("{t} inside a PointInstancer prototype: not rendered")], "{:?}", scene.skipped);
    }
    assert!(scene.dome.is_none() && scene.lights.is_empty());
    assert_eq!(spheres(&scene).len(), 2, "the ball still renders per instance");
}
