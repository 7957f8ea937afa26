#!/usr/bin/env python3
"""Peak memory and CPU time of `ppis info` on the corpus, beside Pixar's library.

For each kind, format and size of a corpus written by `host-usd/tests/corpus/make_corpus.py`
(`<kind>_<n>.<format>` in DIR), R runs of `ppis info FILE` and of Pixar's `Usd.Stage.Open`
plus a traversal computing every gprim's world transform (import_bench.py's), each under
`setarch -R` (address-space randomisation off: the 10-prim floor, mostly the pages of the
executable and libraries that the process maps, then moves by a few KiB instead of half a
MiB). Prints a Markdown table: the least peak RSS (`/usr/bin/time`) and the least CPU time
(user + system for `ppis`, `process_time` around Pixar's open and traversal), and bytes per
prim above the 10-prim file of the same kind and format, divided by the added prims.

    python3 host-usd/bench/corpus_memory.py PPIS DIR [--runs R] [--kinds spheres,…]
        [--formats usda,usdc,usdz] [--sizes 1000,10000,100000]

Sizes whose files are missing from DIR are left out.
"""
import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from import_bench import PIXAR  # noqa: E402


def least(cmd, runs, cpu_of):
    """(least peak RSS in bytes, least CPU seconds) of `cmd` over `runs` runs."""
    rss, cpu = [], []
    for _ in range(runs):
        r = subprocess.run(["setarch", "-R", "/usr/bin/time", "-f", "%M %U %S"] + cmd,
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} failed: {r.stderr[-400:]}")
        m, u, s = r.stderr.strip().splitlines()[-1].split()
        rss.append(int(m) * 1024)
        cpu.append(cpu_of(r.stdout, float(u) + float(s)))
    return min(rss), min(cpu)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ppis")
    ap.add_argument("dir")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--kinds", default="spheres,meshes_varying,meshes_identical")
    ap.add_argument("--formats", default="usda,usdc,usdz")
    ap.add_argument("--sizes", default="1000,10000,100000")
    a = ap.parse_args()
    print("| file | ppis CPU s | Pixar CPU s | CPU ratio | ppis bytes/prim | Pixar bytes/prim |")
    print("|---|---:|---:|---:|---:|---:|")
    ours = [a.ppis, "info"]
    pixar = [sys.executable, "-c", PIXAR]
    for kind in a.kinds.split(","):
        for fmt in a.formats.split(","):
            base = os.path.join(a.dir, f"{kind}_10.{fmt}")
            if not os.path.exists(base):
                continue
            floor = least(ours + [base], a.runs, lambda _, t: t)[0]
            pixar_floor = least(pixar + [base], a.runs, lambda out, _: float(out.split()[1]))[0]
            for n in [int(s) for s in a.sizes.split(",")]:
                path = os.path.join(a.dir, f"{kind}_{n}.{fmt}")
                if not os.path.exists(path):
                    continue
                rss, cpu = least(ours + [path], a.runs, lambda _, t: t)
                prss, pcpu = least(pixar + [path], a.runs, lambda out, _: float(out.split()[1]))
                per, pper = (rss - floor) / (n - 10), (prss - pixar_floor) / (n - 10)
                print(f"| {os.path.basename(path)} | {cpu:.2f} | {pcpu:.2f} | {cpu / max(pcpu, 1e-9):.2f} "
                      f"| {per:.0f} | {pper:.0f} |", flush=True)


if __name__ == "__main__":
    main()
