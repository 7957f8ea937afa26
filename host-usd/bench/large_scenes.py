#!/usr/bin/env python3
"""Large USD scenes, authored with Pixar's library, and how `ppis` renders them.

    pip install usd-core numpy
    cargo build --release -p host-std --bin ppis
    python3 host-usd/bench/large_scenes.py --out /tmp/large [--ppis target/release/ppis]

Writes, under --out:
- `prims_100k.usdc`: 100 000 gprims (spheres, cubes and small meshes in a 50 × 50 grid of
  Xforms of 40 prims each, with four UsdPreviewSurface materials) under a dome;
- `mesh_10m.usdc`: one Mesh of 10 million triangles (a displaced grid of 5 million quads) under
  a dome.
Then renders each with `ppis render --method product-mis --width 320 --height 240 --spp 4 --stats-json` and prints
the file size, load, BVH build and render times and peak memory (`/usr/bin/time -v`), the
table docs/usd.md ("Large scenes") holds.
"""
import argparse
import json
import math
import os
import re
import subprocess
import tempfile

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade, Vt


def materials(stage):
    looks = []
    for k, (color, metallic, roughness) in enumerate(
        [((0.8, 0.2, 0.1), 0.0, 0.5), ((0.9, 0.9, 0.9), 1.0, 0.2), ((0.1, 0.4, 0.8), 0.0, 0.3), ((0.9, 0.7, 0.3), 1.0, 0.4)]
    ):
        mat = UsdShade.Material.Define(stage, f"/World/Looks/M{k}")
        sh = UsdShade.Shader.Define(stage, f"/World/Looks/M{k}/Surface")
        sh.CreateIdAttr("UsdPreviewSurface")
        sh.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*color))
        sh.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(metallic)
        sh.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(roughness)
        mat.CreateSurfaceOutput().ConnectToSource(sh.ConnectableAPI(), "surface")
        looks.append(mat)
    return looks


def frame(stage, eye, target):
    cam = UsdGeom.Camera.Define(stage, "/World/Camera")
    m = Gf.Matrix4d().SetLookAt(Gf.Vec3d(*eye), Gf.Vec3d(*target), Gf.Vec3d(0, 1, 0)).GetInverse()
    cam.AddTransformOp().Set(m)
    UsdLux.DomeLight.Define(stage, "/World/Sky").CreateIntensityAttr(1.0)


def prims_100k(path, n_side=50, per_cell=40):
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    looks = materials(stage)
    quad_points = Vt.Vec3fArray([(0, 0, 0), (0.3, 0, 0), (0.3, 0.3, 0), (0, 0.3, 0)])
    for i in range(n_side):
        for j in range(n_side):
            cell = UsdGeom.Xform.Define(stage, f"/World/Grid/C{i}_{j}")
            cell.AddTranslateOp().Set(Gf.Vec3d(2.0 * i, 0, 2.0 * j))
            for k in range(per_cell):
                p = f"/World/Grid/C{i}_{j}/P{k}"
                kind = k % 3
                g = (UsdGeom.Sphere, UsdGeom.Cube, UsdGeom.Mesh)[kind].Define(stage, p)
                if kind == 0:
                    g.CreateRadiusAttr(0.1)
                elif kind == 1:
                    g.CreateSizeAttr(0.15)
                else:
                    g.CreatePointsAttr(quad_points)
                    g.CreateFaceVertexCountsAttr([4])
                    g.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
                g.AddTranslateOp().Set(Gf.Vec3d(0.3 * (k % 6), 0.3 * (k // 6), 0))
                UsdShade.MaterialBindingAPI.Apply(g.GetPrim()).Bind(looks[k % 4])
    frame(stage, (-20, 30, -20), (50, 0, 50))
    stage.GetRootLayer().Save()
    return n_side * n_side * per_cell


def mesh_10m(path, quads_side=1582):
    """quads_side² quads with 2 triangles each: 1582² · 2 ≈ 5.0 M; 2237² · 2 ≈ 10.0 M."""
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    looks = materials(stage)
    n = quads_side + 1
    x, z = np.meshgrid(np.linspace(-10, 10, n, dtype=np.float32), np.linspace(-10, 10, n, dtype=np.float32))
    y = 0.5 * np.sin(x * 1.7) * np.cos(z * 1.3)
    points = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1).astype(np.float32)
    idx = np.arange(n * n, dtype=np.int32).reshape(n, n)
    quads = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1)
    mesh = UsdGeom.Mesh.Define(stage, "/World/Terrain")
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(points))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(quads_side * quads_side, 4, dtype=np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(quads.astype(np.int32)))
    mesh.CreateSubdivisionSchemeAttr("none")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(looks[2])
    frame(stage, (0, 8, 14), (0, 0, 0))
    stage.GetRootLayer().Save()
    return 2 * quads_side * quads_side


def measure(ppis, scene):
    with tempfile.TemporaryDirectory() as tmp:
        stats = os.path.join(tmp, "stats.json")
        cmd = ["/usr/bin/time", "-v", ppis, "render", scene, "--method", "product-mis", "--width", "320", "--height", "240", "--spp", "4",
               "-o", os.path.join(tmp, "r.exr"), "--stats-json", stats]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            errors = [line for line in run.stderr.splitlines() if line.startswith("ppis: error")]
            return {"error": (errors or ["exit status %d" % run.returncode])[0]}
        peak_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", run.stderr).group(1))
        wall = re.search(r"Elapsed \(wall clock\) time.*: (.*)", run.stderr).group(1)
        with open(stats) as f:
            s = json.load(f)
        return {"stats": s, "peak_mb": peak_kb / 1024, "wall": wall}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--ppis", default="target/release/ppis")
    ap.add_argument("--quads-side", type=int, default=2237)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    scenes = []
    p = os.path.join(args.out, "prims_100k.usdc")
    scenes.append((p, f"{prims_100k(p)} gprims"))
    p = os.path.join(args.out, "mesh_10m.usdc")
    scenes.append((p, f"{mesh_10m(p, args.quads_side)} triangles"))
    print("| scene | size | file MB | load s | BVH s | render s | peak MB | wall |")
    print("|---|---|---|---|---|---|---|---|")
    for path, size in scenes:
        mb = os.path.getsize(path) / 1e6
        m = measure(args.ppis, path)
        if "error" in m:
            print(f"| {os.path.basename(path)} | {size} | {mb:.1f} | {m['error']} |")
            continue
        t = m["stats"]
        print(f"| {os.path.basename(path)} | {size} | {mb:.1f} | {t.get('load_seconds', float('nan')):.2f} | "
              f"{t.get('bvh_seconds', float('nan')):.2f} | {t.get('render_seconds', float('nan')):.2f} | "
              f"{m['peak_mb']:.0f} | {m['wall']} |")


if __name__ == "__main__":
    main()
