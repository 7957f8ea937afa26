#!/usr/bin/env python3
"""Writes `shaped_ceiling.usda` (to the path given, default the current folder): a grey floor
under a ceiling of N × N small downlights, one mesh light with MeshLightAPI and ShapingAPI
(a 20° cone, softness 0.2: each quad lights a spot about 1.5 wide on the floor 2.5 below), and
a camera looking down at the floor. The scene of docs/perf.md, "Shaped and IES lights", that
measures the light tree's bounds of shaped mesh-light faces.

    pip install usd-core
    python3 docs/reference/shaped_ceiling.py /tmp/shaped_ceiling.usda [N] [--ies]

With `--ies`, each quad is tilted 30° from the light's axis and the light carries the bilateral
IES profile of docs/scenes/ies/ (copied beside the output): the load cost of the faces' power
from the profile's grid (docs/perf.md, "Shaped and IES lights").
"""
import math
import os
import shutil
import sys

from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade


def main():
    args = [a for a in sys.argv[1:] if a != "--ies"]
    ies = "--ies" in sys.argv[1:]
    path = args[0] if args else "shaped_ceiling.usda"
    n = int(args[1]) if len(args) > 1 else 60
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.Xform.Define(stage, "/World")
    floor = UsdGeom.Mesh.Define(stage, "/World/Floor")
    floor.CreatePointsAttr([(-12, 0, -12), (-12, 0, 12), (12, 0, 12), (12, 0, -12)])
    floor.CreateFaceVertexCountsAttr([4])
    floor.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    mat = UsdShade.Material.Define(stage, "/World/Looks/Grey")
    sh = UsdShade.Shader.Define(stage, "/World/Looks/Grey/Surface")
    sh.CreateIdAttr("UsdPreviewSurface")
    sh.CreateInput("useSpecularWorkflow", Sdf.ValueTypeNames.Int).Set(1)
    sh.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.7, 0.7, 0.7))
    sh.CreateInput("specularColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0, 0, 0))
    mat.CreateSurfaceOutput().ConnectToSource(sh.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(floor.GetPrim()).Bind(mat)
    # The ceiling: n × n quads of side 0.12 on a 20 × 20 grid, 2.5 above the floor, in the
    # light's frame (its −Z down after rotateX −90: local z = −world y offset 0).
    points, counts, indices = [], [], []
    half, pitch, side = 10.0, 20.0 / n, 0.12
    for i in range(n):
        for j in range(n):
            x, y = -half + pitch * (i + 0.5), -half + pitch * (j + 0.5)
            k = len(points)
            # Counter-clockwise seen from below (local −Z): the front faces the floor.
            dz = side * math.tan(math.radians(30.0)) if ies else 0.0
            points += [(x - side, y - side, dz), (x - side, y + side, 0.0 - dz), (x + side, y + side, 0.0 - dz),
                       (x + side, y - side, dz)]
            counts.append(4)
            indices += [k, k + 1, k + 2, k + 3]
    ceiling = UsdGeom.Mesh.Define(stage, "/World/Ceiling")
    ceiling.CreatePointsAttr(points)
    ceiling.CreateFaceVertexCountsAttr(counts)
    ceiling.CreateFaceVertexIndicesAttr(indices)
    x = UsdGeom.Xformable(ceiling)
    x.AddTranslateOp().Set(Gf.Vec3d(0, 2.5, 0))
    x.AddRotateXOp().Set(-90.0)
    UsdLux.MeshLightAPI.Apply(ceiling.GetPrim())
    UsdLux.LightAPI(ceiling.GetPrim()).CreateIntensityAttr(40.0)
    s = UsdLux.ShapingAPI.Apply(ceiling.GetPrim())
    s.CreateShapingConeAngleAttr(20.0)
    s.CreateShapingConeSoftnessAttr(0.2)
    if ies:
        here = os.path.dirname(os.path.abspath(__file__))
        folder = os.path.join(os.path.dirname(os.path.abspath(path)), "ies")
        os.makedirs(folder, exist_ok=True)
        shutil.copy(os.path.join(here, "..", "scenes", "ies", "bilateral_1995.ies"), folder)
        s.CreateShapingIesFileAttr(Sdf.AssetPath("ies/bilateral_1995.ies"))
    cam = UsdGeom.Camera.Define(stage, "/World/Camera")
    o, t = Gf.Vec3d(0, 9, 9), Gf.Vec3d(0, 0, 0)
    back = (o - t).GetNormalized()
    right = Gf.Cross(Gf.Vec3d(0, 1, 0), back).GetNormalized()
    up = Gf.Cross(back, right)
    m = Gf.Matrix4d(*right, 0, *up, 0, *back, 0, *o, 1)
    UsdGeom.Xformable(cam).AddTransformOp().Set(m)
    cam.CreateVerticalApertureAttr(20.0)
    cam.CreateHorizontalApertureAttr(20.0)
    cam.CreateFocalLengthAttr(10.0 / math.tan(math.radians(30.0)))
    stage.GetRootLayer().Save()


if __name__ == "__main__":
    main()
