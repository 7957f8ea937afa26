#!/usr/bin/env python3
"""Compare our EXR with a Mitsuba 3 reference on covered pixels: relMSE and mean bias.

  python3 docs/compare_mitsuba.py ours.exr mitsuba.exr [coverage.exr [mitsuba_stderr.exr]]

Needs `pip install mitsuba numpy` (Mitsuba reads the EXRs)."""
import sys, numpy as np, mitsuba as mi
mi.set_variant('scalar_rgb')
def load(p): return np.array(mi.Bitmap(p), dtype=np.float64)[..., :3]
ours, ref = load(sys.argv[1]), load(sys.argv[2])
cov = load(sys.argv[3])[..., 0] if len(sys.argv) > 3 else np.ones(ours.shape[:2])
m = cov >= 0.999
o, r = ours[m], ref[m]
rel = np.mean((o - r) ** 2 / (r ** 2 + 0.01))
bias = o.sum(axis=0) / r.sum(axis=0) - 1
print(f"covered pixels {m.sum()} of {m.size}; relMSE {rel:.3e}; mean bias per channel {bias[0]*100:+.3f}% {bias[1]*100:+.3f}% {bias[2]*100:+.3f}%")
if len(sys.argv) > 4:
    se = load(sys.argv[4])[m]
    z = (o.sum(axis=0) - r.sum(axis=0)) / np.sqrt((se ** 2).sum(axis=0))
    print("bias in units of Mitsuba's standard error of the sum:", np.round(z, 2))
