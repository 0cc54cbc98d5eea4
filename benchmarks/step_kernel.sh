#!/usr/bin/env bash
# Throughput of a step kernel (particle-steps per second) at 1e4, 1e5 and 1e6 particles with
# 1 and 2 threads: the median of REPEATS runs of `sppm bench` each, all in one invocation so
# that the figures are comparable. MODEL is "elastic" (default), "tension" or "full".
# Usage: benchmarks/step_kernel.sh [REPEATS] [MODEL]
set -euo pipefail
cd "$(dirname "$0")/.."
repeats=${1:-5}
model=${2:-elastic}
cargo build --release --quiet
bin=target/release/sppm
printf '%-10s %-8s %-7s %-22s %s\n' particles threads steps "median particle-steps/s" "all runs"
for n in 10000 100000 1000000; do
  steps=$(( 50000000 / n )); [ "$steps" -lt 50 ] && steps=50
  for t in 1 2; do
    runs=()
    for _ in $(seq "$repeats"); do
      runs+=("$("$bin" bench --particles "$n" --steps "$steps" --threads "$t" --model "$model" |
        sed -E 's/.*"particle_steps_per_s":([0-9.e+-]+).*/\1/')")
    done
    median=$(printf '%s\n' "${runs[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    printf '%-10s %-8s %-7s %-22.4g %s\n' "$n" "$t" "$steps" "$median" "$(printf '%.3g ' "${runs[@]}")"
  done
done
