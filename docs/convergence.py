#!/usr/bin/env python3
"""Does every method converge? relMSE against a converged reference at 4× steps of spp, each
the mean over several seeds (one seed's relMSE is dominated by its rarest large samples; the
mean over seeds estimates the expected error, which falls 4× per 4× spp when the pixel
footprint is integrated too — docs/tuning.md, "Shading points per pixel").

  python3 docs/convergence.py --out DIR [--methods mis,product-mis] [--spp 16,64,256,1024]
                              [--seeds 8] [--ref-spp 16384] [--width 160 --height 90] [SCENE]

Without SCENE: the embedded default scene. The reference is rendered once (method mis, seed
4242) and cached in DIR. Needs numpy and the `exr`-reading `mitsuba` package, or OpenEXR."""
import argparse, os, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))


def load(path):
    import mitsuba as mi
    import numpy as np
    mi.set_variant('scalar_rgb')
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def render(args, method, spp, seed, out):
    cmd = [args.ppis, 'render', *args.scene, '--method', method, '--spp', str(spp), '--seed', str(seed),
           '--width', str(args.width), '--height', str(args.height), '-o', out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"convergence: {' '.join(cmd)} failed:\n{r.stderr}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('scene', nargs='*')
    ap.add_argument('--out', required=True)
    ap.add_argument('--methods', default='mis,product-mis', type=lambda s: s.split(','))
    ap.add_argument('--spp', default='16,64,256,1024', type=lambda s: [int(v) for v in s.split(',')])
    ap.add_argument('--seeds', type=int, default=8)
    ap.add_argument('--ref-spp', type=int, default=16384)
    ap.add_argument('--width', type=int, default=160)
    ap.add_argument('--height', type=int, default=90)
    ap.add_argument('--ppis', default=os.path.join(HERE, '..', 'target', 'release', 'ppis'))
    args = ap.parse_args()
    import numpy as np
    os.makedirs(args.out, exist_ok=True)
    ref_path = os.path.join(args.out, 'reference.exr')
    if not os.path.exists(ref_path):
        render(args, 'mis', args.ref_spp, 4242, ref_path)
    ref = load(ref_path)
    print(f'relMSE, mean of {args.seeds} seeds, against mis at {args.ref_spp} spp; '
          f'in brackets the fall from the previous spp\n')
    print('| method | ' + ' | '.join(f'{s} spp' for s in args.spp) + ' |')
    print('|---|' + '---:|' * len(args.spp))
    for method in args.methods:
        cells, previous = [], None
        for spp in args.spp:
            errors = []
            for seed in range(args.seeds):
                out = os.path.join(args.out, f'{method}_{spp}_{seed}.exr')
                render(args, method, spp, seed, out)
                img = load(out)
                errors.append(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01)))
            e = float(np.mean(errors))
            cells.append(f'{e:.3e}' + (f' ({previous / e:.1f}×)' if previous else ''))
            previous = e
        print(f'| {method} | ' + ' | '.join(cells) + ' |', flush=True)


if __name__ == '__main__':
    main()
