#!/usr/bin/env python3
"""Equal CPU time on a scene with an environment and other lights (docs/perf.md, "An
environment and a sun at equal time"): every environment method, the sun by its cone or in the
map (`--distant-carrier cone|map`; `auto` chooses between them per scene), and the lights' share
of each shading point's budget, in one table.

  python3 docs/env_and_lights.py --out DIR [--size 128] [--shares 0.25,0.5,0.75] [--ppis target/release/ppis] SCENE.json

Renders two converged references with MIS (8192 spp, 1024 shading points, seed 777): the sun by
its cone, and with `--distant-carrier map` (a sun rasterised into the map is a slightly different
light, so those variants are measured against their own). Then one `ppis report` per variant
(`--clock cpu --bracket --base mis`, 64/256/1024 spp, 2048 too but for `cone`):

- `cone`: mis, product-mis, auto, sis, lightcuts, the sun (every light) by the lights' estimator
  (`--distant-carrier cone`, as every variant but `map`);
- `map`: mis, product-mis, auto with `--distant-carrier map` (only where the scene has a distant light
  with an angle);
- `share-S`: mis and product-mis at 16 visibility samples per shading point with
  `--light-share S` for S in --shares (default ¼, ½, ¾; at the default four per point the split is
  one light pair and one environment pair whatever the share; `none` for no such variant);
- `points-V`: mis, product-mis and auto at V visibility samples per shading point
  (`--samples-per-point V`) and the default share, for V in --per-point (default none).

  python3 docs/env_and_lights.py --out DIR --shares none --per-point 8,16,32 --cone-methods mis,product-mis,auto SCENE.json

measures the budget per shading point alone (`--cone-methods`: the methods of `cone`, which is
every variant's base; default all five).

Every variant's relMSE per region is interpolated log-log at t, the CPU time of `cone`'s MIS at
1024 spp (* marks a value extrapolated past a variant's measured times), and printed as one
Markdown table, a row per variant and method, a column per region: relMSE at t for cone MIS, and
every other row's relMSE over it (< 1: better than cone MIS). The reports stay in DIR/VARIANT/ (report.md: per-spp figures and `auto`'s plans)."""
import argparse, csv, json, math, os, subprocess, sys

ORDER = ['mis', 'product-mis', 'auto', 'sis', 'lightcuts']


def run(cmd):
    print('+ ' + ' '.join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def has_sun(scene):
    lights = json.load(open(scene)).get('lights', [])
    return any(l['type'] == 'distant' and l.get('angle_deg', 0) > 0 for l in lights)


def variants(has_distant, shares, per_point, cone_methods):
    """(name, methods, extra flags, uses the map reference)."""
    cone = ['--distant-carrier', 'cone']
    out = [('cone', cone_methods, cone, False)]
    if has_distant:
        out.append(('map', 'mis,product-mis,auto', ['--distant-carrier', 'map'], True))
    for s in shares:
        out.append(('share-' + s, 'mis,product-mis', cone + ['--samples-per-point', '16', '--light-share', s], False))
    for v in per_point:
        out.append(('points-' + v, 'mis,product-mis,auto', cone + ['--samples-per-point', v], False))
    return out


def spp(variant):
    """The cone variant's MIS sets t at its 1024 spp; the others' MIS is their report's base (not
    bracketed) and may be faster, so they run to 2048 spp to reach t."""
    return '64,256,1024' if variant == 'cone' else '64,256,1024,2048'


def read_curves(path):
    """{(method, region): [(seconds, relmse)]} sorted by time."""
    curves = {}
    for row in csv.DictReader(open(path)):
        key = (row['method'], row['region'])
        curves.setdefault(key, []).append((float(row['seconds']), float(row['relmse'])))
    return {k: sorted(v) for k, v in curves.items()}


def at_time(points, t):
    """relMSE at t, log-log between the two nearest measured times; True if extrapolated."""
    points = [p for p in points if p[0] > 0 and p[1] > 0]
    if len(points) < 2:
        return (points[0][1] if points else float('nan')), True
    extrapolated = not points[0][0] <= t <= points[-1][0]
    i = 0
    while i < len(points) - 2 and points[i + 1][0] < t:
        i += 1
    (t0, e0), (t1, e1) = points[i], points[i + 1]
    if t1 == t0:
        return e0, extrapolated
    slope = (math.log(e1) - math.log(e0)) / (math.log(t1) - math.log(t0))
    return math.exp(math.log(e0) + slope * (math.log(t) - math.log(t0))), extrapolated


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('scene')
    ap.add_argument('--out', required=True)
    ap.add_argument('--size', default='128')
    ap.add_argument('--ppis', default='target/release/ppis')
    ap.add_argument('--shares', default='0.25,0.5,0.75', help='the lights\' shares at V = 16, or none')
    ap.add_argument('--per-point', default='none', help='visibility samples per shading point to compare, or none')
    ap.add_argument('--cone-methods', default='mis,product-mis,auto,sis,lightcuts')
    a = ap.parse_args()
    listed = lambda v: [] if v == 'none' else v.split(',')
    os.makedirs(a.out, exist_ok=True)
    size = ['--width', a.size, '--height', a.size]
    sun = has_sun(a.scene)
    refs = {False: os.path.join(a.out, 'ref.exr'), True: os.path.join(a.out, 'ref_map.exr')}
    for in_map, path in refs.items():
        if (in_map and not sun) or os.path.exists(path):
            continue
        run([a.ppis, 'render', a.scene, '--method', 'mis', '--spp', '8192', '--shading-points', '1024',
             '--seed', '777', '-o', path] + size + ['--distant-carrier', 'map' if in_map else 'cone'])
    curves = {}
    for name, methods, flags, in_map in variants(sun, listed(a.shares), listed(a.per_point), a.cone_methods):
        folder = os.path.join(a.out, name)
        table = os.path.join(folder, 'error_vs_time.csv')
        if not os.path.exists(table):
            run([a.ppis, 'report', a.scene, '--methods', methods, '--base', 'mis', '--spp', spp(name),
                 '--bracket', '--clock', 'cpu', '--reference', refs[in_map], '--out', folder] + size + flags)
        curves[name] = read_curves(table)
    base = curves['cone']
    t = next(float(r['seconds']) for r in csv.DictReader(open(os.path.join(a.out, 'cone', 'error_vs_time.csv')))
             if (r['method'], r['spp'], r['region']) == ('mis', '1024', 'all'))
    regions = [r for m, r in base if m == 'mis']
    rows = [(v, m) for v in curves for m in sorted({m for m, _ in curves[v]}, key=ORDER.index)]
    print(f'relMSE at t = {t:.2f} CPU s (cone MIS at 1024 spp); other rows: relMSE over cone MIS\'s\n')
    print('| variant | method | ' + ' | '.join(regions) + ' |')
    print('|---|---|' + '---:|' * len(regions))
    for v, m in rows:
        cells = []
        for r in regions:
            ref, _ = at_time(base[('mis', r)], t)
            e, x = at_time(curves[v].get((m, r), []), t)
            cells.append(f'{ref:.2e}' if (v, m) == ('cone', 'mis') else f'{e / ref:.2f}' + ('*' if x else ''))
        print(f'| {v} | {m} | ' + ' | '.join(cells) + ' |')


if __name__ == '__main__':
    main()
