#!/usr/bin/env bash
# The random-particle tension prism (lattices/tension_prism_3d.toml with random particles)
# on several particle sets, with the default scheme (bond dampers wholly explicit, the ramp
# read in time) against the fast options (semi-implicit bond dampers, adaptive pace).
# Prints, per set and variant: steps, Δt, wall time,
# peak, dissipated and damper energy, K/U around the peak; then the means per variant and
# their ratios to the first variant.
# Usage: benchmarks/dampers_and_pace.sh [sets] [spacing]     (default 5 sets at 15 mm)
# SPPM=path runs that binary instead of building; OUT=dir keeps the outputs.
set -euo pipefail
cd "$(dirname "$0")/.."
sets=${1:-5}
spacing=${2:-0.015}
if [ -z "${SPPM:-}" ]; then cargo build --release --quiet; fi
bin=${SPPM:-target/release/sppm}
out=${OUT:-/tmp/sppm-dampers-and-pace}
declare -A variants=(
  [source]=""
  [semi_fixed]="--set damping.bond_scheme=semi_implicit"
  [fast]="--set damping.bond_scheme=semi_implicit --set loading.pace=adaptive"
)
order=(source semi_fixed fast)
for seed in $(seq 1 "$sets"); do
  for v in "${order[@]}"; do
    dir="$out/$v-$seed"
    [ -f "$dir/summary.json" ] && continue
    # shellcheck disable=SC2086
    "$bin" run lattices/tension_prism_3d.toml --quiet --threads 2 \
      --set discretisation.lattice=random --set discretisation.spacing="$spacing" \
      --set seed="$seed" ${variants[$v]} --out "$dir" || true
  done
done
python3 - "$out" "$sets" "${order[@]}" <<'PY'
import json, sys, statistics as st
out, sets, order = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
keys = ["steps", "dt_s", "wall_time_s", "peak_force_N", "dissipated_energy_J", "damping_energy_J", "max_kinetic_to_internal_energy"]
print(f"{'variant':12s} {'set':>3s} {'steps':>8s} {'dt s':>10s} {'wall s':>8s} {'peak kN':>8s} {'W_d J':>7s} {'damp J':>7s} {'K/U':>8s}")
means = {}
for v in order:
    rows = []
    for seed in range(1, sets + 1):
        s = json.load(open(f"{out}/{v}-{seed}/summary.json"))
        rows.append([s[k] for k in keys])
        r = rows[-1]
        print(f"{v:12s} {seed:3d} {r[0]:8d} {r[1]:10.3e} {r[2]:8.1f} {r[3]/1e3:8.2f} {r[4]:7.4f} {r[5]:7.4f} {r[6]:8.2e}")
    means[v] = [st.mean(c) for c in zip(*rows)]
print()
base = means[order[0]]
for v in order:
    m = means[v]
    print(f"mean {v:12s} steps {m[0]:9.0f} wall {m[2]:7.1f} s  peak {m[3]/1e3:7.2f} kN ({m[3]/base[3]:.4f})  W_d {m[4]:.4f} J ({m[4]/base[4]:.4f})  damp {m[5]:.4f} J  K/U {m[6]:.2e}  steps ratio {base[0]/m[0]:.2f}  wall ratio {base[2]/m[2]:.2f}")
PY
