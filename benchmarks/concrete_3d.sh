#!/usr/bin/env bash
# Runs the shipped 3D concrete scenes (FCC lattice) and prints, per scene, the
# peak force against its reference, the dissipated energy against G_f·A (tension prism), the
# quasi-static ratio K/U up to the peak, the particles and the run time.
# Usage: benchmarks/concrete_3d.sh [scene ...] [-- --set key=value ...]
#   default scenes: tension_prism_3d compression_prism_3d split_cylinder_3d dogbone_B_3d
#   beam_3pb_unnotched_3d beam_3pb_notch02_3d beam_3pb_notch05_3d
# Needs python3 to read summary.json. SPPM=path runs that binary instead of building;
# OUT=dir keeps the outputs (default /tmp/sppm-concrete-3d).
set -euo pipefail
cd "$(dirname "$0")/.."
scenes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do scenes+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
if [ ${#scenes[@]} -eq 0 ]; then
  scenes=(tension_prism_3d compression_prism_3d split_cylinder_3d dogbone_B_3d beam_3pb_unnotched_3d beam_3pb_notch02_3d beam_3pb_notch05_3d)
fi
if [ -z "${SPPM:-}" ]; then
  cargo build --release --quiet
fi
bin=${SPPM:-target/release/sppm}
out=${OUT:-/tmp/sppm-concrete-3d}
printf '%-22s %7s %9s %9s %8s %9s %9s %9s %8s\n' scene particles "peak kN" "ref kN" ratio "W/(Gf·A)" "K/U peak" "t peak s" "wall s"
for s in "${scenes[@]}"; do
  "$bin" run "lattices/$s.toml" --quiet --out "$out/$s" "$@" || true
  python3 - "$out/$s/summary.json" "$s" <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
name = sys.argv[2]
v = {d["key"]: d["value"] for d in s["material_values"]}
# references: f't·A; f'c·A; (5.6); the dog-bone's f't·0.6·D·t; Hobbs's (2021) bond-based peaks
ref = {
    "tension_prism_3d": v["ft"] * 0.15 * 0.15,
    "compression_prism_3d": v["fc"] * 0.15 * 0.15,
    "split_cylinder_3d": math.pi / 2 * v["ft"] * 0.15 * 0.30 / (1 - (0.025 / 0.15) ** 2) ** 1.5,
    "dogbone_B_3d": v["ft"] * 0.6 * 0.1 * 0.1,
    "beam_3pb_unnotched_3d": 4748.0,
    "beam_3pb_notch02_3d": 3097.0,
    "beam_3pb_notch05_3d": 1280.0,
}.get(name, float("nan"))
energy = s["dissipated_energy_J"] / (v["Gf"] * 0.15 * 0.15) if name == "tension_prism_3d" else float("nan")
p = s["peak_force_N"]
print(f'{name:<22} {s["particles"]:7d} {p/1e3:9.3f} {ref/1e3:9.3f} {p/ref:8.4f} {energy:9.4f} '
      f'{s["max_kinetic_to_internal_energy"]:9.2e} {s["wall_time_to_peak_s"]:9.1f} {s["wall_time_s"]:8.1f}')
PY
done
