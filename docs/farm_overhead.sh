#!/usr/bin/env bash
# The cost of tiling (docs/farm.md, "Overhead"): a frame rendered in one process, then as 4, 16
# and 64 tiles in one process each, one after the other, all at one thread; per split the sum
# over the processes of their CPU time (user + system, /usr/bin/time), of the render's
# (render_cpu_seconds), the environment's (env_cpu_seconds: reading the map, the equal-area
# resampling and the pyramid) and the scene load's (load_cpu_seconds) from --stats-json, the
# rest (start-up, BVH, writing the files), the sum of wall clocks, the largest and the mean
# resident set (/usr/bin/time), and whether the merge is the frame byte for byte. CPU time, not
# wall clock: on a machine shared with other work a process's wall clock grows with the load.
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
  /usr/bin/time -f "%e %U %S %M" -a -o "$name.time" "$ppis" render "${scene[@]}" "${frame[@]}" "$@" \
    --stats-json "$name.$RANDOM$RANDOM.json" 2>/dev/null
}
sum() { # sum PREFIX: over PREFIX's processes, CPU s (all, render, env, load, rest), wall s, RSS MB
  python3 - "$1" <<'PY'
import glob, json, sys
p = sys.argv[1]
times = [[float(x) for x in l.split()] for l in open(p + ".time") if l[0].isdigit()]
stats = [json.load(open(f)) for f in glob.glob(p + ".*.json")]
cpu = sum(t[1] + t[2] for t in times)
render = sum(s["render_cpu_seconds"] for s in stats)
env = sum(s["env_cpu_seconds"] or 0.0 for s in stats)
load = sum(s["load_cpu_seconds"] for s in stats)
rss = [t[3] / 1024 for t in times]
print("%-6s %5d %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %7.1f %7.1f" % (p, len(times), cpu, render, env, load,
      cpu - render - env - load, sum(t[0] for t in times), max(rss), sum(rss) / len(rss)))
PY
}
echo "split  procs    CPU s   render      env     load     rest   wall s  maxRSS meanRSS"
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
