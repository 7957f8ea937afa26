#!/usr/bin/env python3
"""Import time of `ppis info` and Pixar's library back to back, wall clock and CPU time.

For each FILE, R times: `ppis info FILE` (wall clock; user + system CPU time and peak RSS by
`/usr/bin/time`), then Pixar's `Usd.Stage.Open` plus a traversal computing every gprim's
world transform (as import_bench.py; `process_time` for its CPU time; the Python process's
peak RSS, the interpreter and the `pxr` import included, by `/usr/bin/time`). Prints the minimum of
each column and the ratios, a Markdown table. On a shared machine the CPU-time ratio is the
steadier one.

    python3 host-usd/bench/back_to_back.py PPIS R FILE...

The files come from import_bench.py (its --dir).
"""
import subprocess, sys, time, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from import_bench import PIXAR  # Pixar's import and traversal: wall s, CPU s, gprims
ppis = sys.argv[1]; R = int(sys.argv[2]); files = sys.argv[3:]
print("| file | ppis s | Pixar s | ratio | ppis CPU s | Pixar CPU s | CPU ratio | peak MB | Pixar peak MB |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for f in files:
    pw=[];pc=[];xw=[];xc=[];rss=[];xrss=[]
    for _ in range(R):
        t=time.perf_counter()
        r=subprocess.run(["/usr/bin/time","-f","%U %S %M",ppis,"info",f],capture_output=True,text=True)
        pw.append(time.perf_counter()-t)
        assert r.returncode==0, r.stderr[-500:]
        u,s,m=r.stderr.strip().splitlines()[-1].split()
        pc.append(float(u)+float(s)); rss.append(int(m)*1024)
        x=subprocess.run(["/usr/bin/time","-f","%M",sys.executable,"-c",PIXAR,f],capture_output=True,text=True)
        xw.append(float(x.stdout.split()[0])); xc.append(float(x.stdout.split()[1]))
        xrss.append(int(x.stderr.strip().splitlines()[-1])*1024)
    name=os.path.basename(f)
    print(f"| {name} | {min(pw):.3f} | {min(xw):.3f} | {min(pw)/min(xw):.2f} | {min(pc):.2f} | {min(xc):.2f} | {min(pc)/min(xc):.2f} | {min(rss)/2**20:.1f} | {min(xrss)/2**20:.1f} |",flush=True)
