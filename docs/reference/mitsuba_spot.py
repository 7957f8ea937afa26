#!/usr/bin/env python3
"""Mitsuba 3's `spot` emitter against UsdLux ShapingAPI's cone, the formula
`sampler-core/tests/integration/light_shaping.rs` holds ppis's shaped point light to.

    pip install mitsuba
    python3 docs/reference/mitsuba_spot.py

A spot 2 units above the plane z = 0 aiming straight down, intensity 5, cone 30°: the irradiance
at points of the plane seen at angles θ from the axis is I·cos θ/d² inside the cone and 0
beyond it. Mitsuba's soft band (between `beam_width` and `cutoff_angle`) falls linearly in θ,
while the schema's softness is a smoothstep, so only the hard cone (no transition) compares.
Exits non-zero if Mitsuba and the formula disagree by more than 1e-5 relative.
"""
import math
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")
CONE, I, H = 30.0, 5.0, 2.0
spot = mi.load_dict({
    "type": "spot",
    "cutoff_angle": CONE,
    "beam_width": CONE - 1e-4,
    "intensity": {"type": "rgb", "value": [I, I, I]},
    "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, H], target=[0, 0, 0], up=[0, 1, 0]),
})
worst = 0.0
for deg in [0.0, 10.0, 20.0, 29.0, 31.0, 45.0]:
    x = H * math.tan(math.radians(deg))
    it = mi.Interaction3f()
    it.p, it.n = mi.Point3f(x, 0, 0), mi.Vector3f(0, 0, 1)
    ds, weight = spot.sample_direction(it, mi.Point2f(0.5, 0.5))
    mitsuba = weight[0] * max(0.0, ds.d[2])
    formula = I * (1.0 if deg <= CONE else 0.0) * math.cos(math.radians(deg)) / (H * H + x * x)
    worst = max(worst, abs(mitsuba - formula) / max(formula, 1e-3))
    print(f"{deg:5.1f}°  Mitsuba {mitsuba:.6f}  formula {formula:.6f}")
print(f"largest relative difference {worst:.2e}")
sys.exit(0 if worst <= 1e-5 else 1)
