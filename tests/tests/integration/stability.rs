//! End-to-end stability on extreme inputs: every method renders without
//! panic and without a non-finite value, and where the answer is analytic it is met.

use crate::common::{env_from, materials, sphere_scene};
use glam::Vec3;
use host_std::light::environment::Environment;
use host_std::plan::Method;
use host_std::plan::{Rendered, Settings, render};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::{Bsdf, CameraSpec, Material, Object, Scene, Shape};
use host_std::trace::bvh::Bvh;
use sampler_core::brdf::Lambert;

fn run(scene: &Scene, env: &Environment, method: Method, spp: usize, brdf_samples: usize) -> Rendered {
    let bvh = Bvh::build(scene);
    let h = env.hierarchy();
    let settings = Settings {
        method,
        spp,
        shading_points: 2,
        brdf_samples: BrdfSamples::Fixed(brdf_samples),
        seed: 3,
        progress: false,
        shadows: true,
        lights: Default::default(),
    };
    render(scene, &bvh, Some(&h), &settings)
}

fn all_finite(r: &Rendered) -> bool {
    r.non_finite == 0 && r.pixels.iter().all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0))
}

#[test]
fn a_black_map_renders_exactly_zero() {
    let env = env_from("black", 16, |_, _| [0.0; 3]);
    for (name, bsdf) in materials() {
        let scene = sphere_scene(bsdf, Vec3::Z);
        for method in Method::ALL {
            let r = run(&scene, &env, method, 4, 256);
            assert!(r.pixels.iter().all(|p| *p == [0.0; 3]), "{name} / {method}: not exactly black");
            assert_eq!(r.shadow_rays, 0, "{name} / {method}: traced shadow rays under a black sky");
        }
    }
}

#[test]
fn a_constant_1e30_map_neither_overflows_nor_loses_scale() {
    // White furnace at 1e30: a Lambert sphere of albedo 1 converges to L exactly; with a
    // constant map env sampling is exact per sample, so every method lands within noise.
    let big = 1e30f32;
    let env = env_from("huge", 8, |_, _| [big; 3]);
    let scene = sphere_scene(Bsdf::Diffuse(Lambert::new(Vec3::ONE)), Vec3::new(0.3, 0.5, 0.8).normalize());
    for method in Method::ALL {
        let r = run(&scene, &env, method, 64, 64);
        assert!(all_finite(&r), "{method}: non-finite pixels at 1e30");
        let mean = r.pixels.iter().map(|p| p[1] as f64).sum::<f64>() / r.pixels.len() as f64;
        assert!((mean / big as f64 - 1.0).abs() < 0.05, "{method}: furnace at 1e30 gave {mean:e}");
    }
    // Every material stays finite too.
    for (name, bsdf) in materials() {
        let scene = sphere_scene(bsdf, Vec3::X);
        for method in Method::ALL {
            assert!(all_finite(&run(&scene, &env, method, 4, 64)), "{name} / {method}");
        }
    }
}

#[test]
fn nan_inf_and_negative_texels_are_sanitized_and_never_reach_the_image() {
    let env = env_from("poisoned", 32, |x, y| match (x + 7 * y) % 5 {
        0 => [f32::NAN, 1.0, 1.0],
        1 => [f32::INFINITY, 0.5, 0.5],
        2 => [-3.0, 0.2, 0.2],
        _ => [0.5, 0.6, 0.7],
    });
    assert!(env.stats.sanitized > 0);
    assert!(env.pyramid.iter().all(|v| v.is_finite() && *v >= 0.0));
    for (name, bsdf) in materials() {
        let scene = sphere_scene(bsdf, Vec3::NEG_Y);
        for method in Method::ALL {
            assert!(all_finite(&run(&scene, &env, method, 4, 64)), "{name} / {method}");
        }
    }
}

#[test]
fn tiny_maps_and_suns_on_the_mappings_special_points_stay_finite() {
    let n = 64;
    // A 1e7× sun on the +z pole (centre), the −z pole (a corner), a seam point (edge middle)
    // and a diamond vertex (the equator on the u axis).
    let spots = [(n / 2, n / 2), (0, 0), (n - 1, n - 1), (0, n / 2), (n / 2, 0), (n - 1, n / 2)];
    let mut envs: Vec<(String, Environment)> = spots
        .iter()
        .map(|&(sx, sy)| {
            let e = env_from(
                &format!("sun-{sx}-{sy}"),
                n,
                move |x, y| if (x, y) == (sx, sy) { [1e7; 3] } else { [1.0, 0.9, 0.8] },
            );
            (format!("sun at texel ({sx}, {sy})"), e)
        })
        .collect();
    envs.push(("1×1".into(), env_from("one", 1, |_, _| [2.0, 1.0, 0.5])));
    envs.push(("2×2".into(), env_from("two", 2, |x, y| [(1 + x + 2 * y) as f32; 3])));
    let views = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
    for (label, env) in &envs {
        for (name, bsdf) in materials() {
            for (k, v) in views.iter().enumerate() {
                let scene = sphere_scene(bsdf.clone(), *v);
                for method in Method::ALL {
                    let r = run(&scene, env, method, 2, if k % 2 == 0 { 1 } else { 256 });
                    assert!(all_finite(&r), "{label} / {name} / view {v} / {method}");
                }
            }
        }
    }
}

#[test]
fn back_faces_grazing_views_and_degenerate_triangles() {
    let env = env_from("sky", 32, |_, y| [0.5 + y as f32 / 32.0, 0.7, 1.0]);
    // A triangle mesh with degenerate triangles (repeated and collinear vertices), a one-sided
    // quad seen from the back, and a quad seen at grazing angles.
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 0.0),
    ];
    let triangles = vec![[0, 1, 2], [0, 2, 3], [0, 0, 1], [0, 4, 2], [1, 1, 1]];
    for (name, bsdf) in materials() {
        for (label, origin) in [
            ("front", Vec3::new(0.0, 0.0, 4.0)),
            ("back", Vec3::new(0.0, 0.0, -4.0)),
            ("grazing", Vec3::new(0.0, -4.0, 1e-3)),
        ] {
            let scene = Scene {
                name: label.into(),
                camera: CameraSpec {
                    origin,
                    target: Vec3::ZERO,
                    up: Vec3::X,
                    fov_y_deg: 40.0,
                    width: 8,
                    height: 8,
                    pixel_aspect: 1.0,
                    near_clip: 1e-3,
                },
                objects: vec![Object {
                    shape: Shape::Mesh {
                        positions: positions.clone().into(),
                        triangles: triangles.clone().into(),
                        normals: Box::new([]),
                        uvs: Box::new([]),
                    },
                    material: 0,
                }],
                materials: vec![Material::new(bsdf.clone(), false)],
                env: None,
                lights: Vec::new(),
                hide_emitters: true,
            };
            for method in Method::ALL {
                let r = run(&scene, &env, method, 2, 64);
                assert!(all_finite(&r), "{name} / {label} / {method}");
                if label == "back" {
                    assert!(
                        r.pixels.iter().all(|p| *p == [0.0; 3]),
                        "{name} / {method}: a one-sided back face reflected light"
                    );
                }
            }
        }
    }
}

#[test]
fn views_down_to_n_dot_v_1e_6_shade_finite_values() {
    // A long floor seen from just above it through a very narrow lens: every primary ray meets
    // it at n·v = 1e-3 or 1e-6 (± 1e-6; camera 4e-3 or 4e-6 above the plane, 4 away).
    let env = env_from("sky+sun", 64, |x, y| if (x, y) == (40, 20) { [1e6; 3] } else { [0.3, 0.5, 1.0] });
    for (name, bsdf) in materials() {
        for height in [4e-3f32, 4e-6] {
            let scene = Scene {
                name: "floor".into(),
                camera: CameraSpec {
                    origin: Vec3::new(0.0, -4.0, height),
                    target: Vec3::ZERO,
                    up: Vec3::Z,
                    fov_y_deg: 1e-4,
                    width: 5,
                    height: 5,
                    pixel_aspect: 1.0,
                    near_clip: 1e-6,
                },
                objects: vec![Object {
                    shape: Shape::Rectangle {
                        p0: Vec3::new(-50.0, -3.99, 0.0),
                        e1: Vec3::new(100.0, 0.0, 0.0),
                        e2: Vec3::new(0.0, 1000.0, 0.0),
                    },
                    material: 0,
                }],
                materials: vec![Material::new(bsdf.clone(), false)],
                env: None,
                lights: Vec::new(),
                hide_emitters: true,
            };
            for method in Method::ALL {
                let r = run(&scene, &env, method, 4, 64);
                assert_eq!(r.shading_points, r.camera_rays, "{name} / {height} / {method}: a ray missed the floor");
                assert!(all_finite(&r), "{name} / n·v {} / {method}", height / 4.0);
            }
        }
    }
}
