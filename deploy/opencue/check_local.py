"""Checks deploy/opencue/ppis_tiles.py without a cuebot: builds the outline with PyOutline
(`pip install opencue-pyoutline`), serializes it to OpenCue's job specification (XML), and runs
every frame of its layers on this machine in dependency order through PyOutline's own shell-out
(`outline.io.system`, which replaces the %{FRAME} token as a render host does), then compares
each merged frame byte for byte with `ppis render --frame F` of the whole frame. The job renders
host-usd's animated test stage (its parent turns, its sphere moves and grows, its camera rises)
lit by a small lat-long map that layer `env` caches; the two frames must differ.

    python3 deploy/opencue/check_local.py PPIS
"""

import filecmp
import os
import subprocess
import sys
import tempfile
import xml.dom.minidom

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import outline.backend.cue  # noqa: E402
import outline.io  # noqa: E402
from outline import cuerun  # noqa: E402

import ppis_tiles  # noqa: E402

ppis = os.path.abspath(sys.argv[1])
fixtures = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "host-usd", "tests", "fixtures")
scene = os.path.join(fixtures, "animated.usda")
with tempfile.TemporaryDirectory() as out:
    args = ppis_tiles.parse(["--ppis", ppis, "--out", out, "--frames", "1-2", "--tiles", "4", "--scene", scene,
                             "--env", os.path.join(fixtures, "twins_env.exr"),
                             "--width", "96", "--height", "64", "--spp", "8", "--seed", "2"])
    ol = ppis_tiles.build(args)
    spec = outline.backend.cue.serialize(cuerun.OutlineLauncher(ol, user="ppis", nomail=True))
    dom = xml.dom.minidom.parseString(spec)
    for layer in dom.getElementsByTagName("layer"):
        name = layer.getAttribute("name")
        rng = layer.getElementsByTagName("range")[0].firstChild.data
        print("layer %s: range %s" % (name, rng))
    for depend in dom.getElementsByTagName("depend"):
        print("depend %s: %s → %s" % (
            depend.getAttribute("type"),
            depend.getElementsByTagName("depjob")[0].firstChild.data if depend.getElementsByTagName("depjob") else "",
            " ".join(e.tagName + "=" + (e.firstChild.data if e.firstChild else "") for e in depend.childNodes
                     if e.nodeType == e.ELEMENT_NODE)))
    for layer in ol.get_layers():  # env, render, merge: the order of the dependencies
        rng = layer.get_frame_range()
        first, last = (int(f) for f in rng.split("-")) if "-" in rng else (int(rng),) * 2
        for frame in range(first, last + 1):
            outline.io.system(layer.get_arg("command"), frame=frame)
    merged = {}
    for frame in (1, 2):
        whole = os.path.join(out, "whole%d.exr" % frame)
        subprocess.run([ppis, "render", scene, "--width", "96", "--height", "64", "--env", os.path.join(out, "env.exr"),
                        "--frame", str(frame), "--spp", "8", "--seed", "2", "--method", "product-mis", "-o", whole],
                       check=True)
        for ext in ("exr", "png"):
            same = filecmp.cmp(os.path.join(out, "frame%d.%s" % (frame, ext)), whole[:-3] + ext, shallow=False)
            print("frame %d .%s: %s" % (frame, ext, "the same bytes as the one-process render" if same else "DIFFERS"))
            if not same:
                sys.exit(1)
        merged[frame] = open(os.path.join(out, "frame%d.exr" % frame), "rb").read()
    if merged[1] == merged[2]:
        sys.exit("frames 1 and 2 are the same: the frame did not reach the renders")
    print("frames 1 and 2 differ (the stage is animated)")
