#!/usr/bin/env bash
# Converge the single techniques (env, brdf, two-stage) against Mitsuba 3 where 4096 samples per
# pixel at 256×256 are not enough (docs/stability.md). The same scenes at a lower resolution
# (same camera, box-filtered over larger pixels) cost fewer samples in all, so each pixel can get
# 10⁵–10⁶ of them. Needs what docs/compare_all.sh needs.
# Usage: docs/converge_single.sh OUT_DIR [RES] [SPP] [SCENE...]
set -euo pipefail
cd "$(dirname "$0")/.."
source docs/compare_scene.sh
out="${1:?output folder}"
res="${2:-32}"
spp="${3:-1048576}"
shift $(($# < 3 ? $# : 3))
scenes=("$@")
if [ ${#scenes[@]} -eq 0 ]; then
    scenes=(docs/scenes/s1_forest_spheres.json docs/scenes/s2_courtyard_glossy.json
            docs/scenes/s3_sunset_sharp.json docs/scenes/sharp_sun.json)
fi
methods=(${METHODS:-env brdf two-stage})
mkdir -p "$out"
python3 docs/scenes/make_scenes.py > /dev/null
cargo build --release -p host-std --bin ppis
for scene in "${scenes[@]}"; do
    name="$(basename "$scene" .json)_${res}"
    # The scene at RES×RES, its map path made absolute so the copy can live in OUT_DIR.
    python3 - "$scene" "$res" "$out/$name.json" <<'PY'
import json, os, sys
src, res, dst = sys.argv[1], int(sys.argv[2]), sys.argv[3]
scene = json.load(open(src))
scene["camera"]["width"] = scene["camera"]["height"] = res
env = scene["envmap"]["file"]
scene["envmap"]["file"] = os.path.abspath(os.path.join(os.path.dirname(src), env))
json.dump(scene, open(dst, "w"), indent=1)
PY
    compare_scene "$out" "$out/$name.json" "$name" "$spp" "$spp" 1024 "${methods[@]}"
done
