#!/usr/bin/env python3
"""The lights' share that each part's own variance predicts (docs/tuning.md, "The environment's
and the lights' shares").

  python3 docs/light_share.py --out DIR [--size 128] [--ppis target/release/ppis] SCENE.json

A shading point's estimate is the environment's part plus the lights' part, sampled apart: with
n samples split n_L = s·n and n_E = (1 − s)·n, its variance is S_E/n_E + S_L/n_L, least at
s = √S_L / (√S_L + √S_E) (Neyman's allocation; samples of either part taken to cost the same).
The script writes the scene twice into DIR — without its lights (the environment's part) and
without its environment (the lights' part) — renders each part's MIS reference (8192 spp, 1024
shading points, seed 777) and each part with MIS at 16 shading points per pixel and V = 4 and 64
visibility samples per point; the weighted squared error m(V) = (A + S/V)/16 (A: the part's
pixel-footprint noise, the same at both V; weights 1/(r² + 0.01) per channel, r the whole
scene's reference DIR/ref.exr that docs/env_and_lights.py writes, as `ppis report`'s relMSE)
gives each S = 16·(m(4) − m(64))/(1/4 − 1/64). Prints S_E, S_L and the predicted share. Needs
numpy, and mitsuba to read EXR (docs/reference/README.md installs it)."""
import argparse, json, os, subprocess, sys

import numpy as np


def read_exr(path):
    import mitsuba as mi
    mi.set_variant('scalar_rgb')
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def render(ppis, scene, spp, points, seed, out, size):
    cmd = [ppis, 'render', scene, '--method', 'mis', '--spp', str(spp), '--shading-points', str(points),
           '--seed', str(seed), '-o', out, '--width', size, '--height', size]
    print('+ ' + ' '.join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def part(scene_path, keep, out):
    """The scene with only its environment (keep='env') or only its lights (keep='lights'),
    its files made absolute."""
    scene = json.load(open(scene_path))
    here = os.path.dirname(os.path.abspath(scene_path))
    if keep == 'env':
        scene.pop('lights', None)
    else:
        scene.pop('envmap', None)
    if 'envmap' in scene:
        scene['envmap']['file'] = os.path.join(here, scene['envmap']['file'])
    for light in scene.get('lights', []):
        if 'file' in light:
            light['file'] = os.path.join(here, light['file'])
    with open(out, 'w') as f:
        json.dump(scene, f)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('scene')
    ap.add_argument('--out', required=True)
    ap.add_argument('--size', default='128')
    ap.add_argument('--ppis', default='target/release/ppis')
    a = ap.parse_args()
    weight = 1.0 / (read_exr(os.path.join(a.out, 'ref.exr')) ** 2 + 0.01)
    variance = {}
    for keep in ('env', 'lights'):
        scene = part(a.scene, keep, os.path.join(a.out, f'part_{keep}.json'))
        ref = os.path.join(a.out, f'part_{keep}_ref.exr')
        if not os.path.exists(ref):
            render(a.ppis, scene, 8192, 1024, 777, ref, a.size)
        r = read_exr(ref)
        m = {}
        for v in (4, 64):
            img = os.path.join(a.out, f'part_{keep}_v{v}.exr')
            render(a.ppis, scene, 16 * v, 16, 1, img, a.size)
            m[v] = float(np.mean((read_exr(img) - r) ** 2 * weight))
        variance[keep] = 16 * (m[4] - m[64]) / (1 / 4 - 1 / 64)
        print(f'{keep}: m(4) {m[4]:.3e}, m(64) {m[64]:.3e}, S {variance[keep]:.3e}')
    se, sl = (max(variance[k], 0.0) ** 0.5 for k in ('env', 'lights'))
    print(f'predicted lights\' share: {sl / (sl + se):.2f}')


if __name__ == '__main__':
    main()
