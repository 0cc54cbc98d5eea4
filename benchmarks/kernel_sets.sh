#!/usr/bin/env bash
# Throughput of the three step kernels (elastic; tension: tensile damage only; full: damage
# and plasticity) at 1e5 and 1e6 particles on 2 threads, interleaved run by run so that the
# ratios come from the same conditions: the median of REPEATS runs each, and the speed-up of
# each kernel over the full one.
# Usage: benchmarks/kernel_sets.sh [REPEATS] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
repeats=${1:-5}
threads=${2:-2}
cargo build --release --quiet
bin=target/release/sppm
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
printf '%-10s %-8s %-6s %-16s %-10s %s\n' particles kernel steps "median p-steps/s" "vs full" "all runs"
for n in 100000 1000000; do
  steps=$(( 20000000 / n )); [ "$steps" -lt 20 ] && steps=20
  declare -A runs=()
  for _ in $(seq "$repeats"); do
    for m in elastic tension full; do
      r=$("$bin" bench --particles "$n" --steps "$steps" --threads "$threads" --model "$m" |
        sed -E 's/.*"particle_steps_per_s":([0-9.e+-]+).*/\1/')
      runs[$m]="${runs[$m]:-} $r"
    done
  done
  full=$(printf '%s\n' ${runs[full]} | median)
  for m in elastic tension full; do
    med=$(printf '%s\n' ${runs[$m]} | median)
    printf '%-10s %-8s %-6s %-16.4g %-10.2f %s\n' "$n" "$m" "$steps" "$med" \
      "$(awk -v a="$med" -v b="$full" 'BEGIN {print a / b}')" "$(printf '%.3g ' ${runs[$m]})"
  done
  unset runs
done
