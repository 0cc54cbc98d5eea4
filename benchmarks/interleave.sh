#!/usr/bin/env bash
# Throughput of several sppm binaries on one `sppm bench` row, interleaved run by run with the
# order rotated each round (so that drift hits all alike). Prints, per binary, the median
# particle-steps/s, its ratio to the first binary's median and the median of the run-by-run
# ratios to the first binary.
#
#   bash benchmarks/interleave.sh MODEL PARTICLES STEPS THREADS RUNS BIN...
#
# e.g. bash benchmarks/interleave.sh elastic 1000000 40 2 7 old/sppm target/release/sppm
set -euo pipefail
model=${1:?usage: interleave.sh MODEL PARTICLES STEPS THREADS RUNS BIN...}
n=${2:?} steps=${3:?} threads=${4:?} runs=${5:?}
shift 5
bins=("$@")
[ ${#bins[@]} -ge 1 ] || { echo "interleave.sh: name at least one binary" >&2; exit 2; }
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for r in $(seq "$runs"); do
  for t in $(seq 0 $((${#bins[@]} - 1))); do
    b=${bins[$(((t + r) % ${#bins[@]}))]}
    v=$("$b" bench --model "$model" --particles "$n" --steps "$steps" --threads "$threads" |
      python3 -c 'import json,sys; print(json.loads(sys.stdin.read().strip().splitlines()[-1])["particle_steps_per_s"] / 1e6)')
    printf '%s\t%s\t%s\n' "$r" "$b" "$v" >>"$out"
  done
done
python3 - "$out" "${bins[@]}" <<'PY'
import collections, statistics as st, sys
rate = collections.defaultdict(dict)
for line in open(sys.argv[1]):
    r, b, v = line.rstrip("\n").split("\t")
    rate[b][int(r)] = float(v)
bins = sys.argv[2:]
base = rate[bins[0]]
print("| binary | median (M particle-steps/s) | ratio of medians | median of paired ratios | runs |")
print("|---|---|---|---|---|")
for b in bins:
    v = [rate[b][r] for r in sorted(rate[b])]
    m = st.median(v)
    paired = st.median(rate[b][r] / base[r] for r in base)
    print(f"| {b} | {m:.2f} | {m / st.median(base.values()):.3f} | {paired:.3f} | {' '.join(f'{x:.1f}' for x in v)} |")
PY
