//! Our binned-SAH BVH against the `obvhs` crate (a compressed-wide BVH with SIMD traversal), on a
//! scene's triangles: build time, closest-hit camera rays and any-hit shadow rays per second on
//! one thread, and agreement of the answers.
//!
//!     cargo run --release -p host-std --example bvh_compare -- [SCENE] [--width W]
//!
//! Spheres are left out (obvhs builds over triangles); rectangles count as two triangles.
use host_std::scene::{Object, Scene, Shape};
use host_std::trace::bvh::Bvh;
use host_std::trace::camera::Camera;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use sampler_core::glam::{Vec3, Vec3A};
use std::time::{Duration, Instant};

fn triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for o in &scene.objects {
        match &o.shape {
            Shape::Mesh { positions, triangles, .. } => {
                out.extend(triangles.iter().map(|t| t.map(|i| positions[i as usize])));
            }
            Shape::Rectangle { p0, e1, e2 } => {
                out.push([*p0, *p0 + *e1, *p0 + *e1 + *e2]);
                out.push([*p0, *p0 + *e1 + *e2, *p0 + *e2]);
            }
            Shape::Sphere { .. } => {}
            Shape::Instance { set, instance, group } => {
                if let Shape::Mesh { positions, triangles, .. } = set.0.mesh(*instance, *group) {
                    out.extend(triangles.iter().map(|t| t.map(|i| positions[i as usize])));
                }
            }
        }
    }
    out.retain(|[a, b, c]| (*b - *a).cross(*c - *a).length_squared() > 0.0);
    out
}

/// Rays through every pixel centre.
fn camera_rays(camera: &Camera) -> Vec<(Vec3, Vec3)> {
    let mut cam = Vec::new();
    for y in 0..camera.height {
        for x in 0..camera.width {
            cam.push((camera.origin, camera.direction(x as f32 + 0.5, y as f32 + 0.5)));
        }
    }
    cam
}

/// Shadow rays from each camera ray's hit towards a fixed set of directions over the sphere.
fn shadow_rays(cam: &[(Vec3, Vec3)], hits: &[Option<f32>]) -> Vec<(Vec3, Vec3)> {
    let dirs: Vec<Vec3> = (0..16)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / 16.0;
            let phi = k as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            Vec3::new(r * phi.cos(), z, r * phi.sin())
        })
        .collect();
    // Four of the sixteen directions per hit, rotating with the pixel.
    let mut shadow = Vec::new();
    for (i, ((o, d), t)) in cam.iter().zip(hits).enumerate() {
        if let Some(t) = t {
            let p = *o + *d * *t;
            let eps = 1e-4 * (1.0 + p.abs().max_element());
            for k in 0..4 {
                let w = dirs[(i + 4 * k) % dirs.len()];
                shadow.push((p + w * eps, w));
            }
        }
    }
    shadow
}

/// obvhs's closest hit along each ray.
fn obvhs_closest(bvh: &obvhs::cwbvh::CwBvh, tris: &[Triangle], rays: &[(Vec3, Vec3)]) -> Vec<Option<f32>> {
    rays.iter()
        .map(|&(o, d)| {
            let mut hit = RayHit::none();
            let ray = Ray::new_inf(o.into(), d.into());
            bvh.ray_traverse(ray, &mut hit, |r, id| tris[bvh.primitive_indices[id] as usize].intersect(r))
                .then_some(hit.t)
        })
        .collect()
}

/// How many of the rays obvhs finds occluded.
fn obvhs_occluded(bvh: &obvhs::cwbvh::CwBvh, tris: &[Triangle], rays: &[(Vec3, Vec3)]) -> usize {
    rays.iter()
        .filter(|&&(o, d)| {
            !bvh.ray_traverse_miss(Ray::new_inf(o.into(), d.into()), |r, id| {
                tris[bvh.primitive_indices[id] as usize].intersect(r)
            })
        })
        .count()
}

/// How many closest hits agree (both miss, or hit at the same distance within 1e-4 relative).
fn agreeing(ours: &[Option<f32>], theirs: &[Option<f32>]) -> usize {
    ours.iter()
        .zip(theirs)
        .filter(|(a, b)| match (a, b) {
            (Some(a), Some(b)) => (a - b).abs() <= 1e-4 * a.max(1.0),
            (None, None) => true,
            _ => false,
        })
        .count()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let width: u32 = args.iter().position(|a| a == "--width").map_or(512, |i| args[i + 1].parse().unwrap());
    let path = args.iter().find(|a| !a.starts_with("--") && a.parse::<u32>().is_err());
    let mut scene = match path {
        None => host_std::scene::builtin::scene(),
        Some(p) if p.ends_with(".json") => host_std::scene::json::load(p.as_ref()).unwrap(),
        #[cfg(feature = "usd")]
        Some(p) => host_std::scene::usd::load(p.as_ref(), &Default::default()).unwrap().scene,
        #[cfg(not(feature = "usd"))]
        Some(p) => panic!("{p}: USD scenes need the `usd` feature"),
    };
    let tris = triangles(&scene);
    let aspect = scene.camera.width as f32 / scene.camera.height as f32;
    scene.camera.width = width;
    scene.camera.height = (width as f32 / aspect).round() as u32;
    // Our BVH over the same triangles only.
    let mesh = Shape::Mesh {
        positions: tris.iter().flatten().copied().collect(),
        triangles: (0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
        normals: Box::new([]),
        uvs: Box::new([]),
    };
    let tri_scene = Scene { objects: vec![Object { shape: mesh, material: 0 }], ..scene.clone() };

    let t0 = Instant::now();
    let ours = Bvh::build(&tri_scene);
    let ours_build = t0.elapsed();
    let theirs_tris: Vec<Triangle> = tris
        .iter()
        .map(|[a, b, c]| Triangle { v0: Vec3A::from(*a), v1: Vec3A::from(*b), v2: Vec3A::from(*c) })
        .collect();
    let t0 = Instant::now();
    let theirs = obvhs::cwbvh::builder::build_cwbvh_from_tris(
        &theirs_tris,
        obvhs::BvhBuildParams::medium_build(),
        &mut Duration::default(),
    );
    let theirs_build = t0.elapsed();

    // Camera rays through pixel centres; shadow rays from each hit towards a fixed set of
    // directions over the sphere.
    let cam = camera_rays(&Camera::new(&scene.camera));
    let t0 = Instant::now();
    let ours_hits: Vec<Option<f32>> =
        cam.iter().map(|&(o, d)| ours.intersect(o, d, 0.0, f32::INFINITY).map(|h| h.t)).collect();
    let ours_cam = t0.elapsed();
    let t0 = Instant::now();
    let theirs_hits = obvhs_closest(&theirs, &theirs_tris, &cam);
    let theirs_cam = t0.elapsed();
    let agree = agreeing(&ours_hits, &theirs_hits);

    let shadow = shadow_rays(&cam, &ours_hits);
    let t0 = Instant::now();
    let ours_occ = shadow.iter().filter(|&&(o, d)| ours.occluded(o, d, 0.0, f32::INFINITY)).count();
    let ours_shadow = t0.elapsed();
    let t0 = Instant::now();
    let theirs_occ = obvhs_occluded(&theirs, &theirs_tris, &shadow);
    let theirs_shadow = t0.elapsed();

    let mrays = |n: usize, t: Duration| n as f64 / t.as_secs_f64() / 1e6;
    println!("{} triangles, {} camera rays, {} shadow rays (1 thread)", tris.len(), cam.len(), shadow.len());
    println!(
        "ours : build {:8.2} ms  closest {:6.2} M rays/s  any-hit {:6.2} M rays/s",
        ours_build.as_secs_f64() * 1e3,
        mrays(cam.len(), ours_cam),
        mrays(shadow.len(), ours_shadow)
    );
    println!(
        "obvhs: build {:8.2} ms  closest {:6.2} M rays/s  any-hit {:6.2} M rays/s",
        theirs_build.as_secs_f64() * 1e3,
        mrays(cam.len(), theirs_cam),
        mrays(shadow.len(), theirs_shadow)
    );
    println!(
        "agreement: closest hits {:.4}%, occluded {} vs {}",
        100.0 * agree as f64 / cam.len() as f64,
        ours_occ,
        theirs_occ
    );
}
