//! What a light tree's pick and pmf cost as the number of lights grows (docs/perf.md, "Many
//! lights"): N small one-sided triangles with random normals scattered over a 10 × 2 × 10 slab
//! above a floor, shading points on the floor; per N, the tree's size, the CPU time of its build
//! per light, the mean depth of a pick and the CPU time of one pick plus the pmf of the light
//! picked (what a shading point spends on light selection with MIS). Logarithmic growth shows as
//! a constant cost per level.
//!
//! `cargo run --release -p sampler-core --example light_tree_cost [-- N...]`
use glam::{Vec2, Vec3};
use sampler_core::light::{LightBounds, LightNode, LightTree, SceneLight, TriangleLight};
use sampler_core::rng::Pcg32;

const QUERIES: usize = 1 << 20;

fn lights(n: usize, rng: &mut Pcg32) -> Vec<SceneLight> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(10.0 * rng.next_f32() - 5.0, 1.0 + 2.0 * rng.next_f32(), 10.0 * rng.next_f32() - 5.0);
            let mut d = || sampler_core::mapping::square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            let (a, b) = (d(), d());
            let v = [c, c + 0.05 * a, c + 0.05 * b];
            let light = TriangleLight::new(v, Vec3::splat(1.0 + 9.0 * rng.next_f32()));
            light
                .unwrap_or_else(|_| TriangleLight::new([c, c + 0.05 * Vec3::X, c + 0.05 * Vec3::Z], Vec3::ONE).unwrap())
        })
        .map(SceneLight::from)
        .collect()
}

fn main() {
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let sizes = if sizes.is_empty() { vec![10, 100, 1_000, 10_000, 100_000, 1_000_000] } else { sizes };
    println!(
        "| lights | nodes | bytes per node | build, ns per light | mean depth | ns per pick + pmf | ns per level |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for n in sizes {
        let mut rng = Pcg32::new(n as u64, 7);
        let lights = lights(n, &mut rng);
        let bounds: Vec<Option<LightBounds>> = lights.iter().map(LightBounds::of).collect();
        let mut order = vec![0u32; n];
        let mut nodes = vec![LightNode { bounds: bounds[0].unwrap(), index: 0, leaf: true }; 2 * n];
        let mut paths = vec![0u64; n];
        let start = cpu_seconds();
        let tree = LightTree::build(&bounds, &mut order, &mut nodes, &mut paths).unwrap();
        let build_ns = (cpu_seconds() - start) * 1e9 / n as f64;
        let queries: Vec<(Vec3, f64)> = (0..QUERIES)
            .map(|_| (Vec3::new(12.0 * rng.next_f32() - 6.0, 0.0, 12.0 * rng.next_f32() - 6.0), rng.next_f64()))
            .collect();
        let depths = leaf_depths(tree.nodes(), n);
        let start = cpu_seconds();
        let mut sum = 0.0f64;
        for &(p, u) in &queries {
            if let Some(s) = tree.pick(u, p, Vec3::Y) {
                sum += tree.pmf(s.index, p, Vec3::Y);
            }
        }
        let seconds = cpu_seconds() - start;
        let picked = queries.iter().filter_map(|&(p, u)| tree.pick(u, p, Vec3::Y));
        let mean_depth = picked.map(|s| depths[s.index] as f64).sum::<f64>() / QUERIES as f64;
        let ns = seconds * 1e9 / QUERIES as f64;
        println!(
            "| {n} | {} | {} | {build_ns:.0} | {mean_depth:.1} | {ns:.0} | {:.1} |",
            tree.nodes().len(),
            size_of::<LightNode>(),
            ns / mean_depth.max(1.0)
        );
        std::hint::black_box(sum);
    }
}

/// This thread's CPU time (the machine is shared: time spent waiting for a core is not the
/// tree's cost), from the scheduler's own count in nanoseconds.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux's /proc/thread-self/schedstat");
    stat.split_whitespace().next().and_then(|t| t.parse::<f64>().ok()).expect("a CPU time in ns") * 1e-9
}

/// Each light's depth in the tree (its leaf's distance from the root).
fn leaf_depths(nodes: &[LightNode], lights: usize) -> Vec<u32> {
    let mut depths = vec![0u32; lights];
    let mut stack = vec![(0usize, 0u32)];
    while let Some((k, d)) = stack.pop() {
        if nodes[k].leaf {
            depths[nodes[k].index as usize] = d;
        } else {
            stack.push((k + 1, d + 1));
            stack.push((nodes[k].index as usize, d + 1));
        }
    }
    depths
}
