#!/usr/bin/env bash
# Energy dissipated in uniaxial tension against G_f × crack area (docs/model.md §8): the Table 1
# block of Nikravesh Kazeroni (2017), 150 mm wide and 150 mm thick, at L0 = 10 and 5 mm, for both readings of the
# crack opening (total, as written; inelastic, from initiation) and crack bands of 2 L0
# (4.13 as written) and 2.8 L0 (the default). HEIGHT is the block height (default 0.1 m, a
# block that separates stably; 0.3 m is docs/validation.md §B's, which snaps back after the peak).
# Usage: benchmarks/tension_energy.sh   (needs python3 to read summary.json)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
h=${HEIGHT:-0.1}
out=${OUT:-/tmp/sppm-tension-energy}
printf '%-7s %-10s %-6s %10s %10s %12s %9s %8s\n' L0 opening band "peak/ftA" "W_d J" "W_d/(Gf A)" "K/U" "wall s"
for band in 2.0 2.8; do
  for opening in total inelastic; do
    for l0 in 0.01 0.005; do
      d="$out/h$h-$l0-$opening-$band"
      target/release/sppm run lattices/uniaxial_tension.toml --quiet --out "$d" \
        --set body.height="$h" --set discretisation.spacing="$l0" \
        --set concrete.crack_opening="$opening" --set concrete.crack_band="$band" || true
      python3 - "$d/summary.json" "$l0" "$opening" "$band" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
c = s["concrete"]
a = 0.15 * 0.15
print(f'{sys.argv[2]:<7} {sys.argv[3]:<10} {sys.argv[4]:<6} {s["peak_force_N"]/(c["ft"]*a):10.4f} '
      f'{s["dissipated_energy_J"]:10.4f} {s["dissipated_energy_J"]/(c["gf"]*a):12.4f} '
      f'{s["max_kinetic_to_internal_energy"]:9.2e} {s["wall_time_s"]:8.1f}')
PY
    done
  done
done
