#!/usr/bin/env python3
"""Import speed of `ppis info` against Pixar's library (usd-core).

Generates stages of N spheres and of N simple meshes (a quad each) under one Xform,
each prim with its own translate (kinds: `spheres`; `meshes`, every quad the same
points; `quads`, every quad its own points), in usda and usdc (exported by Pixar's Sdf), plus
chains of nested Xforms,
into a folder (default: a temporary one); then times, for each file, `ppis info FILE`
(the whole process, wall clock, and its peak RSS) and Pixar's `Usd.Stage.Open` plus a
traversal computing every gprim's world transform with a UsdGeom.XformCache (inside
one Python process, the pxr import excluded). Prints a Markdown table.

    python3 host-usd/bench/import_bench.py [--ppis target/release/ppis] [--dir DIR]
        [--counts 10,1000,10000,100000] [--depths 250,500,1000,2000]
        [--kinds spheres,meshes,quads] [--formats usda,usdc]

Bytes per prim is the peak RSS above the 10-prim file's of the same kind, divided by
the prim count.
"""
import argparse, os, subprocess, sys, tempfile, time

PIXAR = r"""
import sys, time
from pxr import Usd, UsdGeom
t = time.perf_counter(); c = time.process_time()
stage = Usd.Stage.Open(sys.argv[1])
cache = UsdGeom.XformCache(Usd.TimeCode.Default())
n = 0
for p in stage.Traverse():
    if p.IsA(UsdGeom.Gprim):
        cache.GetLocalToWorldTransform(p)
        n += 1
print(time.perf_counter() - t, time.process_time() - c, n)
"""


def usda_text(kind, n):
    """The stage as usda text (written directly: authoring 100 000 prims through the
    Usd API takes minutes)."""
    out = ["#usda 1.0\n"]
    xf = 'double3 xformOp:translate = ({})\nuniform token[] xformOpOrder = ["xformOp:translate"]\n'
    if kind == "deep":
        for i in range(n):
            out.append(f'def Xform "X{i}"\n{{\n' + xf.format("0.5, 0, 0"))
        out.append('def Sphere "S"\n{\n}\n' + "}\n" * n)
        return "".join(out)
    out.append('def Xform "W"\n{\n')
    for i in range(n):
        at = f"{i % 100}, {(i // 100) % 100}, {i // 10000}"
        if kind == "spheres":
            out.append(f'def Sphere "S{i}"\n{{\ndouble radius = 0.4\n' + xf.format(at) + "}\n")
        else:
            # "meshes" share one quad's points (a layer may hold them once); "quads" each
            # have their own, as scanned or modelled meshes do.
            x = i if kind == "quads" else 0
            points = f"({x}, 0, 0), ({x + 1}, 0, 0), ({x + 1}, 1, 0), ({x}, 1, 0)"
            out.append(f'def Mesh "M{i}"\n{{\npoint3f[] points = [{points}]\n'
                       "int[] faceVertexCounts = [4]\nint[] faceVertexIndices = [0, 1, 2, 3]\n"
                       + xf.format(at) + "}\n")
    out.append("}\n")
    return "".join(out)


def generate(kind, n, path):
    text = usda_text(kind, n)
    if path.endswith(".usda"):
        with open(path, "w") as f:
            f.write(text)
        return
    from pxr import Sdf
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    layer.Export(path)


def timed(cmd):
    """(wall seconds, peak RSS bytes, stdout, return code) of a process."""
    t = time.perf_counter()
    r = subprocess.run(["/usr/bin/time", "-f", "%M"] + cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    rss = int(r.stderr.strip().splitlines()[-1]) * 1024
    return wall, rss, r.stdout, r.returncode, r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ppis", default="target/release/ppis")
    ap.add_argument("--dir")
    ap.add_argument("--counts", default="10,1000,10000,100000")
    ap.add_argument("--depths", default="250,500,1000,2000")
    ap.add_argument("--formats", default="usda,usdc")
    ap.add_argument("--kinds", default="spheres,meshes,quads")
    a = ap.parse_args()
    folder = a.dir or tempfile.mkdtemp(prefix="ppis-import-bench-")
    os.makedirs(folder, exist_ok=True)
    cases = []
    for fmt in a.formats.split(","):
        for kind in a.kinds.split(","):
            cases += [(kind, int(n), fmt) for n in a.counts.split(",")]
        cases += [("deep", int(d), fmt) for d in a.depths.split(",")]
    print("| file | prims | size | ppis s | Pixar s | ratio | ppis peak MB | bytes/prim |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    base = {}
    for kind, n, fmt in cases:
        path = os.path.join(folder, f"{kind}{n}.{fmt}")
        if not os.path.exists(path):
            generate(kind, n, path)
        prims = n + 1
        wall, rss, _, rc, err = timed([a.ppis, "info", path])
        pix = subprocess.run([sys.executable, "-c", PIXAR, path], capture_output=True, text=True)
        pixar_s = float(pix.stdout.split()[0])
        size = os.path.getsize(path)
        name = os.path.basename(path)
        if rc != 0:
            msg = err.strip().splitlines()[0][:60]
            print(f"| {name} | {prims} | {size} | failed: {msg} | {pixar_s:.3f} | | | |")
            continue
        key = (kind, fmt)
        if kind != "deep" and key not in base:
            base[key] = (rss, prims)
        b = base.get(key)
        per = f"{(rss - b[0]) / (prims - b[1]):.0f}" if b and prims > b[1] else ""
        print(f"| {name} | {prims} | {size} | {wall:.3f} | {pixar_s:.3f} | {wall / pixar_s:.2f} "
              f"| {rss / 2**20:.1f} | {per} |", flush=True)


if __name__ == "__main__":
    main()
