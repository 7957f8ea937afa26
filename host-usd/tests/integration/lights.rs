//! UsdLux lights (fixtures authored with Pixar's library by `tests/fixtures/make_lights.py`):
//! each kind imports at its world position and size with the schema's radiance (intensity ·
//! 2^exposure · color · blackbody, divided by the area with `normalize`); pre-21.02 names are
//! read; dark, invisible and partly supported lights are notes; a NaN or negative input is an
//! error naming the prim; the blackbody colour agrees with Pixar's (divided by its 6500 K
//! colour, which the schema makes white) within 1% from 3000 K up and 5% below. ShapingAPI is
//! read about each light's axis, and lights inside PointInstancer prototypes and instanceable
//! references come once per instance.

use glam::Vec3;
use host_usd::lights::{Emitter, UsdLight};
use host_usd::{UsdError, UsdScene};
use std::f32::consts::PI;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

fn light<'a>(s: &'a UsdScene, path: &str) -> &'a UsdLight {
    s.lights.iter().find(|l| l.path == path).unwrap_or_else(|| panic!("no light {path}: {:?}", s.skipped))
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() <= 1e-4 * b.length().max(1.0)
}

fn notes_of<'a>(s: &'a UsdScene, path: &str) -> Vec<&'a str> {
    s.skipped.iter().filter(|k| k.path == path).map(|k| k.what.as_str()).collect()
}

#[test]
fn each_kind_imports_at_its_place_and_size_with_the_schemas_radiance() {
    let s = host_usd::load(&fixture("lights.usda")).unwrap();
    let Emitter::Sphere { center, radius, radiance } = light(&s, "/World/Sphere").emitter else { panic!() };
    assert!(close(center, Vec3::new(1.0, 2.0, 3.0)) && (radius - 1.0).abs() < 1e-6);
    assert!(close(radiance, Vec3::new(6.0, 3.0, 1.5)), "3 · 2¹ · color: {radiance}");
    // treatAsPoint: the sphere's intensity π r² L.
    let Emitter::Point { position, intensity } = light(&s, "/World/Point").emitter else { panic!() };
    assert!(close(position, Vec3::new(0.0, 4.0, 0.0)));
    assert!(close(intensity, Vec3::splat(16.0 * PI * 0.0625)), "{intensity}");
    // 2 × 0.5 scaled ×3 in X: 6 × 0.5 facing down, normalised by its area 3.
    let Emitter::Rect { p0, e1, e2, radiance } = light(&s, "/World/Rect").emitter else { panic!() };
    let normal = e1.cross(e2);
    assert!(close(normal.normalize(), -Vec3::Y), "emits towards world −Y: {normal}");
    assert!((normal.length() - 3.0).abs() < 1e-5);
    assert!(close(p0 + 0.5 * (e1 + e2), Vec3::new(0.0, 3.0, 0.0)));
    assert!(close(radiance, Vec3::splat(10.0)), "30 / 3: {radiance}");
    // Turned −90° about Y: its −Z faces world +X; 3000 K is warm.
    let Emitter::Disk { center, normal, radius, radiance } = light(&s, "/World/Disk").emitter else { panic!() };
    assert!(close(center, Vec3::new(-2.0, 1.0, 0.0)) && close(normal, Vec3::X) && (radius - 0.4).abs() < 1e-6);
    assert!(radiance.x > radiance.y && radiance.y > radiance.z && radiance.x > 5.0, "{radiance}");
    let expected = host_usd::blackbody::rgb(3000.0).as_vec3() * 5.0;
    assert!(close(radiance, expected));
    // The default DistantLight: 0.53°, 50000 (not normalised), light from +Z turned by −30° about X.
    let Emitter::Distant { direction, irradiance, angle_deg } = light(&s, "/World/Sun").emitter else { panic!() };
    let t = (-30f32).to_radians();
    assert!(close(direction, Vec3::new(0.0, -t.sin(), t.cos())), "{direction}");
    assert!((angle_deg - 0.53).abs() < 1e-6);
    let e = 50000.0 * PI * (0.5 * 0.53f32).to_radians().sin().powi(2);
    assert!(close(irradiance, Vec3::splat(e)), "π sin²θ · L: {irradiance} vs {e}");
    // Angle 0: a delta light whose intensity is its irradiance.
    let Emitter::Distant { irradiance, angle_deg, .. } = light(&s, "/World/Delta").emitter else { panic!() };
    assert!(angle_deg == 0.0 && close(irradiance, Vec3::splat(2.0)));
    // A normalised CylinderLight: its tessellated side has the cylinder's area 2π r l.
    let Emitter::Triangles { ref positions, ref triangles, radiance, two_sided } = light(&s, "/World/Tube").emitter
    else {
        panic!()
    };
    let area: f32 = triangles
        .iter()
        .map(|t| {
            0.5 * (positions[t[1] as usize] - positions[t[0] as usize])
                .cross(positions[t[2] as usize] - positions[t[0] as usize])
                .length()
        })
        .sum();
    assert!((area - 2.0 * PI * 0.1 * 2.0).abs() < 1e-4 * area, "{area}");
    assert!(!two_sided && close(radiance, Vec3::splat(4.0 / area)));
    // Each facet faces outwards from the axis (local X at y = 1, z = −2).
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let out = (a + b + c) / 3.0 - Vec3::new((a.x + b.x + c.x) / 3.0, 1.0, -2.0);
        assert!((b - a).cross(c - a).dot(out) > 0.0);
    }
    // A doubleSided mesh light of area 1, normalised; its mesh is not also a surface.
    let Emitter::Triangles { ref positions, radiance, two_sided, .. } = light(&s, "/World/Panel").emitter else {
        panic!()
    };
    assert!(two_sided && close(radiance, Vec3::splat(2.0)) && close(positions[0], Vec3::new(5.0, 0.0, 0.0)));
    assert!(s.meshes.is_empty(), "the MeshLightAPI mesh is a light only");
    // Pre-21.02 names.
    let Emitter::Rect { e1, e2, radiance, .. } = light(&s, "/World/OldRect").emitter else { panic!() };
    assert!(
        close(radiance, Vec3::new(3.5, 7.0, 7.0))
            && (e2.length() - 0.5).abs() < 1e-6
            && (e1.length() - 1.0).abs() < 1e-6
    );
}

#[test]
fn dark_hidden_and_partly_rendered_lights_are_notes() {
    let s = host_usd::load(&fixture("lights.usda")).unwrap();
    for (path, needle) in [
        ("/World/Dark", "emits nothing"),
        ("/World/NoSize", "radius 0"),
        ("/World/Hidden", "invisible"),
        ("/World/Spot", "non-uniform scale"),
        ("/World/Portal", "PortalLight not rendered"),
    ] {
        let notes = notes_of(&s, path);
        assert!(notes.iter().any(|n| n.contains(needle)), "{path}: {needle:?} not in {notes:?}");
    }
    for path in ["/World/Dark", "/World/NoSize", "/World/Hidden", "/World/Portal"] {
        assert!(s.lights.iter().all(|l| l.path != path), "{path} is not rendered");
    }
    // The spot renders as a sphere shaped by its cone.
    assert!(matches!(light(&s, "/World/Spot").emitter, Emitter::Sphere { .. }));
    assert_eq!(light(&s, "/World/Spot").shaping.map(|x| x.cone_angle_deg), Some(30.0));
    assert_eq!(s.lights.len(), 10, "{:?}", s.lights.iter().map(|l| &l.path).collect::<Vec<_>>());
}

/// ShapingAPI (`lights_shaping.usda`): each input read, the axis the world image of the light's
/// −Z, the cone falling back to 90° where ShapingAPI is applied and to none where it is not, a
/// shaping that changes nothing dropped, and a kind that does not render it noted.
#[test]
fn shaping_inputs_are_read_about_the_lights_axis() {
    let s = host_usd::load(&fixture("lights_shaping.usda")).unwrap();
    let shaping = |path: &str| light(&s, path).shaping;
    let spot = shaping("/World/Spot").expect("the RectLight is shaped");
    assert!(close(spot.axis, -Vec3::Y), "{:?}", spot.axis);
    assert_eq!((spot.cone_angle_deg, spot.cone_softness, spot.focus), (30.0, 0.5, 2.0));
    assert!(close(spot.focus_tint, Vec3::new(0.1, 0.2, 0.3)));
    let point = shaping("/World/PointSpot").expect("the point light is shaped");
    assert!(matches!(light(&s, "/World/PointSpot").emitter, Emitter::Point { .. }));
    assert!(close(point.axis, Vec3::X) && point.cone_angle_deg == 40.0, "{point:?}");
    let disk = shaping("/World/FocusDisk").unwrap();
    assert_eq!((disk.cone_angle_deg, disk.focus, disk.focus_tint), (90.0, 4.0, Vec3::ZERO));
    let unapplied = shaping("/World/Unapplied").unwrap();
    assert_eq!((unapplied.cone_angle_deg, unapplied.focus), (180.0, 2.0));
    assert_eq!(shaping("/World/Plain"), None);
    assert_eq!(shaping("/World/ShapedSun"), None);
    let notes = notes_of(&s, "/World/ShapedSun");
    assert!(notes.iter().any(|n| n.contains("cone angle not rendered on a DistantLight")), "{notes:?}");
    for path in ["/World/Spot", "/World/PointSpot", "/World/FocusDisk", "/World/Unapplied", "/World/Plain"] {
        assert!(notes_of(&s, path).is_empty(), "{path}: {:?}", notes_of(&s, path));
    }
}

/// IES profiles (`lights_ies.usda`): the file resolved and read, angleScale and normalize, the
/// light's local −Z, +X and +Y in the world; the cone's fallback where ShapingAPI is applied and
/// none where only the file is authored; no note. A type B file is read here (the renderer
/// parses it); a missing file is an error naming it.
#[test]
fn ies_inputs_are_read_with_the_lights_frame() {
    let s = host_usd::load(&fixture("lights_ies.usda")).unwrap();
    let spot = light(&s, "/World/Spot");
    let ies = spot.ies.as_ref().expect("the point light has a profile");
    assert!(ies.name.ends_with("ies/bilateral_1995.ies"), "{}", ies.name);
    assert_eq!(ies.bytes, std::fs::read(fixture("ies/bilateral_1995.ies")).unwrap());
    assert!(close(ies.axis, -Vec3::Y) && close(ies.x, Vec3::X) && close(ies.y, -Vec3::Z), "{ies:?}");
    assert_eq!((ies.angle_scale, ies.normalize), (0.0, false));
    assert_eq!(spot.shaping.map(|x| x.cone_angle_deg), None, "cone 180° authored: no cone");
    let panel = light(&s, "/World/Panel");
    let ies = panel.ies.as_ref().unwrap();
    assert_eq!((ies.angle_scale, ies.normalize), (0.5, true));
    assert_eq!(panel.shaping.map(|x| x.cone_angle_deg), Some(90.0));
    let disk = light(&s, "/World/Disk");
    assert!(disk.ies.is_some() && disk.shaping.is_none());
    assert!(s.skipped.is_empty(), "{:?}", s.skipped);
    assert!(host_usd::load(&fixture("lights_ies_bad.usda")).unwrap().lights[0].ies.is_some());
    let missing = host_usd::load(&fixture("lights_ies_missing.usda")).unwrap_err().to_string();
    assert!(missing.contains("inputs:shaping:ies:file ies/nowhere.ies not found"), "{missing}");
}

/// Lights inside a PointInstancer's prototype and under instanceable references
/// (`lights_instanced.usda`): one light per visible instance, at the instance's transform.
#[test]
fn instanced_lights_take_each_instances_transform() {
    let s = host_usd::load(&fixture("lights_instanced.usda")).unwrap();
    let bulb = |i: usize| light(&s, &format!("/World/Lamps/Protos/Lamp/Bulb[/World/Lamps:{i}]"));
    let Emitter::Sphere { center, radius, .. } = bulb(0).emitter else { panic!() };
    assert!(close(center, Vec3::new(0.0, 1.0, 0.0)) && (radius - 0.1).abs() < 1e-6, "{center} {radius}");
    // Scaled ×2 and moved to x = 5.
    let Emitter::Sphere { center, radius, .. } = bulb(1).emitter else { panic!() };
    assert!(close(center, Vec3::new(5.0, 2.0, 0.0)) && (radius - 0.2).abs() < 1e-6, "{center} {radius}");
    let panel = |i: usize| light(&s, &format!("/World/Lamps/Protos/Lamp/Panel[/World/Lamps:{i}]"));
    let Emitter::Triangles { positions, .. } = &panel(1).emitter else { panic!() };
    assert!(positions.iter().any(|p| close(*p, Vec3::new(7.0, 0.0, 2.0))), "{positions:?}");
    assert!(matches!(panel(0).emitter, Emitter::Triangles { .. }));
    // Instance id 12 is invisible.
    assert!(s.lights.iter().all(|l| !l.path.ends_with(":2]")), "{:?}", s.lights);
    for (path, x) in [("/World/A/Panel", -4.0), ("/World/B/Panel", 4.0)] {
        let Emitter::Rect { p0, e1, e2, .. } = light(&s, path).emitter else { panic!() };
        assert!(close(p0 + 0.5 * (e1 + e2), Vec3::new(x, 2.0, 0.0)), "{path}: {p0}");
    }
    assert_eq!(s.lights.len(), 6, "{:?}", s.lights.iter().map(|l| &l.path).collect::<Vec<_>>());
}

/// What is not rendered (`lights_unrendered.usda`) is a note each: an IES profile on a
/// DistantLight, a light filter, light and shadow linking, a PortalLight, a PluginLight and a dome's portals.
#[test]
fn what_is_not_rendered_is_a_note_each() {
    let s = host_usd::load(&fixture("lights_unrendered.usda")).unwrap();
    for (path, needle) in [
        ("/World/Sun", "IES profile profile.ies not rendered on a DistantLight"),
        ("/World/Lamp", "light filters not rendered"),
        ("/World/Lamp", "light linking (collection:lightLink) not honoured"),
        ("/World/Lamp", "shadow linking (collection:shadowLink) not honoured"),
        ("/World/Window", "PortalLight not rendered"),
        ("/World/Plugin", "PluginLight not rendered"),
        ("/World/Sky", "portals ignored"),
    ] {
        let notes = notes_of(&s, path);
        assert!(notes.iter().any(|n| n.contains(needle)), "{path}: {needle:?} not in {notes:?}");
    }
    // The lamp itself renders.
    assert!(matches!(light(&s, "/World/Lamp").emitter, Emitter::Sphere { .. }));
}

#[test]
fn a_dome_takes_its_colour_temperature() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("dome.usda");
    let dome = "def DomeLight \"D\" { bool inputs:enableColorTemperature = 1\n float inputs:colorTemperature = 4000 }";
    std::fs::write(&file, format!("#usda 1.0\n{dome}\n")).unwrap();
    let s = host_usd::load(&file).unwrap();
    let expected = host_usd::blackbody::rgb(4000.0).as_vec3();
    assert!(close(s.dome.unwrap().radiance, expected));
    assert!(s.skipped.is_empty(), "{:?}", s.skipped);
}

#[test]
fn a_z_up_stage_turns_its_lights_with_its_geometry() {
    let s = host_usd::load(&fixture("lights_z.usda")).unwrap();
    let Emitter::Distant { direction, .. } = light(&s, "/Up").emitter else { panic!() };
    assert!(close(direction, Vec3::Y), "{direction}");
}

#[test]
fn a_light_that_cannot_exist_is_an_error_naming_the_prim() {
    let dir = tempfile::tempdir().unwrap();
    for (body, needle) in [
        ("def SphereLight \"L\" { float inputs:intensity = nan }", "inputs:intensity"),
        ("def RectLight \"L\" { color3f inputs:color = (1, -1, 1) }", "inputs:color"),
        ("def DiskLight \"L\" { float inputs:radius = -1 }", "inputs:radius"),
        ("def DistantLight \"L\" { float inputs:intensity = -5 }", "negative"),
        ("def RectLight \"L\" { asset inputs:texture:file = @gone.png@ }", "texture:file gone.png not found"),
    ] {
        let file = dir.path().join("bad.usda");
        std::fs::write(&file, format!("#usda 1.0\n{body}\n")).unwrap();
        match host_usd::load(&file) {
            Err(UsdError::Prim { prim, message, .. }) => {
                assert_eq!(prim, "/L");
                assert!(message.contains(needle), "{body}: {message}");
            }
            other => panic!("{body}: {other:?}"),
        }
    }
}

#[test]
fn the_blackbody_colour_is_pixars_up_to_the_schemas_white_at_6500_k() {
    let text = std::fs::read_to_string(fixture("blackbody.json")).unwrap();
    let pixar: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&text).unwrap();
    let rgb = |k: &str| -> [f64; 3] {
        let v = pixar[k].as_array().unwrap();
        [0, 1, 2].map(|c| v[c].as_f64().unwrap())
    };
    let white = rgb("6500");
    for (k, _) in &pixar {
        let p = rgb(k);
        let kelvin: f64 = k.parse().unwrap();
        let ours = host_usd::blackbody::rgb(kelvin);
        // Pixar interpolates a table, host-usd integrates a fit of the CIE observer: they
        // differ most where the locus bends fastest, below 3000 K.
        let tolerance = if kelvin >= 3000.0 { 0.01 } else { 0.05 };
        for c in 0..3 {
            let expected = p[c] / white[c];
            let d = (ours[c] - expected).abs();
            assert!(d <= tolerance * expected.max(0.1), "{k} K channel {c}: {} vs {expected}", ours[c]);
        }
    }
}

/// A GeometryLight (`lights_geometry.usda`) makes the gprims it targets emit with its inputs,
/// as MeshLightAPI would, whether the walk meets the light or the gprim first; the gprims
/// are lights only, not also surfaces. A GeometryLight with nothing to light is a note.
#[test]
fn a_geometry_light_makes_its_targets_emit_and_not_also_surfaces() {
    let s = host_usd::load(&fixture("lights_geometry.usda")).unwrap();
    let Emitter::Triangles { ref positions, ref triangles, radiance, two_sided } =
        light(&s, "/World/PanelLight").emitter
    else {
        panic!()
    };
    assert_eq!(triangles.len(), 2);
    assert!(two_sided, "the quad is doubleSided");
    assert!(positions.iter().all(|p| (5.0..=6.0).contains(&p.x) && (0.0..=1.0).contains(&p.y) && p.z == 0.0));
    assert!(close(radiance, Vec3::new(2.0, 1.0, 0.5)), "2 · color over area 1: {radiance}");
    let Emitter::Triangles { ref positions, radiance, two_sided, .. } = light(&s, "/World/BallLight").emitter else {
        panic!()
    };
    assert!(!two_sided);
    assert!(positions.iter().all(|p| ((*p - Vec3::new(0.0, 2.0, 0.0)).length() - 0.5).abs() < 1e-3));
    assert!(close(radiance, Vec3::splat(6.0)), "3 · 2¹, not normalised: {radiance}");
    assert_eq!(light(&s, "/World/BallLight").prim_type, "GeometryLight");
    // Neither target is also a surface; the untargeted cube is.
    assert!(s.spheres.is_empty(), "{:?}", s.spheres.iter().map(|p| &p.path).collect::<Vec<_>>());
    let surfaces: Vec<&str> = s.meshes.iter().map(|m| m.path.as_str()).collect();
    assert_eq!(surfaces, ["/World/Box"]);
    assert_eq!((s.counts.gprims, s.counts.meshes), (1, 0), "{:?}", s.counts);
    assert_eq!(s.counts.triangles, s.meshes[0].triangles.len());
    for (path, note) in [
        ("/World/Empty", "targets no geometry"),
        ("/World/NotGprim", "is not a gprim"),
        ("/World/HiddenTarget", "is invisible"),
    ] {
        let notes = notes_of(&s, path);
        assert!(notes.iter().any(|n| n.contains(note)), "{path}: {notes:?}");
        assert!(s.lights.iter().all(|l| l.path != path));
    }
    assert!(s.skipped.iter().all(|k| !k.what.contains("GeometryLight not rendered")), "{:?}", s.skipped);
}
