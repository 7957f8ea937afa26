#!/usr/bin/env bash
# Every method against Mitsuba 3 on s1–s3 and our two scenes (docs/stability.md), Mitsuba through
# docs/reference/mitsuba_ref.py. Needs `pip install mitsuba numpy` and, for the fast llvm variant,
# `apt-get install libllvm19` (docs/reference/README.md). Usage: docs/compare_all.sh OUT_DIR [SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
source docs/compare_scene.sh
out="${1:?output folder}"
spp="${2:-4096}"
mkdir -p "$out"
python3 docs/scenes/make_scenes.py > /dev/null
cargo build --release -p host-std --bin ppis
scenes=(docs/scenes/s1_forest_spheres.json docs/scenes/s2_courtyard_glossy.json
        docs/scenes/s3_sunset_sharp.json docs/scenes/furnace.json docs/scenes/sharp_sun.json)
methods=(product wavelet env brdf mis product-mis ris two-stage auto)
for scene in "${scenes[@]}"; do
    compare_scene "$out" "$scene" "$(basename "$scene" .json)" 4096 "$spp" 64 "${methods[@]}"
done
