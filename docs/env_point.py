#!/usr/bin/env python3
"""Env-only sampling at one point, ours against Mitsuba 3's, on the same points (docs/perf.md,
"What is left against Mitsuba on studio").

  python3 docs/env_point.py --out DIR [--seeds 7,1,2,3,4,5,6,8] [--normals 0,0 20,120 45,60 60,300 90,30 90,250]
                            [--example target/release/examples/env_point]

For each seed, a studio-like map (docs/scenes/make_scenes.py's `studio_map`: seed 7 is
studio.json's own) written to DIR; our env samples from `host-std/examples/env_point.rs`
(`cargo build --release -p host-std --example env_point`: 256 Owen-scrambled (0,2) points per
estimate, 200 scrambles, the points written out) and Mitsuba's (`envmap`, `scalar_rgb`,
`sample_direction`) at the same points. Each estimates a plane's irradiance (RGB averaged) for
each normal (TILT,AZIMUTH in degrees from +y, azimuth from +x towards +z); prints the relative
variance of both, their ratio per map and normal, and the geometric means of the ratios. Both
draw ∝ the map's luminance (Mitsuba without MIS compensation, ours from the plain pyramid); only
the warp from the points to directions differs: our equal-area octahedral square's descent,
Mitsuba's hierarchical warp of the lat-long map.

Needs numpy and mitsuba (docs/reference/README.md)."""
import argparse, math, os, re, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, 'scenes'))


def mitsuba_relvars(mi, np, map_path, points, normals):
    env = mi.load_dict({'type': 'envmap', 'filename': map_path})
    it = mi.Interaction3f()
    it.p, it.t = mi.Point3f(0, 0, 0), 0.0
    dirs, weights = [], []
    for u in points.reshape(-1, 2):
        ds, w = env.sample_direction(it, mi.Point2f(float(u[0]), float(u[1])))
        dirs.append([ds.d.x, ds.d.y, ds.d.z])
        weights.append(np.array(w).mean())
    dirs = np.array(dirs).reshape(points.shape[0], points.shape[1], 3)
    weights = np.array(weights).reshape(points.shape[0], points.shape[1])
    out = []
    for n in normals:
        e = (weights * np.maximum(dirs @ n, 0.0)).mean(1)
        out.append(e.var() / e.mean() ** 2)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--out', required=True)
    ap.add_argument('--seeds', default='7,1,2,3,4,5,6,8')
    ap.add_argument('--normals', nargs='+', default=['0,0', '20,120', '45,60', '60,300', '90,30', '90,250'])
    ap.add_argument('--example', default=os.path.join(HERE, '..', 'target', 'release', 'examples', 'env_point'))
    args = ap.parse_args()
    import numpy as np
    import mitsuba as mi
    from make_scenes import studio_map, write_exr
    mi.set_variant('scalar_rgb')
    os.makedirs(args.out, exist_ok=True)

    def unit(normal):
        t, a = (math.radians(float(x)) for x in normal.split(','))
        return np.array([math.sin(t) * math.cos(a), math.cos(t), math.sin(t) * math.sin(a)])

    normals = [unit(n) for n in args.normals]
    print('| map seed | normal (tilt, azimuth) | ours: relative variance | Mitsuba\'s | ours / Mitsuba\'s |')
    print('|---:|---|---:|---:|---:|')
    ratios = {n: [] for n in args.normals}
    for seed in [int(s) for s in args.seeds.split(',')]:
        path = os.path.join(args.out, f'studio_{seed}.exr')
        write_exr(path, studio_map(seed).astype(np.float32))
        points_path = os.path.join(args.out, f'points_{seed}.txt')
        text = subprocess.run([args.example, path, points_path, *args.normals], capture_output=True, text=True, check=True).stdout
        ours = [float(x) for x in re.findall(r'relvar plain ([0-9.eE+-]+)', text)]
        points = np.loadtxt(points_path).reshape(-1, 256, 2)
        theirs = mitsuba_relvars(mi, np, path, points, normals)
        for name, o, m in zip(args.normals, ours, theirs):
            ratios[name].append(o / m)
            print(f'| {seed} | {name} | {o:.2e} | {m:.2e} | {o / m:.2f} |', flush=True)
    gm = lambda r: math.exp(sum(math.log(x) for x in r) / len(r))
    print('\n| normal | ours / Mitsuba\'s over the maps: min – max (geometric mean) |')
    print('|---|---|')
    for name, r in ratios.items():
        print(f'| {name} | {min(r):.2f} – {max(r):.2f} ({gm(r):.2f}) |')
    every = [x for r in ratios.values() for x in r]
    print(f'| every normal | {min(every):.2f} – {max(every):.2f} ({gm(every):.2f}) |')


if __name__ == '__main__':
    main()
