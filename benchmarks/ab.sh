#!/usr/bin/env bash
# A/B throughput of two sppm binaries: `sppm bench --model elastic|tension|full` at 1e5 and
# 1e6 particles on 2 threads, the two binaries interleaved run by run (RUNS runs each, default
# 5), printing each row's medians, the ratio NEW/OLD of the medians and, as a check on drift,
# the median of the run-by-run ratios (each run of NEW over the run of OLD beside it).
#
#   bash benchmarks/ab.sh OLD_BIN NEW_BIN [RUNS]
#
# Extra arguments for either binary (e.g. --scalar for NEW only) go in OLD_ARGS / NEW_ARGS.
set -euo pipefail
old=${1:?usage: ab.sh OLD_BIN NEW_BIN [RUNS]}
new=${2:?usage: ab.sh OLD_BIN NEW_BIN [RUNS]}
runs=${3:-5}
steps_for() { if [ "$1" -ge 1000000 ]; then echo 40; else echo 400; fi; }
rate() { python3 -c 'import json,sys; print(json.loads(sys.stdin.read().strip().splitlines()[-1])["particle_steps_per_s"])'; }
echo "| model | particles | old median (M particle-steps/s) | new median (M particle-steps/s) | new/old | median of paired ratios |"
echo "|---|---|---|---|---|---|"
for model in elastic tension full; do
  for n in 100000 1000000; do
    steps=$(steps_for "$n")
    a=(); b=()
    for r in $(seq "$runs"); do
      # alternate which binary goes first, so that drift hits both alike
      if [ $((r % 2)) -eq 1 ]; then
        a+=("$("$old" bench --model "$model" --particles "$n" --steps "$steps" --threads 2 ${OLD_ARGS:-} | rate)")
        b+=("$("$new" bench --model "$model" --particles "$n" --steps "$steps" --threads 2 ${NEW_ARGS:-} | rate)")
      else
        b+=("$("$new" bench --model "$model" --particles "$n" --steps "$steps" --threads 2 ${NEW_ARGS:-} | rate)")
        a+=("$("$old" bench --model "$model" --particles "$n" --steps "$steps" --threads 2 ${OLD_ARGS:-} | rate)")
      fi
    done
    python3 -c "
import statistics, sys
model, n, runs = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
a = [float(v) for v in sys.argv[4:4 + runs]]
b = [float(v) for v in sys.argv[4 + runs:]]
ma, mb = statistics.median(a), statistics.median(b)
pr = statistics.median(y / x for x, y in zip(a, b))
print(f'| {model} | {n:,} | {ma/1e6:.2f} | {mb/1e6:.2f} | {mb/ma:.3f} | {pr:.3f} |')
" "$model" "$n" "$runs" "${a[@]}" "${b[@]}"
  done
done
