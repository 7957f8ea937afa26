#!/usr/bin/env python3
"""Import time of hostile-shaped usda (and, with Pixar's `pxr`, usdc) stages at growing sizes.

Each shape puts N of one thing where a real asset has a few: properties on one prim, children
of one prim, time samples of one attribute, relationship targets, attribute connections,
entries of one dictionary, variants of one variant set, variant sets of one prim (each
selected), classes one prim inherits or specializes, prims it references in its own layer,
apiSchemas entries, GeometryLights (each taking a mesh met before it out of the surfaces), a
PointInstancer's prototypes (each a root prim beside it), a mesh's materialBind GeomSubsets (one
face and material each), sublayers and
references (each to a small file of its own). For each shape and N, `ppis info FILE` is run
R times and the least user CPU time is printed (the kernel's time is mostly opening files),
with the exponent of its growth from each size to the next: log(t2 / t1) / log(n2 / n1), 1
for linear growth, 2 for quadratic (shown where the smaller time is 0.02 s or more).

    python3 host-usd/bench/hostile_scaling.py PPIS DIR [--sizes 1000,10000,100000] [--repeat R]
        [--shapes props,children,…] [--usdc]
"""
import argparse, math, os, resource, subprocess, sys


def props(n):
    body = "".join(f"    float a{i} = {i}\n" for i in range(n))
    return f'#usda 1.0\ndef Xform "P"\n{{\n{body}}}\n'


def children(n):
    body = "".join(f'    def Xform "c{i}"\n    {{\n    }}\n' for i in range(n))
    return f'#usda 1.0\ndef Xform "P"\n{{\n{body}}}\n'


def samples(n):
    body = ", ".join(f"{i}: ({i}, 0, 0)" for i in range(n))
    return f'#usda 1.0\ndef Xform "P"\n{{\n    double3 xformOp:translate.timeSamples = {{ {body} }}\n' \
        f'    uniform token[] xformOpOrder = ["xformOp:translate"]\n}}\n'


def targets(n):
    body = ", ".join(f"</P/c{i}>" for i in range(n))
    return f'#usda 1.0\ndef Xform "P"\n{{\n    rel r = [{body}]\n}}\n'


def connections(n):
    body = ", ".join(f"</P.a{i}>" for i in range(n))
    return f'#usda 1.0\ndef Xform "P"\n{{\n    float x.connect = [{body}]\n}}\n'


def dictionary(n):
    body = "".join(f"        int k{i} = {i}\n" for i in range(n))
    return f'#usda 1.0\ndef Xform "P" (\n    customData = {{\n{body}    }}\n)\n{{\n}}\n'


def variants(n):
    body = "".join(f'        "v{i}" {{\n        }}\n' for i in range(n))
    return f'#usda 1.0\ndef Xform "P" (\n    variants = {{ string s = "v0" }}\n    prepend variantSets = "s"\n)\n' \
        f'{{\n    variantSet "s" = {{\n{body}    }}\n}}\n'


def variant_sets(n):
    sets = ", ".join(f'"s{i}"' for i in range(n))
    selections = "; ".join(f'string s{i} = "v"' for i in range(n))
    body = "".join(f'    variantSet "s{i}" = {{\n        "v" {{\n            float a{i} = {i}\n        }}\n    }}\n'
                   for i in range(n))
    return f'#usda 1.0\ndef Xform "P" (\n    variants = {{ {selections} }}\n    prepend variantSets = [{sets}]\n)\n' \
        f'{{\n{body}}}\n'


def inherits(n):
    classes = "".join(f'class "C{i}"\n{{\n    float a{i} = {i}\n}}\n' for i in range(n))
    body = ", ".join(f"</C{i}>" for i in range(n))
    return f'#usda 1.0\n{classes}def Xform "P" (\n    prepend inherits = [{body}]\n)\n{{\n}}\n'


def geometry_lights(n):
    mesh = ('    def Mesh "m{i}"\n    {{\n        point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]\n'
            '        int[] faceVertexCounts = [3]\n        int[] faceVertexIndices = [0, 1, 2]\n    }}\n')
    light = '    def GeometryLight "g{i}"\n    {{\n        rel geometry = </P/m{i}>\n    }}\n'
    body = "".join(mesh.format(i=i) for i in range(n)) + "".join(light.format(i=i) for i in range(n))
    return f'#usda 1.0\ndef Xform "P"\n{{\n{body}}}\n'


def prototypes(n):
    targets = ", ".join(f"</s{i}>" for i in range(n))
    indices = ", ".join(str(i) for i in range(n))
    positions = ", ".join(f"({i}, 0, 0)" for i in range(n))
    spheres = "".join(f'def Sphere "s{i}"\n{{\n}}\n' for i in range(n))
    return (f'#usda 1.0\ndef PointInstancer "P"\n{{\n    rel prototypes = [{targets}]\n'
            f'    int[] protoIndices = [{indices}]\n    point3f[] positions = [{positions}]\n}}\n{spheres}')


def subsets(n):
    material = ('def Material "M{i}"\n{{\n    token outputs:surface.connect = </M{i}/S.outputs:surface>\n'
                '    def Shader "S"\n    {{\n        uniform token info:id = "UsdPreviewSurface"\n'
                '        token outputs:surface\n    }}\n}}\n')
    subset = ('    def GeomSubset "g{i}" (\n        prepend apiSchemas = ["MaterialBindingAPI"]\n    )\n    {{\n'
              '        uniform token elementType = "face"\n        uniform token familyName = "materialBind"\n'
              '        int[] indices = [{i}]\n        rel material:binding = </M{i}>\n    }}\n')
    points = ", ".join(f"({i}, 0, 0), ({i + 1}, 0, 0), ({i}, 1, 0)" for i in range(n))
    counts = ", ".join("3" for _ in range(n))
    indices = ", ".join(str(i) for i in range(3 * n))
    body = "".join(subset.format(i=i) for i in range(n))
    mesh = (f'def Mesh "big"\n{{\n    point3f[] points = [{points}]\n    int[] faceVertexCounts = [{counts}]\n'
            f'    int[] faceVertexIndices = [{indices}]\n{body}}}\n')
    return "#usda 1.0\n" + "".join(material.format(i=i) for i in range(n)) + mesh


def specializes(n):
    classes = "".join(f'class "C{i}"\n{{\n    float a{i} = {i}\n}}\n' for i in range(n))
    body = ", ".join(f"</C{i}>" for i in range(n))
    return f'#usda 1.0\n{classes}def Xform "P" (\n    prepend specializes = [{body}]\n)\n{{\n}}\n'


def internal_references(n):
    prims = "".join(f'def Xform "R{i}"\n{{\n    float a{i} = {i}\n}}\n' for i in range(n))
    body = ", ".join(f"</R{i}>" for i in range(n))
    return f'#usda 1.0\n{prims}def Xform "P" (\n    prepend references = [{body}]\n)\n{{\n}}\n'


def api_schemas(n):
    body = ", ".join(f'"S{i}API"' for i in range(n))
    return f'#usda 1.0\ndef Xform "P" (\n    prepend apiSchemas = [{body}]\n)\n{{\n}}\n'


def sublayers(n, out):
    os.makedirs(out, exist_ok=True)
    for i in range(n):
        with open(os.path.join(out, f"l{i}.usda"), "w") as f:
            f.write(f'#usda 1.0\nover "P"\n{{\n    float a{i} = {i}\n}}\n')
    body = ", ".join(f"@{os.path.basename(out)}/l{i}.usda@" for i in range(n))
    return f'#usda 1.0\n(\n    subLayers = [{body}]\n)\ndef Xform "P"\n{{\n}}\n'


def references(n, out):
    os.makedirs(out, exist_ok=True)
    for i in range(n):
        with open(os.path.join(out, f"r{i}.usda"), "w") as f:
            f.write(f'#usda 1.0\ndef Xform "R"\n{{\n    float a{i} = {i}\n}}\n')
    body = ", ".join(f"@{os.path.basename(out)}/r{i}.usda@</R>" for i in range(n))
    return f'#usda 1.0\ndef Xform "P" (\n    prepend references = [{body}]\n)\n{{\n}}\n'


SHAPES = {"props": props, "children": children, "samples": samples, "targets": targets,
          "connections": connections, "dictionary": dictionary, "variants": variants,
          "variantSets": variant_sets, "inherits": inherits, "specializes": specializes,
          "internalReferences": internal_references, "apiSchemas": api_schemas,
          "geometryLights": geometry_lights, "prototypes": prototypes, "subsets": subsets}
FILE_SHAPES = {"sublayers": sublayers, "references": references}


def write(shape, n, dirname):
    path = os.path.join(dirname, f"{shape}{n}.usda")
    if shape in FILE_SHAPES:
        text = FILE_SHAPES[shape](n, os.path.join(dirname, f"{shape}{n}_files"))
    else:
        text = SHAPES[shape](n)
    with open(path, "w") as f:
        f.write(text)
    return path


def to_usdc(path):
    from pxr import Sdf
    out = path[:-5] + ".usdc"
    Sdf.Layer.FindOrOpen(path).Export(out)
    return out


def cpu_seconds(ppis, path):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([ppis, "info", path], capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        return None, r.stderr.strip().splitlines()[-1][:100]
    return after.ru_utime - before.ru_utime, ""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ppis"); ap.add_argument("dir")
    ap.add_argument("--sizes", default="1000,10000,100000")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--shapes", default=",".join(list(SHAPES) + list(FILE_SHAPES)))
    ap.add_argument("--usdc", action="store_true", help="also each file exported by Pixar's library")
    a = ap.parse_args()
    os.makedirs(a.dir, exist_ok=True)
    sizes = [int(s) for s in a.sizes.split(",")]
    print("| shape | format | " + " | ".join(f"{n}: user s" for n in sizes) + " | growth exponent |")
    print("|---|---|" + "---:|" * len(sizes) + "---|")
    for shape in a.shapes.split(","):
        for fmt in (["usda", "usdc"] if a.usdc else ["usda"]):
            cells, times = [], []
            for n in sizes:
                path = write(shape, n, a.dir)
                if fmt == "usdc":
                    path = to_usdc(path)
                runs = [cpu_seconds(a.ppis, path) for _ in range(a.repeat)]
                ok = [t for t, _ in runs if t is not None]
                cells.append(f"{min(ok):.2f}" if ok else f"error: {runs[0][1]}")
                times.append(min(ok) if ok else None)
            growth = ", ".join(f"{math.log(b / t) / math.log(m / n):.1f}" if t and b and t >= 0.02 else "–"
                               for t, b, n, m in zip(times, times[1:], sizes, sizes[1:]))
            print(f"| {shape} | {fmt} | " + " | ".join(cells) + f" | {growth} |", flush=True)


if __name__ == "__main__":
    main()
