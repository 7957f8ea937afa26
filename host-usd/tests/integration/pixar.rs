//! host-usd against Pixar's own answers. The fixtures were authored with Pixar's library
//! (`tests/fixtures/make_fixtures.py`, usd-core 26.11), which also saved what it computes:
//! world matrices, bound materials, PointInstancer instance transforms, stage metadata.

use glam::DMat4;
use host_usd::conformance;
use host_usd::xform::WorldTransforms;
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

#[test]
fn every_fixture_matches_pixar_to_1e_9() {
    let pairs = conformance::pairs(&fixtures());
    // usda, usdc and usdz, each with Pixar's answers beside it.
    for ext in ["usda", "usdc", "usdz"] {
        assert!(pairs.iter().any(|(p, _)| p.extension().unwrap() == ext), "no .{ext} fixture");
    }
    assert!(pairs.len() >= 12, "{} fixtures", pairs.len());
    let mut matrices = 0;
    for (usd, expected) in &pairs {
        let r = conformance::check(usd, expected).unwrap();
        assert!(r.mismatches.is_empty(), "{}: {:#?}", usd.display(), r.mismatches);
        assert!(r.max_matrix_error <= 1e-9, "{}: {}", usd.display(), r.max_matrix_error);
        matrices += r.matrices;
    }
    assert!(matrices >= 80, "only {matrices} world matrices checked");
}

#[test]
fn instancer_transforms_match_pixar() {
    for file in ["instancing.usda", "instancing.usdc"] {
        let usd = fixtures().join(file);
        let text = std::fs::read_to_string(fixtures().join("instancing.expected.json")).unwrap();
        let want: serde_json::Value = serde_json::from_str(&text).unwrap();
        let stage = host_usd::import::open(&usd, host_usd::TimeCode::Default).unwrap();
        let mut worlds = WorldTransforms::default();
        for (path, w) in want["instancers"].as_object().unwrap() {
            let (protos, instances) =
                host_usd::instancer::read(&stage, &host_usd::stage::PrimPath::new(path).unwrap()).unwrap();
            let mask: Vec<bool> = w["mask"].as_array().unwrap().iter().map(|b| b.as_bool().unwrap()).collect();
            let visible: Vec<usize> = instances.iter().map(|i| i.index).collect();
            let want_visible: Vec<usize> = (0..mask.len()).filter(|&i| mask[i]).collect();
            assert_eq!(visible, want_visible, "{file}: invisibleIds");
            let proto_indices: Vec<u64> =
                w["protoIndices"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
            // Pixar lists the transforms of the visible instances only, in order.
            assert_eq!(w["transforms"].as_array().unwrap().len(), instances.len());
            for (k, inst) in instances.iter().enumerate() {
                assert_eq!(inst.prototype as u64, proto_indices[inst.index]);
                // Pixar's instance transform includes the prototype root's own transform.
                let root = &protos[inst.prototype];
                let ours = inst.transform * worlds.relative_to(&stage, root, root).unwrap();
                let rows = &w["transforms"][k];
                let pixar = DMat4::from_cols_array(&std::array::from_fn(|k| rows[k / 4][k % 4].as_f64().unwrap()));
                let err = (ours - pixar).to_cols_array().iter().fold(0.0f64, |m, d| m.max(d.abs()));
                assert!(err <= 1e-9, "{file} instance {}: {err:e}\nours {ours}\npixar {pixar}", inst.index);
            }
        }
    }
}

/// A row-major 4×4 of Pixar's JSON (row vectors) as a column-vector matrix.
fn pixar_matrix(rows: &serde_json::Value) -> DMat4 {
    DMat4::from_cols_array(&std::array::from_fn(|k| rows[k / 4][k % 4].as_f64().unwrap()))
}

#[test]
fn instances_keep_each_prototype_once_and_pixars_transforms() {
    let scene = host_usd::load(&fixtures().join("instancing.usda")).unwrap();
    let text = std::fs::read_to_string(fixtures().join("instancing.expected.json")).unwrap();
    let want: serde_json::Value = serde_json::from_str(&text).unwrap();
    let set = &scene.instanced;
    assert_eq!(set.instancers, ["/World/Forest"]);
    // The cone (instances 0 and 3) and the rock (1 and 4: neither under a uniform scale, the
    // authored half-precision quaternion of 1 not being unit) are instances; 2 is invisible.
    let indices: Vec<u32> = set.instances.iter().map(|i| i.index).collect();
    assert_eq!(indices, [0, 1, 3, 4]);
    assert_eq!(set.prototypes.len(), 2, "each prototype gprim is read once");
    assert!(scene.meshes.iter().all(|m| !m.path.contains('[')), "no instance is a mesh of its own");
    // Pixar's instance transform includes the prototype root's own; the cone's scale lies
    // below the root.
    let pixar = &want["instancers"]["/World/Forest"]["transforms"];
    let visible = [0, 1, 3, 4];
    let forest = pixar_matrix(&want["prims"]["/World/Forest"]["world"]);
    let conversion = host_usd::xform::up_axis_conversion(true);
    for inst in &set.instances {
        let k = visible.iter().position(|&v| v == inst.index).unwrap();
        let path = &set.prototypes[inst.prototype as usize].path;
        let part = if path.ends_with("Crown") { DMat4::from_scale((0.5, 0.5, 1.0).into()) } else { DMat4::IDENTITY };
        let expected = conversion * forest * pixar_matrix(&pixar[k]) * part;
        let err = (DMat4::from(inst.transform) - expected).to_cols_array().iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert!(err <= 1e-9, "instance {}: {err:e}", inst.index);
    }
    // Placed, each instance is its prototype's triangles under its transform, named by it.
    let placed: Vec<String> =
        scene.all_meshes().iter().filter(|m| m.path.contains('[')).map(|m| m.path.clone()).collect();
    let names = ["Crown[/World/Forest:0]", "Rock[/World/Forest:1]", "Crown[/World/Forest:3]", "Rock[/World/Forest:4]"];
    assert_eq!(placed.len(), names.len());
    placed.iter().zip(names).for_each(|(p, n)| assert!(p.ends_with(n), "{p}"));
    let (inst, mesh) = (&set.instances[0], set.mesh(0, 0));
    let proto = &set.prototypes[inst.prototype as usize];
    let corner = inst.transform.transform_point3(proto.local.positions[proto.local.triangles[0][0] as usize]);
    assert_eq!(mesh.positions[mesh.triangles[0][0] as usize], corner.as_vec3());
}

#[test]
fn instancer_renders_instances_not_prototypes() {
    let scene = host_usd::load(&fixtures().join("instancing.usda")).unwrap();
    // 4 visible instances (tree, rock, tree, rock) of one gprim each, plus 3 chairs as
    // instance proxies; the prototypes themselves are not rendered in place.
    let meshes = scene.all_meshes();
    assert!(meshes.iter().all(|m| !m.path.starts_with("/World/Forest/Prototypes") || m.path.contains('[')));
    let instanced = meshes.iter().filter(|m| m.path.contains("[/World/Forest:")).count()
        + scene.spheres.iter().filter(|s| s.path.contains("[/World/Forest:")).count();
    assert_eq!(instanced, 4);
    assert_eq!(scene.counts.instances, 4 + 3);
    let chairs = meshes.iter().filter(|m| m.path.starts_with("/World/Chair")).count();
    assert_eq!(chairs, 3);
    // Z-up stage: converted to Y up.
    assert_eq!(scene.up_axis, host_usd::UpAxis::Z);
}

#[test]
fn usdz_texture_and_dome_are_read_from_inside_the_package() {
    let scene = host_usd::load(&fixtures().join("textured.usdz")).unwrap();
    let dome = scene.dome.as_ref().expect("dome");
    let (name, bytes) = dome.texture.as_ref().expect("dome texture");
    assert!(name.contains("textured.usdz[") && name.ends_with("bright_texel.png]"), "{name}");
    assert_eq!(&bytes[1..4], b"PNG");
    // color · intensity · 2^exposure = (1, 0.5, 0.25) · 2 · 2.
    assert!((dome.radiance - glam::Vec3::new(4.0, 2.0, 1.0)).length() < 1e-6, "{}", dome.radiance);
    let m = scene.materials.iter().find(|m| m.name == "/Root/Looks/Tex").unwrap();
    let t = &m.textures[0];
    assert_eq!(t.input, host_usd::TextureInput::DiffuseColor);
    assert_eq!(t.source.scale, [0.5, 0.5, 0.5, 1.0]);
    assert_eq!(&t.bytes.as_ref().unwrap()[1..4], b"PNG");
    assert!(scene.camera.as_ref().is_some_and(|c| c.path == "/Root/Cam" && c.focal_length == 35.0));
}

#[test]
fn materials_follow_the_preview_surface_rules() {
    let scene = host_usd::load(&fixtures().join("materials.usda")).unwrap();
    let lobes = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap().lobes();
    let gold = lobes("/Root/Looks/Gold");
    assert_eq!(gold.diffuse, glam::Vec3::ZERO);
    assert!((gold.specular - glam::Vec3::new(1.0, 0.8, 0.3)).length() < 1e-6);
    assert!((gold.alpha - 0.04).abs() < 1e-7);
    let coat = lobes("/Root/Looks/Coat");
    assert_eq!(coat.clearcoat, 1.0);
    assert!((coat.clearcoat_alpha - 0.0025).abs() < 1e-7);
    let spec = lobes("/Root/Looks/Spec");
    assert!((spec.specular - glam::Vec3::new(0.5, 0.6, 0.7)).length() < 1e-6);
    assert!((spec.diffuse - glam::Vec3::splat(0.2)).length() < 1e-6);
    // The GeomSubset's faces get their own material: the quad mesh splits in two.
    let quads: Vec<_> = scene.meshes.iter().filter(|m| m.path == "/Root/Quads").collect();
    assert_eq!(quads.len(), 2);
    let names: Vec<&str> = quads.iter().map(|m| scene.materials[m.material].name.as_str()).collect();
    assert!(names.contains(&"/Root/Looks/Spec") && names.contains(&"/Root/Looks/Gold"), "{names:?}");
    // Unbound gprims get UsdPreviewSurface's fallback.
    assert!(scene.materials.iter().any(|m| m.name == "<fallback>"));
}
