//! A PointInstancer's instances, kept as prototype and transform and placed when the BVH
//! gathers them, render exactly as their flattened twin (each instance a mesh of its own).
#![cfg(feature = "usd")]

use host_std::light::environment::{EnvSource, Environment, Placement};
use host_std::plan::{Method, Settings, render};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::{Scene, Shape, usd};
use host_std::trace::bvh::Bvh;
use std::path::PathBuf;

fn render_bits(scene: &Scene) -> Vec<u32> {
    let (source, placement) = scene.env.clone().unwrap();
    let env = Environment::build(&source, placement).unwrap();
    let bvh = Bvh::build(scene);
    let settings = Settings {
        method: Method::Mis,
        spp: 4,
        shading_points: 4,
        brdf_samples: BrdfSamples::Fixed(32),
        seed: 3,
        progress: false,
        shadows: true,
        lights: Default::default(),
    };
    render(scene, &bvh, Some(&env.hierarchy()), &settings).pixels.iter().flatten().map(|v| v.to_bits()).collect()
}

#[test]
fn instances_render_as_their_flattened_twin() {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures/instancing.usda");
    let options = usd::Options { width: Some(48), height: Some(32), ..Default::default() };
    let mut scene = usd::load(&file, &options).unwrap().scene;
    scene.env = Some((EnvSource::Constant { level: 3 }, Placement::default()));
    let mut twin = scene.clone();
    let mut instances = 0;
    for o in &mut twin.objects {
        if let Shape::Instance { set, instance, group } = &o.shape {
            o.shape = set.0.mesh(*instance, *group);
            instances += 1;
        }
    }
    assert_eq!(instances, 4, "the two cones and the two rocks are instances");
    assert_eq!(scene.triangle_count(), twin.triangle_count());
    assert_eq!(Bvh::count_primitives(&scene), Bvh::count_primitives(&twin));
    let (a, b) = (render_bits(&scene), render_bits(&twin));
    assert!(a.iter().any(|&v| v != 0), "the image is not black");
    assert_eq!(a, b, "byte-identical images");
}
