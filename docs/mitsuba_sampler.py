#!/usr/bin/env python3
"""Render a scene with Mitsuba 3 like ../shared/reference/mitsuba_ref.py, but with another sampler
(the shared script always uses `independent`): to compare our pixel-wide sample nets with
Mitsuba's own stratified and low-discrepancy samplers at equal time.

  python3 docs/mitsuba_sampler.py SCENE.json --sampler ldsampler --spp 1024 --seed 7 --out OUT.exr

Prints 'render_seconds: X' after an untimed warm-up render (JIT excluded), as mitsuba_ref.py does."""
import argparse, os, sys
here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(here, '..', '..', 'shared', 'reference')))
import mitsuba_ref  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument('scene'); ap.add_argument('--spp', type=int, default=64)
ap.add_argument('--seed', type=int, default=0); ap.add_argument('--out', required=True)
ap.add_argument('--sampler', default='ldsampler',
                choices=['independent', 'stratified', 'multijitter', 'orthogonal', 'ldsampler'])
args = ap.parse_args()

build = mitsuba_ref.build_scene
def build_with_sampler(*a, **k):
    d = build(*a, **k)
    s = d['sensor']['sampler']
    d['sensor']['sampler'] = {'type': args.sampler, 'sample_count': s['sample_count'], 'seed': s['seed']}
    return d
mitsuba_ref.build_scene = build_with_sampler

img, secs, _ = mitsuba_ref.render(args.scene, args.spp, args.seed, warmup=True)
mitsuba_ref.write_exr(args.out, img)
print(f'render_seconds: {secs:.4f}')
