#!/usr/bin/env python3
"""Writes a corpus of USD files with Pixar's own library, with Pixar's answers beside them.

    pip install usd-core==26.11
    python3 host-usd/tests/corpus/make_corpus.py --out DIR [--min-prims N] [--max-prims N]
        [--kinds spheres,…] [--formats usda,usdc,usdz]

For each kind and size it writes `<kind>_<n>.usda`, `.usdc` and `.usdz` (or those --formats
names; the same scene, the binary one by `Export`, as Pixar's tools save it) and `<kind>_<n>.expected.json`, what Pixar
computes for that scene in the format host-usd's conformance check reads
(`host-usd/src/conformance.rs`, `ppis info --expected DIR`): per prim its type, instancing,
world matrix, bound material and mesh counts; stage metadata; PointInstancer instance
transforms; and how many gprims, meshes and instances a renderer draws.

Kinds, each at 10, 1 000, 10 000 and 100 000 prims (from --min-prims to --max-prims): spheres; meshes with
varying points; meshes with identical points; a PointInstancer (as many instances); prims that
reference, or load as a payload, an asset file; prims with a variant set. Deep hierarchies
nest 10, 100 and 1 000 levels. The files up to 1 000 prims are committed in
host-usd/tests/corpus/; CI generates the rest.
"""
import argparse
import json
import math
import os
import shutil
import tempfile

from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, UsdUtils

SIZES = [10, 1000, 10000, 100000]
DEPTHS = [10, 100, 1000]
# Instance transforms saved per PointInstancer: the first ones, in order (JSON stays small).
MAX_TRANSFORMS = 1000


def matrix(m):
    return [[m[i][j] for j in range(4)] for i in range(4)]


def in_prototypes(path, prototypes):
    return any(path == p or path.HasPrefix(p) for p in prototypes)


def renders(prim):
    """A gprim a viewer draws: visible, of purpose default or render."""
    if UsdGeom.Imageable(prim).ComputeVisibility() == UsdGeom.Tokens.invisible:
        return False
    return UsdGeom.Imageable(prim).ComputePurpose() in (UsdGeom.Tokens.default_, UsdGeom.Tokens.render)


def answers(stage):
    """Pixar's answers for every prim (all prims, instance proxies included)."""
    cache = UsdGeom.XformCache(Usd.TimeCode.Default())
    out = {
        "stage": {
            "upAxis": UsdGeom.GetStageUpAxis(stage),
            "metersPerUnit": UsdGeom.GetStageMetersPerUnit(stage),
            "defaultPrim": str(stage.GetDefaultPrim().GetPath()) if stage.GetDefaultPrim() else None,
            "prototypes": [str(p.GetPath()) for p in stage.GetPrototypes()],
        },
        "prims": {},
        "instancers": {},
    }
    prims = list(Usd.PrimRange.Stage(stage, Usd.TraverseInstanceProxies(Usd.PrimAllPrimsPredicate)))
    prototypes = [t for p in prims if p.IsA(UsdGeom.PointInstancer)
                  for t in UsdGeom.PointInstancer(p).GetPrototypesRel().GetTargets()]
    counts = {"gprims": 0, "meshes": 0, "instances": 0}
    for prim in prims:
        entry = {"type": str(prim.GetTypeName()), "instance": prim.IsInstance(), "instanceProxy": prim.IsInstanceProxy()}
        if prim.IsA(UsdGeom.Xformable):
            entry["world"] = matrix(cache.GetLocalToWorldTransform(prim))
        if prim.IsA(UsdGeom.Gprim) or prim.IsA(UsdGeom.Subset):
            mat, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial(UsdShade.Tokens.full)
            if mat:
                entry["material"] = str(mat.GetPath())
        if prim.IsA(UsdGeom.Mesh):
            mesh = UsdGeom.Mesh(prim)
            entry["points"] = len(mesh.GetPointsAttr().Get() or [])
            fvc = list(mesh.GetFaceVertexCountsAttr().Get() or [])
            entry["faceVertexCounts"] = fvc if len(fvc) <= 16 else {"faces": len(fvc), "sum": sum(fvc)}
        out["prims"][str(prim.GetPath())] = entry
        if in_prototypes(prim.GetPath(), prototypes):
            continue
        if prim.IsA(UsdGeom.Gprim) and renders(prim):
            counts["gprims"] += 1
            counts["meshes"] += int(prim.IsA(UsdGeom.Mesh))
            counts["instances"] += int(prim.IsInstanceProxy())
        if prim.IsA(UsdGeom.PointInstancer) and renders(prim):
            instancer(stage, prim, prims, out, counts)
    out["counts"] = counts
    return out


def instancer(stage, prim, prims, out, counts):
    pi = UsdGeom.PointInstancer(prim)
    targets = pi.GetPrototypesRel().GetTargets()
    # The gprims each prototype draws, per instance.
    parts = [[p for p in prims if (p.GetPath() == t or p.GetPath().HasPrefix(t))
              and p.IsA(UsdGeom.Gprim) and renders(p)] for t in targets]
    xforms = pi.ComputeInstanceTransformsAtTime(
        Usd.TimeCode.Default(), Usd.TimeCode.Default(), UsdGeom.PointInstancer.IncludeProtoXform
    )
    mask = list(pi.ComputeMaskAtTime(Usd.TimeCode.Default())) or [True] * len(pi.GetProtoIndicesAttr().Get())
    indices = list(pi.GetProtoIndicesAttr().Get())
    for i, visible in enumerate(mask):
        if visible:
            counts["instances"] += 1
            counts["gprims"] += len(parts[indices[i]])
            counts["meshes"] += sum(int(p.IsA(UsdGeom.Mesh)) for p in parts[indices[i]])
    out["instancers"][str(prim.GetPath())] = {
        "prototypes": [str(p) for p in targets],
        "protoIndices": indices,
        "mask": list(pi.ComputeMaskAtTime(Usd.TimeCode.Default())),
        "instanceCount": len(xforms),
        "transforms": [matrix(m) for m in xforms[:MAX_TRANSFORMS]],
    }


def world_root(stage):
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    return world


def looks(stage, n):
    """n UsdPreviewSurface materials under /World/Looks."""
    mats = []
    for k in range(n):
        mat = UsdShade.Material.Define(stage, f"/World/Looks/M{k}")
        sh = UsdShade.Shader.Define(stage, f"/World/Looks/M{k}/Surface")
        sh.CreateIdAttr("UsdPreviewSurface")
        sh.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.2 * k, 0.5, 1 - 0.2 * k))
        mat.CreateSurfaceOutput().ConnectToSource(sh.ConnectableAPI(), "surface")
        mats.append(mat)
    return mats


def quad(stage, path, offset):
    mesh = UsdGeom.Mesh.Define(stage, path)
    o = offset
    mesh.CreatePointsAttr([(o, 0, 0), (o + 1, 0, 0), (o + 1, 1, o * 0.5), (o, 1, 0), (o + 2, 0.5, 0)])
    mesh.CreateFaceVertexCountsAttr([4, 3])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3, 1, 4, 2])
    mesh.CreateSubdivisionSchemeAttr("none")
    return mesh


# The kinds with the most prims are authored through Sdf in one change block: through
# UsdGeom, each new prim recomposes the stage, which makes 100 000 prims take many minutes.
T = Sdf.ValueTypeNames


def sdf_prim(layer, path, type_name, attrs, material=None):
    """A `def` prim spec with default values (name: (type, value, uniform)) and a direct
    material binding, as UsdGeom and UsdShade author them."""
    spec = Sdf.CreatePrimInLayer(layer, path)
    spec.specifier = Sdf.SpecifierDef
    spec.typeName = type_name
    for name, (kind, value, uniform) in attrs.items():
        attr = Sdf.AttributeSpec(spec, name, kind, Sdf.VariabilityUniform if uniform else Sdf.VariabilityVarying)
        attr.default = value
    if material is not None:
        spec.SetInfo("apiSchemas", Sdf.TokenListOp.Create(prependedItems=["MaterialBindingAPI"]))
        rel = Sdf.RelationshipSpec(spec, "material:binding", custom=False)
        rel.targetPathList.explicitItems = [material]


def sdf_place(i, n):
    """A grid position and a scale that vary with i; every tenth prim also turns (the others'
    matrices stay short in the answers). The scale is uniform: a renderer draws such spheres
    exactly, so that 100 000 of them import in seconds."""
    side = max(1, int(math.ceil(n ** (1 / 3))))
    x, y, z = i % side, (i // side) % side, i // (side * side)
    turn = Gf.Vec3f(i % 7 * 10.0, i % 11 * 5.0, i % 13 * 3.0) if i % 10 == 0 else Gf.Vec3f(0, 0, 0)
    ops = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
    return {
        "xformOp:translate": (T.Double3, Gf.Vec3d(2.5 * x, 2.5 * y, 2.5 * z), False),
        "xformOp:rotateXYZ": (T.Float3, turn, False),
        "xformOp:scale": (T.Float3, Gf.Vec3f(1.0 + i % 3 * 0.25), False),
        "xformOpOrder": (T.TokenArray, ops, True),
    }


def sdf_quad(offset):
    o = offset
    points = [(o, 0, 0), (o + 1, 0, 0), (o + 1, 1, o * 0.5), (o, 1, 0), (o + 2, 0.5, 0)]
    return {
        "points": (T.Point3fArray, points, False),
        "faceVertexCounts": (T.IntArray, [4, 3], False),
        "faceVertexIndices": (T.IntArray, [0, 1, 2, 3, 1, 4, 2], False),
        "subdivisionScheme": (T.Token, "none", True),
    }


def kind_spheres(stage, n, _dir):
    world_root(stage)
    mats = [m.GetPath() for m in looks(stage, 3)]
    layer = stage.GetRootLayer()
    with Sdf.ChangeBlock():
        for i in range(n):
            attrs = {"radius": (T.Double, 0.5 + (i % 5) * 0.1, False), **sdf_place(i, n)}
            sdf_prim(layer, f"/World/Sphere_{i}", "Sphere", attrs, mats[i % 3])


def kind_meshes_varying(stage, n, _dir):
    world_root(stage)
    mats = [m.GetPath() for m in looks(stage, 2)]
    layer = stage.GetRootLayer()
    with Sdf.ChangeBlock():
        for i in range(n):
            sdf_prim(layer, f"/World/Mesh_{i}", "Mesh", sdf_quad(i * 0.001), mats[i % 2])


def kind_meshes_identical(stage, n, _dir):
    world_root(stage)
    layer = stage.GetRootLayer()
    with Sdf.ChangeBlock():
        for i in range(n):
            sdf_prim(layer, f"/World/Mesh_{i}", "Mesh", {**sdf_quad(0.0), **sdf_place(i, n)})


def kind_instancer(stage, n, _dir):
    world_root(stage)
    pi = UsdGeom.PointInstancer.Define(stage, "/World/Instancer")
    pi.AddTranslateOp().Set(Gf.Vec3d(0, 1, 0))
    UsdGeom.Scope.Define(stage, "/World/Instancer/Prototypes")
    # A cube, not a sphere: half-precision orientations make the instance transforms
    # slightly non-orthogonal, and a renderer tessellates a sphere under those.
    box = UsdGeom.Cube.Define(stage, "/World/Instancer/Prototypes/Box")
    box.AddTranslateOp().Set(Gf.Vec3d(0, 0.5, 0))
    tile = UsdGeom.Xform.Define(stage, "/World/Instancer/Prototypes/Tile")
    quad(stage, "/World/Instancer/Prototypes/Tile/Quad", 0.0).AddScaleOp().Set(Gf.Vec3f(0.5, 0.5, 0.5))
    pi.CreatePrototypesRel().SetTargets([box.GetPath(), tile.GetPath()])
    side = max(1, int(math.ceil(math.sqrt(n))))
    pi.CreateProtoIndicesAttr([i % 2 for i in range(n)])
    pi.CreatePositionsAttr([Gf.Vec3f(2.0 * (i % side), 0, 2.0 * (i // side)) for i in range(n)])
    pi.CreateOrientationsAttr([Gf.Quath(Gf.Rotation(Gf.Vec3d(0, 1, 0), i % 360).GetQuat()) for i in range(n)])
    pi.CreateScalesAttr([Gf.Vec3f(1 + (i % 4) * 0.25) for i in range(n)])
    pi.CreateIdsAttr(list(range(n)))
    pi.CreateInvisibleIdsAttr(list(range(3, n, 7)))


def kind_deep(stage, depth, _dir):
    world_root(stage)
    path = Sdf.Path("/World")
    for level in range(depth):
        path = path.AppendChild(f"L{level}")
        x = UsdGeom.Xform.Define(stage, path)
        x.AddTranslateOp().Set(Gf.Vec3d(0.01, 0.02, 0.0))
        x.AddRotateYOp().Set(0.5)
    UsdGeom.Sphere.Define(stage, path.AppendChild("Leaf"))


def asset(directory, name):
    """An asset file, /Asset with a cube and a mesh, for references and payloads."""
    path = os.path.join(directory, name)
    if not os.path.exists(path):
        stage = Usd.Stage.CreateNew(path)
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
        root = UsdGeom.Xform.Define(stage, "/Asset")
        stage.SetDefaultPrim(root.GetPrim())
        UsdGeom.Cube.Define(stage, "/Asset/Box").AddTranslateOp().Set(Gf.Vec3d(0, 0.5, 0))
        quad(stage, "/Asset/Quad", 0.0)
        stage.GetRootLayer().Save()
    return name


def arcs_to_asset(stage, n, directory, prefix, list_of, arc):
    """n Xforms, each bringing in the asset through one composition arc (a reference or a
    payload: `list_of` names the prim spec's list op, `arc` makes its item)."""
    world_root(stage)
    name = asset(directory, "asset.usda")
    layer = stage.GetRootLayer()
    with Sdf.ChangeBlock():
        for i in range(n):
            sdf_prim(layer, f"/World/{prefix}_{i}", "Xform", sdf_place(i, n))
            getattr(layer.GetPrimAtPath(f"/World/{prefix}_{i}"), list_of).prependedItems = [arc(name)]


def kind_references(stage, n, directory):
    arcs_to_asset(stage, n, directory, "Ref", "referenceList", Sdf.Reference)


def kind_payloads(stage, n, directory):
    arcs_to_asset(stage, n, directory, "Payload", "payloadList", Sdf.Payload)


def kind_variants(stage, n, _dir):
    world_root(stage)
    choices = ["ball", "box", "tile"]
    shapes = {
        "ball": ("Sphere", {}),
        "box": ("Cube", {"xformOp:translate": (T.Double3, Gf.Vec3d(0, 1, 0), False),
                         "xformOpOrder": (T.TokenArray, ["xformOp:translate"], True)}),
        "tile": ("Mesh", sdf_quad(0.0)),
    }
    layer = stage.GetRootLayer()
    with Sdf.ChangeBlock():
        for i in range(n):
            path = f"/World/Var_{i}"
            sdf_prim(layer, path, "Xform", sdf_place(i, n))
            spec = layer.GetPrimAtPath(path)
            vset = Sdf.VariantSetSpec(spec, "shape")
            for c in choices:
                Sdf.VariantSpec(vset, c)
                type_name, attrs = shapes[c]
                sdf_prim(layer, f"{path}{{shape={c}}}Shape", type_name, attrs)
            spec.variantSetNameList.prependedItems = ["shape"]
            spec.variantSelections["shape"] = choices[i % 3]


KINDS = {
    "spheres": (kind_spheres, SIZES),
    "meshes_varying": (kind_meshes_varying, SIZES),
    "meshes_identical": (kind_meshes_identical, SIZES),
    "instancer": (kind_instancer, SIZES),
    "deep": (kind_deep, DEPTHS),
    "references": (kind_references, SIZES),
    "payloads": (kind_payloads, SIZES),
    "variants": (kind_variants, SIZES),
}


def write(out, kind, n, build, formats):
    stem = f"{kind}_{n}"
    tmp = tempfile.mkdtemp()
    try:
        usda = os.path.join(tmp, stem + ".usda")
        stage = Usd.Stage.CreateNew(usda)
        build(stage, n, tmp)
        # The usda is also the source of the usdz package.
        stage.GetRootLayer().Save()
        if "usdc" in formats:
            stage.GetRootLayer().Export(os.path.join(tmp, stem + ".usdc"))
        if "usdz" in formats:
            UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(usda), os.path.join(tmp, stem + ".usdz"))
        # The files are one scene, so Pixar's answers are computed once, from the usdc when
        # there is one (the format Pixar's library opens fastest).
        source = "usdc" if "usdc" in formats else formats[0]
        want = answers(Usd.Stage.Open(os.path.join(tmp, f"{stem}.{source}")))
        with open(os.path.join(out, stem + ".expected.json"), "w") as f:
            json.dump(want, f, separators=(",", ":"))
            f.write("\n")
        for name in [f"{stem}.{ext}" for ext in formats] + [n for n in os.listdir(tmp) if n == "asset.usda"]:
            shutil.copy(os.path.join(tmp, name), os.path.join(out, name))
    finally:
        shutil.rmtree(tmp)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--max-prims", type=int, default=max(SIZES))
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--min-prims", type=int, default=0)
    ap.add_argument("--formats", default="usda,usdc,usdz")
    args = ap.parse_args()
    formats = args.formats.split(",")
    assert formats and set(formats) <= {"usda", "usdc", "usdz"}, args.formats
    os.makedirs(args.out, exist_ok=True)
    for kind in args.kinds.split(","):
        build, sizes = KINDS[kind]
        for n in sizes:
            if args.min_prims <= n <= args.max_prims:
                write(args.out, kind, n, build, formats)


if __name__ == "__main__":
    main()
