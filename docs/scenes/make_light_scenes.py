"""Writes the light test scenes (docs/scene-format.md, "lights"): one scene per kind of light
alone, and one with every kind together under an environment map, over the same floor and three
spheres (a rough conductor, a diffuse sphere, a near-mirror). The mesh light is a small torus
written here as OBJ. Run from the repository root:

  python3 docs/scenes/make_light_scenes.py

Renders of them are compared with Mitsuba 3 in docs/stability.md, "Lights against Mitsuba 3"; sun_env.json
(a sun over the map) and lights_env.json are measured at equal time in docs/perf.md, "An
environment, a sun and lights at equal time" (docs/env_and_lights.py); lights_env.json's USD twin
is host-usd/tests/fixtures/lights_env.usda. lights_shaped.json holds shaped lights (cone, focus and
IES profiles from docs/scenes/ies/); its USD twin is host-usd/tests/fixtures/lights_shaped.usda.
With `--many DIR`, it writes instead the many-light scenes of docs/perf.md, "Many lights", into
DIR: tri{10,100,1000,10000}.json (that many small emissive triangles facing a floor with 20
spheres), pt1000.json (1000 point lights) and both.json (10 000 triangles and 1000 point lights).
With `--many-scaling DIR`, area{10,100,1000,10000}.json (the emitting area and power of tri1000
split into that many triangles: the same coverage of the sky at every count) and
points{10,100,1000,10000}.json (that many point lights of pt1000's total power) and
flat{10,100,1000,10000}.json (area{N}'s triangles, all 2.25 above the floor).
"""
import json
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

CAMERA = {"origin": [0, 2.5, 6], "target": [0, 0.6, 0], "up": [0, 1, 0], "fov_y_deg": 40,
          "width": 256, "height": 256}
SHAPES = [
    {"type": "rectangle", "p0": [-4, 0, -4], "e1": [0, 0, 8], "e2": [8, 0, 0],
     "material": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
    {"type": "sphere", "center": [-0.9, 0.6, 0], "radius": 0.6,
     "material": {"type": "roughconductor", "alpha": 0.15, "specular": [0.9, 0.8, 0.6]}},
    {"type": "sphere", "center": [0.6, 0.5, 0.6], "radius": 0.5,
     "material": {"type": "diffuse", "albedo": [0.7, 0.3, 0.2]}},
    {"type": "sphere", "center": [1.2, 0.4, -0.8], "radius": 0.4,
     "material": {"type": "roughconductor", "alpha": 0.02, "specular": [0.95, 0.95, 0.95]}},
]
LIGHTS = {
    "point": {"type": "point", "position": [0, 3, 2.5], "intensity": [12, 12, 12]},
    "sphere": {"type": "sphere", "center": [-1.8, 2.2, 0.5], "radius": 0.3, "radiance": [30, 25, 20]},
    "rectangle": {"type": "rectangle", "p0": [0.5, 3.0, -1.0], "e1": [1.0, 0, 0], "e2": [0, 0, 0.8],
                  "radiance": [8, 8, 10]},
    "disk": {"type": "disk", "center": [2.0, 1.5, 1.0], "normal": [-1, -0.3, -0.2], "radius": 0.35,
             "radiance": [15, 10, 6]},
    "mesh": {"type": "mesh", "file": "meshes/torus_lamp.obj", "radiance": [6, 8, 10]},
    "distant": {"type": "distant", "direction": [0.3, 1, 0.4], "irradiance": [1.5, 1.4, 1.2], "angle_deg": 2},
}
# Shaped lights (ShapingAPI's cone, focus and IES profile): a spot with a bilateral profile and a
# soft cone, a rectangle with a normalised, rescaled downlight profile about its normal, and the
# torus lamp under a focused cone and a profile about the world's −Y (its faces tilted from it).
SHAPED = [
    {"type": "point", "position": [0, 3, 1.5], "intensity": [12, 12, 12],
     "shaping": {"axis": [0, -1, 0], "cone_angle_deg": 60, "cone_softness": 0.3,
                 "ies": {"file": "ies/bilateral_1995.ies", "x": [1, 0, 0], "normalize": True}}},
    dict(LIGHTS["rectangle"], shaping={"ies": {"file": "ies/downlight_2002.ies", "x": [0, 0, 1],
                                                "angle_scale": 0.8, "normalize": True}}),
    dict(LIGHTS["mesh"], shaping={"axis": [0, -1, 0], "cone_angle_deg": 70, "cone_softness": 0.2, "focus": 2,
                                   "focus_tint": [0.2, 0.3, 0.4],
                                   "ies": {"file": "ies/bilateral_1995.ies", "x": [1, 0, 0], "normalize": True}}),
]


def torus(path, major=0.45, minor=0.08, center=(0.0, 2.4, 1.2), n_major=24, n_minor=8):
    """A torus around the vertical axis, faces wound outwards (front = emitting side)."""
    verts, faces = [], []
    for i in range(n_major):
        a = 2 * math.pi * i / n_major
        for j in range(n_minor):
            b = 2 * math.pi * j / n_minor
            r = major + minor * math.cos(b)
            verts.append((center[0] + r * math.cos(a), center[1] + minor * math.sin(b), center[2] + r * math.sin(a)))
    for i in range(n_major):
        for j in range(n_minor):
            a, b = i * n_minor + j, ((i + 1) % n_major) * n_minor + j
            c, d = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor, i * n_minor + (j + 1) % n_minor
            faces += [(a, d, c), (a, c, b)]
    with open(path, "w") as f:
        f.write("# torus lamp: docs/scenes/make_light_scenes.py\n")
        for v in verts:
            f.write("v %.6f %.6f %.6f\n" % v)
        for t in faces:
            f.write("f %d %d %d\n" % tuple(k + 1 for k in t))


def write(name, scene):
    with open(os.path.join(HERE, name + ".json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


def many(out, n_tri, n_point, name, side=0.15, point_intensity=(0.3, 0.3, 0.4), heights=(1.5, 3.0)):
    """A floor with 20 spheres under n_tri emissive triangles (`side` wide, facing down, at
    `heights` above it: a layer 1.5 deep by default) and n_point point lights, all scattered
    over 20×20."""
    random.seed(1)
    lights = []
    if n_tri:
        with open(os.path.join(out, name + ".obj"), "w") as f:
            for i in range(n_tri):
                x, z, y, s = random.uniform(-10, 10), random.uniform(-10, 10), random.uniform(*heights), side
                f.write(f"v {x} {y} {z}\nv {x + s} {y} {z}\nv {x} {y} {z + s}\nf {3 * i + 1} {3 * i + 2} {3 * i + 3}\n")
        lights.append({"type": "mesh", "file": name + ".obj", "radiance": [20, 18, 15]})
    for _ in range(n_point):
        x, z = random.uniform(-10, 10), random.uniform(-10, 10)
        lights.append({"type": "point", "position": [x, random.uniform(0.5, 2.5), z], "intensity": list(point_intensity)})
    shapes = [{"type": "rectangle", "p0": [-12, 0, -12], "e1": [0, 0, 24], "e2": [24, 0, 0],
               "material": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}}]
    for i in range(20):
        x, z = random.uniform(-8, 8), random.uniform(-8, 8)
        material = ({"type": "roughconductor", "alpha": 0.2, "specular": [0.9, 0.9, 0.9]} if i % 2
                    else {"type": "diffuse", "albedo": [0.7, 0.5, 0.3]})
        shapes.append({"type": "sphere", "center": [x, 0.5, z], "radius": 0.5, "material": material})
    camera = {"origin": [0, 6, 14], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 55, "width": 128, "height": 128}
    with open(os.path.join(out, name + ".json"), "w") as f:
        json.dump({"camera": camera, "lights": lights, "shapes": shapes}, f)


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--many":
        os.makedirs(sys.argv[2], exist_ok=True)
        for n in [10, 100, 1000, 10000]:
            many(sys.argv[2], n, 0, f"tri{n}")
        many(sys.argv[2], 0, 1000, "pt1000")
        many(sys.argv[2], 10000, 1000, "both")
        return
    if len(sys.argv) == 3 and sys.argv[1] == "--many-scaling":
        # The same emitting area and power (1000 triangles 0.15 wide) split into n triangles, so
        # that the sky the emitters cover stays alike while the light count grows; and n point
        # lights of the same total power, which are no geometry at all.
        os.makedirs(sys.argv[2], exist_ok=True)
        for n in [10, 100, 1000, 10000]:
            many(sys.argv[2], n, 0, f"area{n}", side=0.15 * math.sqrt(1000 / n))
            many(sys.argv[2], 0, n, f"points{n}", point_intensity=[c * 1000 / n for c in (0.3, 0.3, 0.4)])
            # The same triangles in one plane (a ceiling of tiles) instead of a layer 1.5 deep.
            many(sys.argv[2], n, 0, f"flat{n}", side=0.15 * math.sqrt(1000 / n), heights=(2.25, 2.25))
        return
    os.makedirs(os.path.join(HERE, "meshes"), exist_ok=True)
    torus(os.path.join(HERE, "meshes", "torus_lamp.obj"))
    for kind, light in LIGHTS.items():
        write("light_" + kind, {"name": "light_" + kind, "camera": CAMERA, "lights": [light], "shapes": SHAPES})
    write("lights_env", {"name": "lights_env", "camera": CAMERA,
                         "envmap": {"file": "../envmaps/courtyard.exr", "scale": 0.5},
                         "lights": list(LIGHTS.values()), "shapes": SHAPES})
    # A sun over the map: docs/tuning.md, "A sun in the map or by its cone".
    write("sun_env", {"name": "sun_env", "camera": dict(CAMERA, width=128, height=128),
                      "envmap": {"file": "../envmaps/courtyard.exr", "scale": 0.5},
                      "lights": [{"type": "distant", "direction": [0.3, 1, 0.4], "irradiance": [3, 2.8, 2.4],
                                  "angle_deg": 0.53}],
                      "shapes": SHAPES})
    write("lights_shaped", {"name": "lights_shaped", "camera": CAMERA, "lights": SHAPED, "shapes": SHAPES})


if __name__ == "__main__":
    main()
