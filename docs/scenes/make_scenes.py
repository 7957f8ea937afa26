#!/usr/bin/env python3
"""Writes the environment maps of our two comparison scenes (docs/stability.md):

  furnace.json     — a Lambert sphere (albedo 0.5) alone under a constant map of radiance 1:
                     every pixel on it converges to 0.5 exactly (a convex object does not
                     shadow itself).
  sharp_sun.json   — a GGX conductor sphere with α = 0.01 and a grey ground under a dim sky
                     (0.05) with a sun of radius 0.5° and radiance 2e4 (4e5× the sky, in a
                     1024×512 map): the sharp highlight of a small sun.
  studio.json      — glossy GGX spheres (α = 0.05, 0.15, 0.3) on a grey floor under a dark
                     studio (0.02) lit by 24 soft boxes (discs of 3–6°, radiance 20–200): the
                     structured lighting under a glossy lobe where the paper's product pays —
                     neither factor is a near-delta, so neither env nor BRDF sampling alone
                     finds where their product is large.

  pip install mitsuba numpy; python3 docs/scenes/make_scenes.py
The maps are generated (not committed). Orientation: the project's lat-long convention,
u = atan2(x, −z)/2π, v = acos(y)/π (docs/conventions.md)."""
import os
import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, img):
    mi.Bitmap(img.astype(np.float32)).write(os.path.join(HERE, name))


write("furnace_env.exr", np.ones((32, 64, 3)))

w, h = 1024, 512
v, u = np.meshgrid((np.arange(h) + 0.5) / h, (np.arange(w) + 0.5) / w, indexing="ij")
theta, phi = v * np.pi, u * 2 * np.pi
d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)
sun = np.array([0.35, 0.55, 0.76])
sun /= np.linalg.norm(sun)
inside = d @ sun > np.cos(np.radians(0.5))
img = np.full((h, w, 3), 0.05)
img[inside] = 2.0e4
write("sharp_sun_env.exr", img)
print(f"sun texels: {inside.sum()}")

rng = np.random.default_rng(7)
img = np.full((h, w, 3), 0.02)
for _ in range(24):
    # Above the horizon: y = cos θ uniform in [0, 0.95].
    y = rng.uniform(0.0, 0.95)
    a = rng.uniform(0, 2 * np.pi)
    c = np.array([np.sqrt(1 - y * y) * np.sin(a), y, -np.sqrt(1 - y * y) * np.cos(a)])
    radius = np.radians(rng.uniform(3.0, 6.0))
    colour = rng.uniform(20.0, 200.0) * rng.uniform(0.8, 1.0, 3)
    img[d @ c > np.cos(radius)] = colour
write("studio_env.exr", img)
