#!/usr/bin/env bash
# Queues a frame range as ppis tiles on Slurm: the tile array, then the merge array once every
# tile has succeeded (--dependency=afterok). With ENV (a lat-long map replacing the scene's), a
# first job writes its equal-area map once (`ppis env` → $OUT/env.exr) and every tile reads that
# (--env $OUT/env.exr) after it. docs/farm.md.
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
after=()
if [ -n "${ENV-}" ]; then
  env_job=$(sbatch --parsable --export=ALL "$@" --job-name=ppis-env --output=ppis-env-%j.log \
    --wrap "\"$PPIS\" env \"$ENV\" -o \"$OUT/env.exr\"")
  after=(--dependency="afterok:${env_job%%;*}")
  export FRAME_ARGS="$FRAME_ARGS --env $OUT/env.exr"
fi
tiles=$(sbatch --parsable --export=ALL "$@" "${after[@]}" --array=0-$((frames * TILES - 1)) "$here/ppis-tiles.sbatch")
sbatch --parsable --export=ALL "$@" --dependency="afterok:${tiles%%;*}" --array=0-$((frames - 1)) "$here/ppis-merge.sbatch"
