#!/usr/bin/env python3
"""Equal render time against Mitsuba 3, side by side in one run on one machine (docs/perf.md,
"Equal time against Mitsuba 3").

  python3 docs/equal_time.py --out DIR [--spp 256] [--ref-spp 8192] [--methods mis,product-mis,auto]
                             [--seeds 7] [--threads 2] [--clock wall|cpu] [--repeat 1]
                             [--ppis target/release/ppis] SCENE.json...

Per scene: Mitsuba's converged image (`ldsampler`, --ref-spp) and ours (`mis`, --ref-spp, another
seed), each renderer measured against its own (the two differ on uncovered pixels by the map's
lookup rule, and slightly everywhere within the agreement docs/stability.md checks); the geometry
coverage, to measure covered pixels only. Then Mitsuba (`llvm_ad_rgb`, `direct`, JIT warmed up)
with `ldsampler` and `independent` at --spp, timed; each of our methods at --spp and at the spp
that its first time predicts for Mitsuba-ldsampler's time, its relMSE interpolated log-log at
that time. Prints one Markdown table of times, relMSE and ratios at equal time, and the
throughput per core: our shading points and shadow rays per second beside Mitsuba's (one primary
ray and two shadow rays per sample: `direct` samples the emitter and the BSDF once each), and
the time per visibility sample (a light sample, whether or not its contribution needs a ray:
ours skip the rays of samples that contribute nothing, so per traced ray is not the same
measure) over Mitsuba's. A second table times our MIS in Mitsuba's structure, one camera ray and
one pair of samples per sample, against Mitsuba's time and error at the same count. With
several --seeds, every timed render (both renderers) is repeated per seed, a row per seed, and
a last table gives each method's range of ratios over the seeds. With --repeat N the timed renders
run in N rounds, each round every render once, Mitsuba's and ours interleaved so that a drift of
the machine's speed falls on both; Mitsuba's time is the median of its N, ours per sample the
median of time / spp over all of a method's timings at its two spp (2N, or N where the predicted
spp is --spp; our time is proportional to spp at the default split, up to the few per cent of a
render that its pilots and light tables take), and our error at Mitsuba's time is read log-log in
spp between the two renders' errors at the spp that cost predicts. The images are the same each
round, so only that one cost carries our timings' noise: with the ratio of two renders' times (two
medians) a run moved a ratio by ±10%. The "ours" time in the first table is that cost × --spp. Every timing is kept in
DIR/SCENE_timings_SEED.json.

Needs `pip install mitsuba numpy` and `apt-get install libllvm19` (docs/reference/README.md); Mitsuba
renders through docs/reference/mitsuba_ref.py. References are cached in DIR."""
import argparse, json, math, os, re, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
MITSUBA_REF = os.path.join(HERE, 'reference', 'mitsuba_ref.py')
CLOCK = 'wall'
REPEAT = 1


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
    """Mitsuba's render time, one timed render."""
    key = 'render_cpu_seconds' if CLOCK == 'cpu' else 'render_seconds'
    text = run([sys.executable, MITSUBA_REF, scene, '--spp', str(spp), '--seed', str(seed), '--out', out,
                '--sampler', sampler, '--passes', str(passes), '--warmup', *extra])
    return float(re.search(key + r':\s*([0-9.eE+-]+)', text).group(1))


def seconds(stats):
    """Our render's time by the chosen clock."""
    return stats['render_cpu_seconds'] if CLOCK == 'cpu' else stats['render_seconds']


def ours(args, scene, method, spp, seed, out, extra=()):
    """Our render's statistics, one timed render."""
    stats = out + '.json'
    run([args.ppis, 'render', scene, '--method', method, '--spp', str(spp), '--seed', str(seed),
         '--threads', str(args.threads), '-o', out, '--stats-json', stats, *extra])
    with open(stats) as f:
        return json.load(f)


def at_spp(points, spp):
    """log-log interpolation (or extrapolation) of (spp, error) points at `spp`; from a single
    point, error ∝ 1/spp."""
    (s1, e1), (s2, e2) = sorted(points)[:1] + sorted(points)[-1:]
    if s1 == s2:
        return e1 * s1 / spp
    slope = (math.log(e2) - math.log(e1)) / (math.log(s2) - math.log(s1))
    return math.exp(math.log(e1) + slope * (math.log(spp) - math.log(s1)))


def median(values):
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def scene_rows(args, scene, seed):
    """One seed of one scene. The timed renders run in REPEAT rounds, each round every render once
    (Mitsuba's, then ours), so that a drift of the machine's speed falls on both renderers alike.
    Our time per sample is the median over all our timings of a method at both its spp, time / spp
    (our render time is proportional to spp at the default split), and our error at Mitsuba's time
    is read at the spp that cost predicts, log-log between the two renders' errors: the images do
    not change between rounds, so only the one cost carries the timings' noise."""
    name = os.path.splitext(os.path.basename(scene))[0]
    d = lambda f: os.path.join(args.out, f'{name}_{f}')
    if not os.path.exists(d('mref.exr')):
        mitsuba(scene, args.ref_spp, 4242, d('mref.exr'), 'ldsampler', passes=4, extra=['--coverage-out', d('cov.exr')])
    if not os.path.exists(d('pref.exr')):
        ours(args, scene, 'mis', args.ref_spp, 4242, d('pref.exr'))
    covered = load(d('cov.exr'))[..., 0] >= 0.999
    mref, pref = load(d('mref.exr')), load(d('pref.exr'))
    # Mitsuba's structure: one camera ray and one MIS pair (an emitter and a BSDF sample, the
    # power heuristic) per sample, so 2·spp visibility samples over spp camera rays.
    pairs_args = ['--shading-points', str(args.spp), '--mis-heuristic', 'power']
    times, stats, spps = {}, {}, {}
    for _ in range(REPEAT):
        for sampler in ['ldsampler', 'independent']:
            times.setdefault(sampler, []).append(
                mitsuba(scene, args.spp, seed, d(f'mts_{sampler}_{seed}.exr'), sampler))
        times.setdefault('pairs', []).append(seconds(
            ours(args, scene, 'mis', 2 * args.spp, seed, d(f'mis_pairs_{seed}.exr'), pairs_args)))
        for method in args.methods:
            st = ours(args, scene, method, args.spp, seed, d(f'{method}_{seed}.exr'))
            stats[method] = st
            times.setdefault((method, args.spp), []).append(seconds(st))
            if method not in spps:
                spp = max(1, 2 ** round(math.log2(args.spp * times['ldsampler'][0] / seconds(st))))
                spps[method] = sorted({args.spp, spp})
            for spp in spps[method]:
                if spp != args.spp:
                    st2 = ours(args, scene, method, spp, seed, d(f'{method}_{spp}_{seed}.exr'))
                    times.setdefault((method, spp), []).append(seconds(st2))
    # Every timing, for a reading other than this script's.
    with open(d(f'timings_{seed}.json'), 'w') as f:
        json.dump({'clock': CLOCK, 'times': {k if isinstance(k, str) else f'{k[0]}@{k[1]}': v for k, v in times.items()}},
                  f, indent=1)
    rows = {}
    for sampler in ['ldsampler', 'independent']:
        rows[sampler] = (median(times[sampler]), relmse(load(d(f'mts_{sampler}_{seed}.exr')), mref, covered))
    rows['pairs'] = (median(times['pairs']), relmse(load(d(f'mis_pairs_{seed}.exr')), pref, covered))
    target = rows['ldsampler'][0]
    h, w = covered.shape
    results = []
    for method in args.methods:
        cost = median([t / spp for spp in spps[method] for t in times[(method, spp)]])
        image = lambda spp: d(f'{method}_{seed}.exr' if spp == args.spp else f'{method}_{spp}_{seed}.exr')
        points = [(spp, relmse(load(image(spp)), pref, covered)) for spp in spps[method]]
        t = cost * args.spp
        per_core = t if CLOCK == 'cpu' else args.threads * t
        results.append((method, t, dict(points)[args.spp], at_spp(points, target / cost),
                        stats[method]['shading_points'] / per_core, stats[method]['shadow_rays'] / per_core))
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
    ap.add_argument('--repeat', type=int, default=1,
                    help='time every render (both renderers) in this many interleaved rounds (see above)')
    args = ap.parse_args()
    global CLOCK, REPEAT
    CLOCK, REPEAT = args.clock, max(1, args.repeat)
    os.makedirs(args.out, exist_ok=True)
    print(f'{args.spp} spp, {args.threads} threads; relMSE on covered pixels, each renderer against its own '
          f'converged image ({args.ref_spp} spp); "at Mitsuba-ld time": ours read log-log in spp at the spp its cost per sample predicts for that time; '
          f'"ours": that cost × {args.spp} spp.\n')
    print('| scene | seed | Mitsuba ldsampler | Mitsuba independent | method | ours | ours at Mitsuba-ld time '
          '| / ldsampler | / independent | our shading points/s/core | our shadow rays/s/core '
          '| Mitsuba-ld samples/s/core | time per visibility sample, ours / Mitsuba\'s |')
    print('|---|---:|---|---|---|---|---|---:|---:|---:|---:|---:|---:|')
    ratios, pair_rows = {}, []
    for scene in args.scenes:
        for seed in args.seeds:
            name, rows, results, samples = scene_rows(args, scene, seed)
            (t_ld, e_ld), (t_in, e_in) = rows['ldsampler'], rows['independent']
            for method, t, e, e_at, sp, sr in results:
                # Mitsuba's independent sampler's error at ldsampler's time: error ∝ 1/time.
                e_in_at = e_in * t_in / t_ld
                ratios.setdefault((name, method), []).append(e_at / e_ld)
                # Both at --spp: ours `spp` visibility samples per pixel, Mitsuba's two per sample.
                per_sample = t / (t_ld / 2)
                ratios.setdefault((name, method, 'sample'), []).append(per_sample)
                # Per traced shadow ray: ours trace only the samples that contribute, Mitsuba's
                # `direct` two rays per sample.
                mts_rate = samples / (t_ld if CLOCK == 'cpu' else args.threads * t_ld)
                ratios.setdefault((name, method, 'ray'), []).append(2 * mts_rate / sr)
                print(f'| {name} | {seed} | {t_ld:.2f} s, {e_ld:.2e} | {t_in:.2f} s, {e_in:.2e} | {method} | {t:.2f} s, {e:.2e} '
                      f'| {e_at:.2e} | {e_at / e_ld:.2f} | {e_at / e_in_at:.2f} | {sp / 1e6:.2f} M | {sr / 1e6:.2f} M '
                      f'| {mts_rate / 1e6:.2f} M | {per_sample:.2f} |', flush=True)
            t_p, e_p = rows['pairs']
            ratios.setdefault((name, 'one pair per camera ray', 'time'), []).append(t_p / t_ld)
            ratios.setdefault((name, 'one pair per camera ray', 'error'), []).append(e_p / e_ld)
            pair_rows.append(f'| {name} | {seed} | {t_p:.2f} s, {e_p:.2e} | {t_p / t_ld:.2f} | {e_p / e_ld:.2f} |')
    print('\nOur MIS in Mitsuba\'s structure (`--spp 2N --shading-points N --mis-heuristic power`: one camera '
          'ray, one env and one BRDF sample per sample, as `direct` at N spp):\n')
    print('| scene | seed | ours: CPU s, relMSE | time / Mitsuba-ld\'s (per camera ray) | relMSE / Mitsuba-ld\'s (equal samples) |')
    print('|---|---:|---|---:|---:|')
    print('\n'.join(pair_rows))
    if len(args.seeds) > 1:
        print('\n| scene | method | measure | over the seeds: min – max (median) |')
        print('|---|---|---|---|')
        measure = {'ratio': 'relMSE at equal time / ldsampler', 'sample': 'time per visibility sample / Mitsuba\'s',
                   'ray': 'time per traced shadow ray / Mitsuba\'s',
                   'time': 'time / Mitsuba-ld\'s', 'error': 'relMSE / Mitsuba-ld\'s'}
        for key, r in ratios.items():
            name, method, what = key if len(key) == 3 else (*key, 'ratio')
            r = sorted(r)
            print(f'| {name} | {method} | {measure[what]} | {r[0]:.2f} – {r[-1]:.2f} ({r[len(r) // 2]:.2f}) |')


if __name__ == '__main__':
    main()
