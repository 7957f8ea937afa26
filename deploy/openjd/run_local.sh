#!/usr/bin/env bash
# Runs deploy/openjd/ppis-tiles.yaml end to end on this machine with Open Job Description's
# reference runner (`openjd run`, from `pip install openjd-cli`): host-usd's animated test stage
# (its parent turns, its sphere moves and grows, its camera rises), lit by a small lat-long map
# that step BuildEnv caches, 2 frames of 4 tiles each; then compares each merged frame byte for
# byte with the frame `ppis render --frame F` writes in one process, and checks that the two
# frames differ. Usage: deploy/openjd/run_local.sh [PPIS] (default: target/release/ppis, or
# $CARGO_TARGET_DIR/release/ppis). Exits non-zero when a frame differs.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
ppis="$(realpath "${1:-${CARGO_TARGET_DIR:-$here/../../target}/release/ppis}")"
fixtures="$(realpath "$here/../../host-usd/tests/fixtures")"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
settings=("$fixtures/animated.usda" --width 160 --height 96 --method product-mis --spp 8 --seed 3)

openjd run "$here/ppis-tiles.yaml" --step Merge --run-dependencies \
  -p Ppis="$ppis" -p OutDir="$out" -p Frames=1-2 -p TileCount=4 -p Scene="$fixtures/animated.usda" \
  -p Env="$fixtures/twins_env.exr" -p Width=160 -p Height=96 -p Method=product-mis -p Spp=8 -p Seed=3

for frame in 1 2; do
  "$ppis" render "${settings[@]}" --env "$out/env.exr" --frame $frame -o "$out/whole$frame.exr" 2>/dev/null
  ls "$out"/frame$frame.tile*.exr
  cmp "$out/frame$frame.exr" "$out/whole$frame.exr"
  cmp "$out/frame$frame.png" "$out/whole$frame.png"
  echo "frame $frame: $(sha256sum < "$out/frame$frame.exr" | cut -c1-16)… the same bytes as the one-process render"
done
if cmp -s "$out/frame1.exr" "$out/frame2.exr"; then
  echo "frames 1 and 2 are the same: the frame did not reach the renders" >&2
  exit 1
fi
echo "frames 1 and 2 differ (the stage is animated)"
