#!/usr/bin/env bash
# A/B throughput of two sppm binaries on the 3D kernels: `sppm bench --dim 3 --model M` for
# M in MODELS (default elastic tension full) on LATTICE (fcc or random, default fcc) at N
# particles (default 1000000) and STEPS steps (default 20) on 2 threads, the two binaries
# interleaved run by run (RUNS runs each, default 5; the order alternates), printing each
# model's medians, new/old of the medians and the median of the paired ratios, and then each
# binary's median ratio of every damage model to the elastic one of the same round.
#
#   [MODELS="elastic tension"] [LATTICE=random] [N=200000] [STEPS=20] \
#     bash benchmarks/ab3d.sh OLD_BIN NEW_BIN [RUNS]
set -euo pipefail
old=${1:?usage: ab3d.sh OLD_BIN NEW_BIN [RUNS]}
new=${2:?usage: ab3d.sh OLD_BIN NEW_BIN [RUNS]}
runs=${3:-5}
models=${MODELS:-elastic tension full}
lattice=${LATTICE:-fcc}
n=${N:-1000000}
steps=${STEPS:-20}
rate() { python3 -c 'import json,sys; print(json.loads(sys.stdin.read().strip().splitlines()[-1])["particle_steps_per_s"])'; }
one() { "$1" bench --dim 3 --lattice "$lattice" --model "$2" --particles "$n" --steps "$steps" --threads 2 | rate; }
declare -A rates
for r in $(seq "$runs"); do
  for model in $models; do
    if [ $((r % 2)) -eq 1 ]; then order="old new"; else order="new old"; fi
    for b in $order; do
      if [ "$b" = old ]; then bin=$old; else bin=$new; fi
      rates[$b,$model,$r]=$(one "$bin" "$model")
    done
  done
done
args=()
for b in old new; do for model in $models; do for r in $(seq "$runs"); do
  args+=("$b,$model,$r=${rates[$b,$model,$r]}")
done; done; done
python3 - "$runs" "$lattice" "$n" "$models" "${args[@]}" <<'PY'
import statistics, sys
runs, lattice, n, models = int(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4].split()
v = {}
for a in sys.argv[5:]:
    k, x = a.split('=')
    b, m, r = k.split(',')
    v[(b, m, int(r))] = float(x)
med = lambda xs: statistics.median(xs)
print(f"lattice {lattice}, {n:,} particles requested, {runs} interleaved rounds")
print("| model | old median (M particle-steps/s) | new median | new/old | median of paired ratios | old runs | new runs |")
print("|---|---:|---:|---:|---:|---|---|")
for m in models:
    a = [v[('old', m, r)] for r in range(1, runs + 1)]
    b = [v[('new', m, r)] for r in range(1, runs + 1)]
    pr = med([y / x for x, y in zip(a, b)])
    fmt = lambda xs: ", ".join(f"{x/1e6:.2f}" for x in xs)
    print(f"| {m} | {med(a)/1e6:.2f} | {med(b)/1e6:.2f} | {med(b)/med(a):.3f} | {pr:.3f} | {fmt(a)} | {fmt(b)} |")
if 'elastic' in models:
    print()
    print("| binary | " + " | ".join(f"{m}/elastic (median of rounds)" for m in models if m != 'elastic') + " |")
    print("|---|" + "---:|" * (len(models) - 1))
    for b in ('old', 'new'):
        cells = []
        for m in models:
            if m == 'elastic':
                continue
            cells.append(f"{med([v[(b, m, r)] / v[(b, 'elastic', r)] for r in range(1, runs + 1)]):.3f}")
        print(f"| {b} | " + " | ".join(cells) + " |")
PY
