#!/usr/bin/env bash
# Queues a frame range as ppis tiles on Slurm: the tile array, then the merge array once every
# tile has succeeded (--dependency=afterok). docs/farm.md.
#   PPIS=/farm/bin/ppis OUT=/farm/renders/shot FIRST=1 LAST=24 TILES=16 \
#   FRAME_ARGS="/farm/shot.usd --width 1920 --height 1080" RENDER_ARGS="--spp 64" \
#   deploy/slurm/submit.sh [SBATCH OPTIONS…]
# Options given are passed to both sbatch calls (they override the scripts' #SBATCH lines:
# --partition, --cpus-per-task, --mem…).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
: "${PPIS:?}" "${OUT:?}" "${FIRST:?}" "${LAST:?}" "${TILES:?}"
export PPIS OUT FIRST TILES FRAME_ARGS="${FRAME_ARGS-}" RENDER_ARGS="${RENDER_ARGS-}"
frames=$((LAST - FIRST + 1))
tiles=$(sbatch --parsable --export=ALL "$@" --array=0-$((frames * TILES - 1)) "$here/ppis-tiles.sbatch")
sbatch --parsable --export=ALL "$@" --dependency="afterok:${tiles%%;*}" --array=0-$((frames - 1)) "$here/ppis-merge.sbatch"
