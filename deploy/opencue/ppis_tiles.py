"""OpenCue job (PyOutline) for ppis: frames split into tiles.

With --env (a lat-long map replacing the scene's), layer `env` first writes its equal-area map
once (`ppis env` → OUT/env.exr), which every tile reads instead of resampling the map itself.
Layer `render` runs one OpenCue frame per (frame, tile), after `env`: its frame numbers
1..frames×tiles encode both, `ppis tiles --index` names the tile's crop for `ppis render
--crop`, and `--frame` the frame's time code (a USD stage's time samples; a JSON scene is the
same at every frame). Layer `merge` runs one OpenCue frame per frame of the range once every
render frame is done (`depend_all`): `ppis merge` assembles the frame, byte for byte the
one-process render. docs/farm.md.

    python3 deploy/opencue/ppis_tiles.py --ppis /farm/bin/ppis --out /farm/renders/shot \
        --frames 1-24 --tiles 16 [--scene /farm/shot.usd] [--env /farm/sky.exr] [--width 1920 ...]

submits it to the cuebot PyOutline's configuration names (outline.cfg, OUTLINE_CONFIG_FILE).
"""

import argparse

from outline import Outline, cuerun
from outline.modules.shell import Shell

# Runs in bash on the render host; $1 is the layer's frame number (PyOutline's %{FRAME} token),
# the rest the settings every tile and the merge share.
RENDER = r"""set -euo pipefail
task=$1 ppis=$2 out=$3 first=$4 tiles=$5; shift 5
frame=$(( first + (task - 1) / tiles )); tile=$(( (task - 1) % tiles + 1 ))
crop=$("$ppis" tiles "$@" --frame "$frame" --count "$tiles" --index $(( tile - 1 )))
"$ppis" render "$@" --frame "$frame" "${RENDER_ARGS[@]}" --crop "$crop" -o "$out/frame$frame.tile$tile.exr"
"""

ENV = r"""set -euo pipefail
ppis=$1 source=$2 out=$3
"$ppis" env "$source" -o "$out/env.exr"
"""

MERGE = r"""set -euo pipefail
frame=$1 ppis=$2 out=$3
"$ppis" merge "$out/frame$frame".tile*.exr -o "$out/frame$frame.exr"
"""


def build(args):
    """The outline: layer `env` (with --env), layer `render` over frames × tiles after it, layer
    `merge` over frames after `render`."""
    first, last = (int(f) for f in args.frames.split("-")) if "-" in args.frames else (int(args.frames),) * 2
    frames = last - first + 1
    frame_args = ([args.scene] if args.scene else []) + ["--width", str(args.width), "--height", str(args.height)]
    if args.env:
        frame_args += ["--env", "%s/env.exr" % args.out]
    render_args = ["--method", args.method, "--spp", str(args.spp), "--seed", str(args.seed)]
    # RENDER_ARGS: the settings only `ppis render` takes (bash array from the words after --).
    render_script = "RENDER_ARGS=(%s)\n%s" % (" ".join(render_args), RENDER)
    ol = Outline("ppis_tiles_%s" % args.name)
    render = Shell(
        "render",
        command=["bash", "-c", render_script, "render", "%{FRAME}", args.ppis, args.out, str(first), str(args.tiles)]
        + frame_args,
        range="1-%d" % (frames * args.tiles),
        chunk=1,
    )
    merge = Shell(
        "merge",
        command=["bash", "-c", MERGE, "merge", "%{FRAME}", args.ppis, args.out],
        range="%d-%d" % (first, last),
        chunk=1,
    )
    merge.depend_all(render)
    if args.env:
        env = Shell("env", command=["bash", "-c", ENV, "env", args.ppis, args.env, args.out], range="1", chunk=1)
        render.depend_all(env)
        ol.add_layer(env)
    ol.add_layer(render)
    ol.add_layer(merge)
    return ol


def parse(argv=None):
    """The job's settings from the command line."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ppis", default="ppis", help="the ppis executable on the render hosts")
    p.add_argument("--scene", default="", help="scene file (JSON or USD); empty: the built-in scene")
    p.add_argument("--env", default="", help="lat-long map replacing the scene's, cached once for all tiles")
    p.add_argument("--out", required=True, help="shared folder for the tiles and frames")
    p.add_argument("--frames", default="1", help="frame range, FIRST-LAST or one frame")
    p.add_argument("--tiles", type=int, default=4, help="tiles per frame")
    p.add_argument("--width", type=int, default=640)
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--method", default="product-mis")
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--name", default="shot", help="job name suffix")
    return p.parse_args(argv)


if __name__ == "__main__":
    cuerun.launch(build(parse()), use_pycuerun=True)
