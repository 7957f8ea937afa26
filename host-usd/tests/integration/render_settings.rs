//! UsdRenderSettings on small hand-written stages: which settings prim applies, what a
//! RenderProduct overrides, the camera they name, and the errors and notes on bad settings.

use host_usd::render_settings::Conform;
use host_usd::{Options, UsdError, UsdScene};

const CAMERAS: &str = r#"
def Camera "First" { double3 xformOp:translate = (0, 0, 9)
    uniform token[] xformOpOrder = ["xformOp:translate"] }
def Camera "Second" { double3 xformOp:translate = (0, 0, 5)
    uniform token[] xformOpOrder = ["xformOp:translate"] }
"#;

fn import_with(meta: &str, body: &str, options: &Options) -> Result<UsdScene, UsdError> {
    let dir = tempfile::Builder::new().prefix("ppis-usd-rs-").tempdir().unwrap();
    let file = dir.path().join("s.usda");
    std::fs::write(&file, format!("#usda 1.0\n(\n    upAxis = \"Y\"\n{meta}\n)\n{CAMERAS}\n{body}\n")).unwrap();
    host_usd::load_with(&file, options)
}

fn import(meta: &str, body: &str) -> UsdScene {
    import_with(meta, body, &Options::default()).unwrap()
}

const TWO_SETTINGS: &str = r#"
def Scope "Render" {
    def RenderSettings "Preview" { uniform int2 resolution = (320, 180) }
    def RenderSettings "Final" {
        uniform int2 resolution = (1920, 1080)
        uniform float pixelAspectRatio = 2
        uniform token aspectRatioConformPolicy = "cropAperture"
        rel camera = </Second>
    }
}"#;

#[test]
fn the_layer_names_the_settings_and_they_name_the_camera() {
    let s = import("    renderSettingsPrimPath = \"/Render/Final\"", TWO_SETTINGS);
    let r = s.render_settings.as_ref().unwrap();
    assert_eq!((r.path.as_str(), r.resolution, r.pixel_aspect), ("/Render/Final", (1920, 1080), 2.0));
    assert_eq!(r.conform, Conform::CropAperture);
    assert_eq!(s.camera.as_ref().unwrap().path, "/Second");
    assert!(s.skipped.is_empty(), "{:?}", s.skipped);
    // --render-settings chooses another; --camera overrides the settings' camera.
    let options = Options { render_settings: Some("/Render/Preview".into()), camera: None, ..Default::default() };
    let s = import_with("", TWO_SETTINGS, &options).unwrap();
    assert_eq!(s.render_settings.as_ref().unwrap().resolution, (320, 180));
    assert_eq!(s.camera.as_ref().unwrap().path, "/First");
    let options = Options { render_settings: None, camera: Some("/First".into()), ..Default::default() };
    let s = import_with("    renderSettingsPrimPath = \"/Render/Final\"", TWO_SETTINGS, &options).unwrap();
    assert_eq!(s.camera.as_ref().unwrap().path, "/First");
}

#[test]
fn without_the_layer_metadata_the_only_settings_apply_and_several_are_a_note() {
    let one = "def RenderSettings \"Only\" { rel camera = </Second> }";
    let s = import("", one);
    let r = s.render_settings.as_ref().unwrap();
    // Unauthored attributes take the schema's fallbacks.
    assert_eq!((r.resolution, r.pixel_aspect, r.conform), ((2048, 1080), 1.0, Conform::ExpandAperture));
    assert_eq!(s.camera.as_ref().unwrap().path, "/Second");
    let s = import("", TWO_SETTINGS);
    assert_eq!(s.render_settings.as_ref().unwrap().path, "/Render/Preview");
    assert!(s.skipped.iter().any(|k| k.what.contains("2 RenderSettings prims")), "{:?}", s.skipped);
    // No settings at all: the first camera, no render settings.
    let s = import("", "");
    assert!(s.render_settings.is_none());
    assert_eq!(s.camera.as_ref().unwrap().path, "/First");
}

#[test]
fn the_first_render_product_overrides_what_it_authors() {
    let body = r#"
def RenderSettings "S" {
    uniform int2 resolution = (640, 480)
    uniform float pixelAspectRatio = 1.5
    rel camera = </First>
    rel products = [</P>, </Q>]
}
def RenderProduct "P" { uniform int2 resolution = (200, 100)
    rel camera = </Second> }
def RenderProduct "Q" { uniform int2 resolution = (10, 10) }"#;
    let s = import("", body);
    let r = s.render_settings.as_ref().unwrap();
    assert_eq!((r.resolution, r.pixel_aspect), ((200, 100), 1.5));
    assert_eq!(s.camera.as_ref().unwrap().path, "/Second");
    assert!(s.skipped.iter().any(|k| k.what.contains("2 render products")), "{:?}", s.skipped);
}

#[test]
fn bad_settings_are_errors_or_notes_naming_the_prim() {
    let err = |meta: &str, body: &str, options: &Options| import_with(meta, body, options).err().unwrap().to_string();
    let e = err("", "def RenderSettings \"S\" { uniform int2 resolution = (0, 100) }", &Options::default());
    assert!(e.contains("/S") && e.contains("resolution"), "{e}");
    let e = err(
        "",
        "def RenderSettings \"S\" { uniform token aspectRatioConformPolicy = \"squash\" }",
        &Options::default(),
    );
    assert!(e.contains("aspectRatioConformPolicy"), "{e}");
    let e = err("", "def RenderSettings \"S\" { rel camera = </Nowhere> }", &Options::default());
    assert!(e.contains("/Nowhere") && e.contains("named by /S"), "{e}");
    let options = Options { render_settings: Some("/First".into()), camera: None, ..Default::default() };
    let e = err("", "", &options);
    assert!(e.contains("/First") && e.contains("no such RenderSettings"), "{e}");
    // Metadata naming nothing is a note, and no settings apply.
    let s = import("    renderSettingsPrimPath = \"/Render/Missing\"", TWO_SETTINGS);
    assert!(s.render_settings.is_none());
    assert!(s.skipped.iter().any(|k| k.what.contains("/Render/Missing")), "{:?}", s.skipped);
}
