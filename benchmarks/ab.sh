#!/usr/bin/env bash
# A/B throughput of two sppm binaries: `sppm bench --model elastic|tension|full` at 1e5 and
# 1e6 particles on 2 threads, the two binaries interleaved run by run (RUNS runs each, default
# 5), printing each row's medians and the ratio NEW/OLD of the medians.
#
#   bash benchmarks/ab.sh OLD_BIN NEW_BIN [RUNS]
#
# Extra arguments for both binaries (e.g. --layout csr for NEW only) go in OLD_ARGS / NEW_ARGS.
set -euo pipefail
old=${1:?usage: ab.sh OLD_BIN NEW_BIN [RUNS]}
new=${2:?usage: ab.sh OLD_BIN NEW_BIN [RUNS]}
runs=${3:-5}
steps_for() { if [ "$1" -ge 1000000 ]; then echo 40; else echo 400; fi; }
rate() { python3 -c 'import json,sys; print(json.loads(sys.stdin.read().strip().splitlines()[-1])["particle_steps_per_s"])'; }
median() { python3 -c 'import statistics,sys; print(statistics.median(float(x) for x in sys.argv[1:]))' "$@"; }
echo "| model | particles | old median (M particle-steps/s) | new median (M particle-steps/s) | new/old |"
echo "|---|---|---|---|---|"
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
    ma=$(median "${a[@]}"); mb=$(median "${b[@]}")
    python3 -c "import sys; a,b=float(sys.argv[1]),float(sys.argv[2]); print(f'| {sys.argv[3]} | {int(sys.argv[4]):,} | {a/1e6:.2f} | {b/1e6:.2f} | {b/a:.3f} |')" "$ma" "$mb" "$model" "$n"
  done
done
