//! A crop of the frame (`ppis render --crop`) holds bit for bit the whole frame's pixels there,
//! for every method and at 1 and 2 threads — crops that cut through the 16×16 render tiles,
//! whose pixels depend on the tile's earlier pixels through the product-MIS samplers they keep —
//! and `auto`'s pilot decides from the whole frame whichever crop is rendered.

use crate::common;
use host_std::light::environment::Environment;
use host_std::plan::{Method, Rendered, Settings, render, render_crop};
use host_std::render::crop::Crop;
use host_std::scene::{Bsdf, builtin};
use host_std::trace::bvh::Bvh;
use sampler_core::brdf::RoughConductor;
use sampler_core::glam::Vec3;

fn settings(method: Method, spp: usize, shading_points: usize) -> Settings {
    common::settings(method, spp, shading_points, 5)
}

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

/// The crop's pixels cut out of the whole frame.
fn cut(whole: &Rendered, crop: Crop) -> Vec<[u32; 3]> {
    (crop.y0..crop.y1)
        .flat_map(|y| (crop.x0..crop.x1).map(move |x| (x, y)))
        .map(|(x, y)| whole.pixels[y * whole.width + x].map(f32::to_bits))
        .collect()
}

fn bits(image: &Rendered) -> Vec<[u32; 3]> {
    image.pixels.iter().map(|p| p.map(f32::to_bits)).collect()
}

#[test]
fn every_method_renders_a_crop_bit_for_bit_as_the_whole_frame() {
    let mut scene = builtin::scene();
    scene.camera.width = 64;
    scene.camera.height = 48;
    let (source, placement) = scene.env.clone().unwrap();
    let sky = Environment::build(&source, placement).unwrap();
    let h = sky.hierarchy();
    let bvh = Bvh::build(&scene);
    // Through tiles' middles, a single pixel, the last pixel, a column, the frame's corner tile.
    let crops = ["5,3,37,29", "40,17,64,48", "21,30,22,31", "63,47,64,48", "17,0,18,48", "0,0,16,16"];
    let crops: Vec<Crop> = crops.iter().map(|c| Crop::parse(c).unwrap().check(64, 48).unwrap()).collect();
    for method in Method::ALL {
        let s = settings(method, 4, 2);
        let whole = on_threads(2, || render(&scene, &bvh, Some(&h), &s));
        assert_eq!(whole.crop, Crop::full(64, 48));
        for (i, &crop) in crops.iter().enumerate() {
            let threads = 1 + i % 2;
            let part = on_threads(threads, || render_crop(&scene, &bvh, Some(&h), &s, crop));
            assert_eq!((part.crop, part.width, part.height), (crop, crop.width(), crop.height()));
            assert!(bits(&part) == cut(&whole, crop), "{method}, crop {crop}, {threads} threads");
        }
    }
}

#[test]
fn autos_pilot_decides_from_the_whole_frame_whatever_the_crop() {
    // A glossy sphere filling a 96×96 view under the sky: large enough for the pilot to run.
    let scene = common::pilot_sphere(Bsdf::Conductor(RoughConductor::new(0.1, Vec3::ONE)));
    let sky =
        Environment::build(&host_std::light::environment::EnvSource::Sky { level: 7 }, Default::default()).unwrap();
    let h = sky.hierarchy();
    let bvh = Bvh::build(&scene);
    let s = settings(Method::Auto, 16, 1);
    let whole = on_threads(2, || render(&scene, &bvh, Some(&h), &s));
    assert_eq!(whole.pilot.len(), 1, "the pilot ran");
    // A corner off the sphere (no pixel of the material) and a strip through it.
    for (crop, threads) in [("0,0,20,20", 1), ("30,41,70,60", 2)] {
        let crop = Crop::parse(crop).unwrap();
        let part = on_threads(threads, || render_crop(&scene, &bvh, Some(&h), &s, crop));
        assert_eq!(format!("{:?}", part.pilot), format!("{:?}", whole.pilot), "crop {crop}: the same pilot");
        assert!(bits(&part) == cut(&whole, crop), "crop {crop}");
    }
}
