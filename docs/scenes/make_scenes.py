#!/usr/bin/env python3
"""Writes the environment maps of our two comparison scenes (docs/stability.md):

  furnace.json     — a Lambert sphere (albedo 0.5) alone under a constant map of radiance 1:
                     every pixel on it converges to 0.5 exactly (a convex object does not
                     shadow itself).
  sharp_sun.json   — a GGX conductor sphere with α = 0.01 and a grey ground under a dim sky
                     (0.05) with a sun of radius 0.5° and radiance 2e4 (4e5× the sky, in a
                     1024×512 map): the sharp highlight of a small sun.

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
