"""Runs the pods of deploy/kubernetes/ppis-tiles.yaml on this machine, without a cluster: for
each Job in order (ppis-tiles, then ppis-merge) and each completion index, the container's
`bash -c` script with the container's env, JOB_COMPLETION_INDEX set as Kubernetes sets it,
`ppis` first on the PATH and the volume's mount path (/renders) replaced by a temporary folder;
the frame settings are replaced by a small frame of the built-in scene. Then compares each
merged frame byte for byte with `ppis render` of the whole frame.

    python3 deploy/kubernetes/check_local.py PPIS
"""

import filecmp
import os
import subprocess
import sys
import tempfile

import yaml

here = os.path.dirname(os.path.abspath(__file__))
ppis = os.path.abspath(sys.argv[1])
frame_args = "--width 160 --height 96"
render_args = "--method product-mis --spp 8 --seed 3"
with open(os.path.join(here, "ppis-tiles.yaml")) as f:
    jobs = list(yaml.safe_load_all(f))
with tempfile.TemporaryDirectory() as root:
    os.mkdir(os.path.join(root, "out"))
    for job in jobs:
        spec = job["spec"]
        assert spec["completionMode"] == "Indexed"
        pod = spec["template"]["spec"]
        container = pod["containers"][0]
        mount = container["volumeMounts"][0]["mountPath"]
        env = dict(os.environ, PATH=os.path.dirname(ppis) + os.pathsep + os.environ["PATH"])
        env.update({e["name"]: e["value"] for e in container["env"]})
        env.update({k: v for k, v in (("FRAME_ARGS", frame_args), ("RENDER_ARGS", render_args)) if k in env})
        script = container["args"][0].replace(mount, root)
        for index in range(spec["completions"]):
            env["JOB_COMPLETION_INDEX"] = str(index)
            subprocess.run(container["command"] + [script], env=env, check=True, stderr=subprocess.DEVNULL)
        print("job %s: %d pods ran" % (job["metadata"]["name"], spec["completions"]))
    whole = os.path.join(root, "whole.exr")
    subprocess.run([ppis, "render"] + frame_args.split() + render_args.split() + ["-o", whole], check=True,
                   stderr=subprocess.DEVNULL)
    for frame in (1, 2):
        for ext in ("exr", "png"):
            same = filecmp.cmp(os.path.join(root, "out", "frame%d.%s" % (frame, ext)), whole[:-3] + ext, shallow=False)
            print("frame %d .%s: %s" % (frame, ext, "the same bytes as the one-process render" if same else "DIFFERS"))
            if not same:
                sys.exit(1)
