#!/usr/bin/env python3
"""Realisations per hour per size from a Monte Carlo study folder (realisations.csv).

Usage: python3 benchmarks/montecarlo_rates.py output/<study> [--jobs 2]

Each realisation runs on one thread, `--jobs` at a time, so the throughput of the machine is
jobs × 3600 / (mean time of one realisation, set-up and outputs included: total_time_s).
Prints one Markdown row per size: D, particles, n, median and mean time per realisation,
realisations per hour, median iterations if known, mean/std/CoV of σN.
"""
import csv
import statistics as st
import sys

args = sys.argv[1:]
jobs = 2
if "--jobs" in args:
    i = args.index("--jobs")
    jobs = int(args[i + 1])
    del args[i : i + 2]
folder = args[0]
rows = list(csv.DictReader(open(f"{folder}/realisations.csv")))
by = {}
for r in rows:
    by.setdefault(float(r["size_D_m"]), []).append(r)
print("| D (m) | particles | n | median s/realisation | mean s | realisations/h (×%d jobs) | mean σN (MPa) | std (MPa) | CoV |" % jobs)
print("|---|---|---|---|---|---|---|---|---|")
total = 0.0
for d in sorted(by):
    rs = [r for r in by[d] if r["status"] == "completed"]
    t = [float(r["total_time_s"]) for r in by[d]]
    s = [float(r["sigma_N_Pa"]) / 1e6 for r in rs]
    mean_t = st.mean(t)
    total += mean_t
    sd = st.stdev(s) if len(s) > 1 else 0.0
    print(
        f"| {d:g} | {rs[0]['particles']} | {len(rs)} | {st.median(t):.2f} | {mean_t:.2f} | "
        f"{jobs * 3600 / mean_t:.0f} | {st.mean(s):.4f} | {sd:.4f} | {sd / st.mean(s):.4f} |"
    )
print(f"\none realisation of every size: {total:.1f} s of one thread; "
      f"100 of each on {jobs} jobs: {100 * total / jobs / 3600:.2f} h")
