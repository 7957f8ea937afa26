#!/usr/bin/env bash
# Runs deploy/openjd/ppis-tiles.yaml end to end on this machine with Open Job Description's
# reference runner (`openjd run`, from `pip install openjd-cli`): 2 frames of 4 tiles each,
# then compares each merged frame byte for byte with the frame `ppis render` writes in one
# process. Usage: deploy/openjd/run_local.sh [PPIS] (default: target/release/ppis, or
# $CARGO_TARGET_DIR/release/ppis). Exits non-zero when a frame differs.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
ppis="$(realpath "${1:-${CARGO_TARGET_DIR:-$here/../../target}/release/ppis}")"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
settings=(--width 160 --height 96 --method product-mis --spp 8 --seed 3)

openjd run "$here/ppis-tiles.yaml" --step Merge --run-dependencies \
  -p Ppis="$ppis" -p OutDir="$out" -p Frames=1-2 -p TileCount=4 \
  -p Width=160 -p Height=96 -p Method=product-mis -p Spp=8 -p Seed=3

"$ppis" render "${settings[@]}" -o "$out/whole.exr"
for frame in 1 2; do
  ls "$out"/frame$frame.tile*.exr
  cmp "$out/frame$frame.exr" "$out/whole.exr"
  cmp "$out/frame$frame.png" "$out/whole.png"
  echo "frame $frame: $(sha256sum < "$out/frame$frame.exr" | cut -c1-16)… the same bytes as the one-process render"
done
