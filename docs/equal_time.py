#!/usr/bin/env python3
"""Equal render time against Mitsuba 3, side by side in one run on one machine (docs/perf.md,
"Equal time against Mitsuba 3").

  python3 docs/equal_time.py --out DIR [--spp 256] [--ref-spp 8192] [--methods mis,product-mis,auto]
                             [--seeds 7] [--threads 2] [--clock wall|cpu] [--ppis target/release/ppis]
                             SCENE.json...

Per scene: Mitsuba's converged image (`ldsampler`, --ref-spp) and ours (`mis`, --ref-spp, another
seed), each renderer measured against its own (the two differ on uncovered pixels by the map's
lookup rule, and slightly everywhere within the agreement docs/stability.md checks); the geometry
coverage, to measure covered pixels only. Then Mitsuba (`llvm_ad_rgb`, `direct`, JIT warmed up)
with `ldsampler` and `independent` at --spp, timed; each of our methods at --spp and at the spp
that its first time predicts for Mitsuba-ldsampler's time, its relMSE interpolated log-log at
that time. Prints one Markdown table of times, relMSE and ratios at equal time, and the
throughput per core: our shading points and shadow rays per second beside Mitsuba's (one primary
ray and two shadow rays per sample: `direct` samples the emitter and the BSDF once each). With
several --seeds, every timed render (both renderers) is repeated per seed, a row per seed, and
a last table gives each method's range of ratios over the seeds.

Needs `pip install mitsuba numpy` and `apt-get install libllvm19` (docs/reference/README.md); Mitsuba
renders through docs/reference/mitsuba_ref.py. References are cached in DIR."""
import argparse, json, math, os, re, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
MITSUBA_REF = os.path.join(HERE, 'reference', 'mitsuba_ref.py')
CLOCK = 'wall'


def run(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"equal_time: {' '.join(cmd)} failed:\n{out.stderr}")
    return out.stdout + out.stderr


def load(path):
    import mitsuba as mi
    import numpy as np
    mi.set_variant('scalar_rgb')
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def relmse(image, reference, covered):
    import numpy as np
    o, r = image[covered], reference[covered]
    return float(np.mean((o - r) ** 2 / (r ** 2 + 0.01)))


def mitsuba(scene, spp, seed, out, sampler, passes=1, extra=()):
    text = run([sys.executable, MITSUBA_REF, scene, '--spp', str(spp), '--seed', str(seed), '--out', out,
                '--sampler', sampler, '--passes', str(passes), '--warmup', *extra])
    key = 'render_cpu_seconds' if CLOCK == 'cpu' else 'render_seconds'
    return float(re.search(key + r':\s*([0-9.eE+-]+)', text).group(1))


def seconds(stats):
    """Our render's time by the chosen clock."""
    return stats['render_cpu_seconds'] if CLOCK == 'cpu' else stats['render_seconds']


def ours(args, scene, method, spp, seed, out):
    stats = out + '.json'
    run([args.ppis, 'render', scene, '--method', method, '--spp', str(spp), '--seed', str(seed),
         '--threads', str(args.threads), '-o', out, '--stats-json', stats])
    with open(stats) as f:
        return json.load(f)


def at_time(points, t):
    """log-log interpolation (or extrapolation) of (time, error) points at time t; from a single
    point, error ∝ 1/time."""
    (t1, e1), (t2, e2) = sorted(points)[:1] + sorted(points)[-1:]
    if t1 == t2:
        return e1 * t1 / t
    slope = (math.log(e2) - math.log(e1)) / (math.log(t2) - math.log(t1))
    return math.exp(math.log(e1) + slope * (math.log(t) - math.log(t1)))


def scene_rows(args, scene, seed):
    name = os.path.splitext(os.path.basename(scene))[0]
    d = lambda f: os.path.join(args.out, f'{name}_{f}')
    if not os.path.exists(d('mref.exr')):
        mitsuba(scene, args.ref_spp, 4242, d('mref.exr'), 'ldsampler', passes=4, extra=['--coverage-out', d('cov.exr')])
    if not os.path.exists(d('pref.exr')):
        ours(args, scene, 'mis', args.ref_spp, 4242, d('pref.exr'))
    covered = load(d('cov.exr'))[..., 0] >= 0.999
    mref, pref = load(d('mref.exr')), load(d('pref.exr'))
    rows = {}
    for sampler in ['ldsampler', 'independent']:
        t = mitsuba(scene, args.spp, seed, d(f'mts_{sampler}_{seed}.exr'), sampler)
        rows[sampler] = (t, relmse(load(d(f'mts_{sampler}_{seed}.exr')), mref, covered))
    target = rows['ldsampler'][0]
    h, w = covered.shape
    results = []
    for method in args.methods:
        points = []
        stats = ours(args, scene, method, args.spp, seed, d(f'{method}_{seed}.exr'))
        points.append((seconds(stats), relmse(load(d(f'{method}_{seed}.exr')), pref, covered)))
        spp = max(1, 2 ** round(math.log2(args.spp * target / seconds(stats))))
        if spp != args.spp:
            s2 = ours(args, scene, method, spp, seed, d(f'{method}_{spp}_{seed}.exr'))
            points.append((seconds(s2), relmse(load(d(f'{method}_{spp}_{seed}.exr')), pref, covered)))
        per_core = seconds(stats) if CLOCK == 'cpu' else args.threads * seconds(stats)
        results.append((method, seconds(stats), points[0][1], at_time(points, target),
                        stats['shading_points'] / per_core, stats['shadow_rays'] / per_core))
    samples = w * h * args.spp
    return name, rows, results, samples


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('scenes', nargs='+')
    ap.add_argument('--out', required=True)
    ap.add_argument('--spp', type=int, default=256)
    ap.add_argument('--ref-spp', type=int, default=8192)
    ap.add_argument('--methods', default='mis,product-mis,auto', type=lambda s: s.split(','))
    ap.add_argument('--seeds', default=[7], type=lambda s: [int(x) for x in s.split(',')])
    ap.add_argument('--threads', type=int, default=2)
    ap.add_argument('--clock', choices=['wall', 'cpu'], default='wall',
                    help='time both renderers by wall clock (an idle machine) or by the CPU seconds of '
                         'all their threads (a machine shared with other work)')
    ap.add_argument('--ppis', default=os.path.join(HERE, '..', 'target', 'release', 'ppis'))
    args = ap.parse_args()
    global CLOCK
    CLOCK = args.clock
    os.makedirs(args.out, exist_ok=True)
    print(f'{args.spp} spp, {args.threads} threads; relMSE on covered pixels, each renderer against its own '
          f'converged image ({args.ref_spp} spp); "at Mitsuba-ld time": ours interpolated log-log at its time.\n')
    print('| scene | seed | Mitsuba ldsampler | Mitsuba independent | method | ours | ours at Mitsuba-ld time '
          '| / ldsampler | / independent | our shading points/s/core | our shadow rays/s/core '
          '| Mitsuba-ld samples/s/core |')
    print('|---|---:|---|---|---|---|---|---:|---:|---:|---:|---:|')
    ratios = {}
    for scene in args.scenes:
        for seed in args.seeds:
            name, rows, results, samples = scene_rows(args, scene, seed)
            (t_ld, e_ld), (t_in, e_in) = rows['ldsampler'], rows['independent']
            for method, t, e, e_at, sp, sr in results:
                # Mitsuba's independent sampler's error at ldsampler's time: error ∝ 1/time.
                e_in_at = e_in * t_in / t_ld
                ratios.setdefault((name, method), []).append(e_at / e_ld)
                print(f'| {name} | {seed} | {t_ld:.2f} s, {e_ld:.2e} | {t_in:.2f} s, {e_in:.2e} | {method} | {t:.2f} s, {e:.2e} '
                      f'| {e_at:.2e} | {e_at / e_ld:.2f} | {e_at / e_in_at:.2f} | {sp / 1e6:.2f} M | {sr / 1e6:.2f} M '
                      f'| {samples / (t_ld if CLOCK == "cpu" else args.threads * t_ld) / 1e6:.2f} M |', flush=True)
    if len(args.seeds) > 1:
        print('\n| scene | method | / ldsampler over the seeds: min – max (median) |')
        print('|---|---|---|')
        for (name, method), r in ratios.items():
            r = sorted(r)
            print(f'| {name} | {method} | {r[0]:.2f} – {r[-1]:.2f} ({r[len(r) // 2]:.2f}) |')


if __name__ == '__main__':
    main()
