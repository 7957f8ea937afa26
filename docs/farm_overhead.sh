#!/usr/bin/env bash
# The cost of tiling (docs/farm.md, "Overhead"): a frame rendered in one process, then as 4, 16
# and 64 tiles in one process each, one after the other, all at one thread; per split the sum of
# the processes' wall clocks, of their render_seconds and env_build_seconds (--stats-json), the
# largest resident set (/usr/bin/time), and whether the merge is the frame byte for byte.
# Usage: docs/farm_overhead.sh PPIS [SCENE [ARGS…]] (SCENE: a JSON or USD file, default the
# built-in; ARGS go to every `ppis render` and `ppis tiles`, e.g. `--env SQUARE.exr
# --env-rotate-y 30` for the environment cached by `ppis env`: give its path absolute).
set -euo pipefail
ppis="$(realpath "$1")"
scene=(); if [ -n "${2:-}" ]; then scene=("$(realpath "$2")"); fi
scene+=("${@:3}")
frame=(--width 640 --height 360 --spp 8 --threads 1)
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
cd "$dir"
run() { # run NAME ARGS…: one process, its wall clock and max RSS appended to NAME.time
  local name=$1; shift
  /usr/bin/time -f "%e %M" -a -o "$name.time" "$ppis" render "${scene[@]}" "${frame[@]}" "$@" \
    --stats-json "$name.$RANDOM$RANDOM.json" 2>/dev/null
}
sum() { # sum PREFIX: wall, render, env build, max RSS over PREFIX's processes
  python3 - "$1" <<'PY'
import glob, json, sys
p = sys.argv[1]
times = [l.split() for l in open(p + ".time")]
stats = [json.load(open(f)) for f in glob.glob(p + ".*.json")]
print("%-6s %5d %8.2f %8.2f %8.3f %7.1f" % (p, len(times), sum(float(t[0]) for t in times),
      sum(s["render_seconds"] for s in stats), sum(s["env_build_seconds"] for s in stats),
      max(int(t[1]) for t in times) / 1024))
PY
}
echo "split  procs   wall s render s  env s  max RSS MB"
run frame -o frame.exr
sum frame
for n in 4 16 64; do
  for crop in $("$ppis" tiles "${scene[@]}" --width 640 --height 360 --count "$n"); do
    run "t$n" --crop "$crop" -o "t$n.$crop.exr"
  done
  sum "t$n"
  "$ppis" merge t"$n".*.exr -o "m$n.exr" 2>/dev/null
  if ! cmp -s "m$n.exr" frame.exr; then echo "merge of $n differs"; exit 1; fi
  echo "       merge of $n: the frame's bytes"
done
