//! The measurements behind the light samplers' choices (docs/tuning.md, "Light samplers"):
//! 1. triangles — per-sample relative variance of the irradiance on a diffuse receiver with
//!    area sampling and with spherical-triangle sampling, by decade of the solid angle the
//!    triangle subtends (random triangles, receivers and normals);
//! 2. rectangles — the relative error of the solid angle 1/pdf implies (f64 spherical rectangle,
//!    or area sampling below its smallest solid angle) against Van Oosterom & Strackee's
//!    formula, face-on and edge-on, by distance.
//!
//! `cargo run --release -p sampler-core --example light_samplers` prints both tables;
//! `… -- cost area|solid|rect` draws 200 000 samples of one sampler only, for
//! `valgrind --tool=callgrind` (instructions per sample = the sampler's inclusive count / 200 000).
use glam::{DVec3, Vec2, Vec3};
use sampler_core::light::{Light, RectLight, TriangleLight, TriangleSampling};
use sampler_core::rng::Pcg32;

const SAMPLES: usize = 4096;
const CONFIGS: usize = 3000;

fn random_dir(rng: &mut Pcg32) -> Vec3 {
    sampler_core::mapping::square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()))
}

/// A random triangle of unit size near the origin, a receiver at log-uniform distance
/// 0.02–300 and a normal in the hemisphere facing the triangle.
fn config(rng: &mut Pcg32) -> ([Vec3; 3], Vec3, Vec3) {
    let v = [random_dir(rng), random_dir(rng), random_dir(rng)];
    let centre = (v[0] + v[1] + v[2]) / 3.0;
    let front = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    // In front of the triangle, at a distance log-uniform over four decades.
    let d = 0.02 * 15_000f32.powf(rng.next_f32());
    let mut off = random_dir(rng);
    if off.dot(front) < 0.0 {
        off = -off;
    }
    let p = centre + off * d;
    let mut n = random_dir(rng);
    if n.dot(centre - p) < 0.0 {
        n = -n;
    }
    (v, p, n)
}

/// (mean, per-sample variance) of the irradiance estimate L cos / pdf.
fn moments(light: &TriangleLight, p: Vec3, n: Vec3, rng: &mut Pcg32) -> (f64, f64) {
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..SAMPLES {
        let v = light
            .sample(p, Vec2::new(rng.next_f32(), rng.next_f32()))
            .map_or(0.0, |s| (n.dot(s.dir).max(0.0) / s.pdf) as f64);
        s1 += v;
        s2 += v * v;
    }
    let mean = s1 / SAMPLES as f64;
    (mean, (s2 / SAMPLES as f64 - mean * mean).max(0.0))
}

fn solid_angle(o: Vec3, v: &[Vec3]) -> f64 {
    let [a, b, c] = [v[0], v[1], v[2]].map(|p| (p - o).as_dvec3().normalize());
    2.0 * a.dot(b.cross(c)).abs().atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
}

fn triangles() {
    let mut rng = Pcg32::new(12, 1);
    // Per decade of solid angle: (relative variance by area, by solid angle) per configuration.
    let mut decades: Vec<Vec<(f64, f64)>> = vec![Vec::new(); 8];
    for _ in 0..CONFIGS {
        let (v, p, n) = config(&mut rng);
        let omega = solid_angle(p, &v);
        let Ok(light) = TriangleLight::new(v, Vec3::ONE) else { continue };
        let solid = light.with_sampling(TriangleSampling::SolidAngle { min_solid_angle: 1e-8 });
        let area = light.with_sampling(TriangleSampling::Area);
        let (m_s, v_s) = moments(&solid, p, n, &mut rng);
        let (m_a, v_a) = moments(&area, p, n, &mut rng);
        if m_s <= 0.0 || m_a <= 0.0 || v_s <= 0.0 {
            continue;
        }
        let k = ((omega.log10() + 6.0).floor() as i64).clamp(0, 7) as usize;
        decades[k].push((v_a / (m_a * m_a), v_s / (m_s * m_s)));
    }
    println!("per-sample relative variance of the irradiance: mean over configurations (area | solid angle),");
    println!("and the median and 90th percentile of their ratio");
    println!("solid angle (sr)     configs   mean area   mean solid   ratio median   ratio p90");
    for (k, r) in decades.iter().enumerate() {
        if r.is_empty() {
            continue;
        }
        let mean = |f: fn(&(f64, f64)) -> f64| r.iter().map(f).sum::<f64>() / r.len() as f64;
        let mut ratio: Vec<f64> = r.iter().map(|(a, s)| a / s).collect();
        ratio.sort_by(f64::total_cmp);
        let q = |f: f64| ratio[((ratio.len() - 1) as f64 * f) as usize];
        let lo = 10f64.powi(k as i32 - 6);
        println!(
            "[{lo:.0e}, {:.0e})   {:5}   {:9.2e}   {:9.2e}   {:8.2}   {:8.2}",
            lo * 10.0,
            r.len(),
            mean(|x| x.0),
            mean(|x| x.1),
            q(0.5),
            q(0.9)
        );
    }
}

fn rect_solid_angle_error() {
    let tri = |a: DVec3, b: DVec3, c: DVec3| {
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        2.0 * a.dot(b.cross(c)).abs().atan2(la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la)
    };
    let light = RectLight::new(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE).unwrap().with_two_sided(true);
    println!("\nunit square: distance, view, solid angle (sr), sampler, relative error of 1/pdf at the centre");
    for e in 0..=6 {
        let d = 10f32.powi(e);
        for (view, p) in [("oblique", Vec3::new(0.5 + 0.3 * d, 0.5, d)), ("edge-on", Vec3::new(0.5 + d, 0.5, 1e-2))] {
            let c = |x: f64, y: f64| DVec3::new(x, y, 0.0) - p.as_dvec3();
            let exact = tri(c(0.0, 0.0), c(1.0, 0.0), c(1.0, 1.0)) + tri(c(0.0, 0.0), c(1.0, 1.0), c(0.0, 1.0));
            let s = light.sample(p, Vec2::splat(0.5)).map_or(f64::NAN, |s| 1.0 / s.pdf as f64);
            // The rectangle's threshold between the two samplers (`spherical_rect::MIN_SOLID_ANGLE`).
            let sampler = if exact >= 1e-8 { "spherical" } else { "area" };
            println!("{d:8.0e}  {view}  {exact:10.3e}  {sampler:9}  {:10.2e}", (s - exact).abs() / exact);
        }
    }
}

fn cost(which: &str) {
    let v = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)];
    let p = Vec3::new(0.3, 0.2, 0.0);
    let tri = TriangleLight::new(v, Vec3::ONE).unwrap().with_two_sided(true);
    let rect = RectLight::new(Vec3::new(0.0, 0.0, 1.0), Vec3::X, Vec3::Y, Vec3::ONE).unwrap().with_two_sided(true);
    let solid = tri.with_sampling(TriangleSampling::SolidAngle { min_solid_angle: 1e-8 });
    let area = tri.with_sampling(TriangleSampling::Area);
    let light: &dyn Light = match which {
        "area" => &area,
        "solid" => &solid,
        _ => &rect,
    };
    let mut rng = Pcg32::new(1, 1);
    let mut sink = 0.0;
    for _ in 0..200_000 {
        sink += light.sample(p, Vec2::new(rng.next_f32(), rng.next_f32())).map_or(0.0, |s| s.pdf);
    }
    println!("{which}: {sink}");
}

fn main() {
    match std::env::args().nth(2) {
        Some(which) => cost(&which),
        None => {
            triangles();
            rect_solid_angle_error();
        }
    }
}
