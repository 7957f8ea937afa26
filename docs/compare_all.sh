#!/usr/bin/env bash
# Every method against Mitsuba 3 on the three shared scenes and our two (docs/stability.md).
# Needs ../shared/ (scenes, maps, mitsuba_ref.py), `pip install mitsuba numpy` and, for the
# fast llvm variant, `apt-get install libllvm19`. Usage: docs/compare_all.sh OUT_DIR [SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:?output folder}"
spp="${2:-4096}"
mkdir -p "$out"
python3 docs/scenes/make_scenes.py > /dev/null
cargo build --release -p host-std --bin ppis
scenes=(../shared/scenes/s1_forest_spheres.json ../shared/scenes/s2_courtyard_glossy.json
        ../shared/scenes/s3_sunset_sharp.json docs/scenes/furnace.json docs/scenes/sharp_sun.json)
methods=(product wavelet env brdf mis product-mis ris two-stage auto)
for scene in "${scenes[@]}"; do
    name="$(basename "$scene" .json)"
    if [ ! -f "$out/${name}_mts.exr" ]; then
        python3 ../shared/reference/mitsuba_ref.py "$scene" --spp 4096 --passes 4 \
            --out "$out/${name}_mts.exr" --stderr-out "$out/${name}_mts_se.exr" \
            --coverage-out "$out/${name}_cov.exr" | tail -1
    fi
    for m in "${methods[@]}"; do
        ./target/release/ppis render "$scene" --method "$m" --spp "$spp" --shading-points 64 \
            -o "$out/${name}_$m.exr" 2>&1 | tail -1 | sed 's/; wrote.*//'
        printf '%s %s: ' "$name" "$m"
        python3 docs/compare_mitsuba.py "$out/${name}_$m.exr" "$out/${name}_mts.exr" \
            "$out/${name}_cov.exr" "$out/${name}_mts_se.exr" | tr '\n' ' '
        echo
    done
done
