"""Runs the pods of deploy/kubernetes/ppis-tiles.yaml on this machine, without a cluster: for
each Job in order (ppis-env, ppis-tiles, ppis-merge) and each completion index, the container's
`bash -c` script with the container's env, JOB_COMPLETION_INDEX set as Kubernetes sets it,
`ppis` first on the PATH and the volume's mount path (/renders) replaced by a temporary folder.
The frame settings are replaced by a small frame of host-usd's animated test stage (its parent
turns, its sphere moves and grows, its camera rises) lit by a small lat-long map that ppis-env
caches. Then compares each merged frame byte for byte with `ppis render --frame F` of the whole
frame, and checks that the two frames differ.

    python3 deploy/kubernetes/check_local.py PPIS
"""

import filecmp
import os
import subprocess
import sys
import tempfile

import yaml

here = os.path.dirname(os.path.abspath(__file__))
fixtures = os.path.join(here, "..", "..", "host-usd", "tests", "fixtures")
ppis = os.path.abspath(sys.argv[1])
frame_args = "%s --width 96 --height 64" % os.path.join(fixtures, "animated.usda")
render_args = "--method product-mis --spp 8 --seed 3"
with open(os.path.join(here, "ppis-tiles.yaml")) as f:
    jobs = list(yaml.safe_load_all(f))
with tempfile.TemporaryDirectory() as root:
    replaced = {"FRAME_ARGS": frame_args, "RENDER_ARGS": render_args,
                "ENV_SOURCE": os.path.join(fixtures, "twins_env.exr")}
    for job in jobs:
        spec = job["spec"]
        pod = spec["template"]["spec"]
        container = pod["containers"][0]
        mount = container["volumeMounts"][0]["mountPath"]
        env = dict(os.environ, PATH=os.path.dirname(ppis) + os.pathsep + os.environ["PATH"])
        env.update({e["name"]: e["value"] for e in container["env"]})
        env.update({k: v for k, v in replaced.items() if k in env})
        script = container["args"][0].replace(mount, root)
        for index in range(spec.get("completions", 1)):
            if spec.get("completionMode") == "Indexed":
                env["JOB_COMPLETION_INDEX"] = str(index)
            subprocess.run(container["command"] + [script], env=env, check=True, stderr=subprocess.DEVNULL)
        print("job %s: %d pods ran" % (job["metadata"]["name"], spec.get("completions", 1)))
    merged = {}
    for frame in (1, 2):
        whole = os.path.join(root, "whole%d.exr" % frame)
        cached = ["--env", os.path.join(root, "out", "env.exr"), "--frame", str(frame)]
        subprocess.run([ppis, "render"] + frame_args.split() + cached + render_args.split() + ["-o", whole],
                       check=True, stderr=subprocess.DEVNULL)
        for ext in ("exr", "png"):
            path = os.path.join(root, "out", "frame%d.%s" % (frame, ext))
            same = filecmp.cmp(path, whole[:-3] + ext, shallow=False)
            print("frame %d .%s: %s" % (frame, ext, "the same bytes as the one-process render" if same else "DIFFERS"))
            if not same:
                sys.exit(1)
        merged[frame] = open(os.path.join(root, "out", "frame%d.exr" % frame), "rb").read()
    if merged[1] == merged[2]:
        sys.exit("frames 1 and 2 are the same: the frame did not reach the renders")
    print("frames 1 and 2 differ (the stage is animated)")
