//! Equal-area mapping: round trips, equal areas, continuity across the square's edges, and the
//! batched form against the scalar one.

use glam::{Vec2, Vec3};
use proptest::prelude::*;
use sampler_core::mapping::*;

const SPECIAL: [f32; 9] = [0.0, -0.0, 1.0, -1.0, 1e-30, -1e-30, 0.5, -0.5, 1e-7];

fn direction() -> impl Strategy<Value = Vec3> {
    let coord = prop_oneof![3 => -1.0f32..1.0, 1 => proptest::sample::select(SPECIAL.to_vec())];
    (coord.clone(), coord.clone(), coord, prop_oneof![Just(1.0f32), Just(1e-20), Just(1e20), 0.01f32..100.0])
        .prop_filter("non-zero", |(x, y, z, _)| x * x + y * y + z * z > 1e-20)
        .prop_map(|(x, y, z, s)| Vec3::new(x, y, z) * s)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20_000))]

    #[test]
    fn sphere_square_sphere_round_trip(d in direction()) {
        let uv = sphere_to_square(d);
        prop_assert!((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y), "{d:?} -> {uv:?}");
        let back = square_to_sphere(uv);
        prop_assert!((back.length() - 1.0).abs() < 1e-6);
        let n = (d.as_dvec3().normalize()).as_vec3();
        let err = angle_between(back, n);
        prop_assert!(err <= 1e-5, "{d:?} -> {uv:?} -> {back:?}: {err} rad");
    }

    #[test]
    fn batched_is_bit_identical(ds in proptest::collection::vec(direction(), 1..13),
                                uvs in proptest::collection::vec((0.0f32..=1.0, 0.0f32..=1.0), 1..13)) {
        let mut out = vec![Vec2::ZERO; ds.len()];
        sphere_to_square_batch(&ds, &mut out);
        for (d, o) in ds.iter().zip(&out) {
            let s = sphere_to_square(*d);
            prop_assert_eq!(s.x.to_bits(), o.x.to_bits());
            prop_assert_eq!(s.y.to_bits(), o.y.to_bits());
        }
        let pts: Vec<Vec2> = uvs.iter().map(|&(u, v)| Vec2::new(u, v)).collect();
        let mut dirs = vec![Vec3::ZERO; pts.len()];
        square_to_sphere_batch(&pts, &mut dirs);
        for (p, o) in pts.iter().zip(&dirs) {
            let s = square_to_sphere(*p);
            prop_assert_eq!([s.x.to_bits(), s.y.to_bits(), s.z.to_bits()], [o.x.to_bits(), o.y.to_bits(), o.z.to_bits()]);
        }
    }

    #[test]
    fn stepping_across_an_edge_is_continuous(v in 0.0f32..1.0, side in 0usize..4, delta in 1e-4f32..1e-2) {
        // A point just inside an edge and the wrap of its mirror just outside: both must be
        // close to the edge point on the sphere.
        let (edge, inside, outside) = match side {
            0 => (Vec2::new(0.0, v), Vec2::new(delta, v), Vec2::new(-delta, v)),
            1 => (Vec2::new(1.0, v), Vec2::new(1.0 - delta, v), Vec2::new(1.0 + delta, v)),
            2 => (Vec2::new(v, 0.0), Vec2::new(v, delta), Vec2::new(v, -delta)),
            _ => (Vec2::new(v, 1.0), Vec2::new(v, 1.0 - delta), Vec2::new(v, 1.0 + delta)),
        };
        let wrapped = wrap_square(outside);
        prop_assert!((0.0..=1.0).contains(&wrapped.x) && (0.0..=1.0).contains(&wrapped.y));
        let e = square_to_sphere(edge);
        let a = angle_between(square_to_sphere(inside), e);
        let b = angle_between(square_to_sphere(wrapped), e);
        // The map stretches by at most ~π along the edges: both within a few δ of the edge point,
        // and on opposite sides of it (their distance is about the sum).
        prop_assert!(a < 8.0 * delta && b < 8.0 * delta, "{a} {b} (δ {delta})");
        // Away from the diamond's vertices (v = ½, where the edge touches the equator and the
        // map folds), the two points lie on opposite sides of the edge point.
        if (v - 0.5).abs() > 4.0 * delta {
            let ab = angle_between(square_to_sphere(inside), square_to_sphere(wrapped));
            prop_assert!(ab > 0.5 * (a + b), "same side: {ab} vs {a}+{b}");
        }
    }
}

/// Solid angle of the spherical triangle (a, b, c) (Van Oosterom & Strackee).
fn triangle_solid_angle(a: glam::DVec3, b: glam::DVec3, c: glam::DVec3) -> f64 {
    2.0 * a.dot(b.cross(c)).atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
}

#[test]
fn every_grid_cell_has_equal_solid_angle() {
    let m = 48; // points per cell side along its boundary
    for k in 1..=5u32 {
        let n = 1usize << k;
        let want = 4.0 * std::f64::consts::PI / (n * n) as f64;
        let mut total = 0.0;
        let mut worst: f64 = 0.0;
        for j in 0..n {
            for i in 0..n {
                let at = |s: f64, t: f64| {
                    // A hair inside the cell, so that edge points map through this cell.
                    let u = (i as f64 + s.clamp(1e-6, 1.0 - 1e-6)) / n as f64;
                    let v = (j as f64 + t.clamp(1e-6, 1.0 - 1e-6)) / n as f64;
                    square_to_sphere(Vec2::new(u as f32, v as f32)).as_dvec3().normalize()
                };
                let centre = at(0.5, 0.5);
                let mut boundary = Vec::with_capacity(4 * m);
                for q in 0..m {
                    boundary.push(at(q as f64 / m as f64, 0.0));
                }
                for q in 0..m {
                    boundary.push(at(1.0, q as f64 / m as f64));
                }
                for q in 0..m {
                    boundary.push(at(1.0 - q as f64 / m as f64, 1.0));
                }
                for q in 0..m {
                    boundary.push(at(0.0, 1.0 - q as f64 / m as f64));
                }
                let mut area = 0.0;
                for q in 0..boundary.len() {
                    let (a, b) = (boundary[q], boundary[(q + 1) % boundary.len()]);
                    area += triangle_solid_angle(centre, a, b);
                }
                total += area;
                worst = worst.max((area / want - 1.0).abs());
            }
        }
        assert!(worst < 2e-3, "level {k}: cell solid angle off by {worst}");
        assert!((total / (4.0 * std::f64::consts::PI) - 1.0).abs() < 1e-4, "level {k}: total {total}");
    }
}

#[test]
fn texel_wrap_lands_next_door_on_the_sphere() {
    let n = 16u32;
    let centre = |i: u32, j: u32| square_to_sphere(Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32));
    let texel_angle = (4.0 * std::f32::consts::PI / (n * n) as f32).sqrt();
    for j in 0..n as i32 {
        for (i, inside) in [(-1, 0), (n as i32, n as i32 - 1)] {
            let (wi, wj) = wrap_texel(i, j, n);
            let d = angle_between(centre(wi, wj), centre(inside as u32, j as u32));
            assert!(d < 3.0 * texel_angle, "texel ({i},{j}) -> ({wi},{wj}): {d}");
            let (wi, wj) = wrap_texel(j, i, n);
            let d = angle_between(centre(wi, wj), centre(j as u32, inside as u32));
            assert!(d < 3.0 * texel_angle, "texel ({j},{i}) -> ({wi},{wj}): {d}");
        }
    }
}
