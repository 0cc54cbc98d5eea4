#!/usr/bin/env bash
# Runs every shipped concrete scene (and any extra `--set` given) and prints, per scene, the
# peak force against its reference, the quasi-static ratio, the damage figures and the
# run time. Usage: benchmarks/concrete_scenes.sh [--set key=value ...]
# Needs python3 to read summary.json. SPPM=path runs that binary instead of building.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${SPPM:-}" ]; then
  cargo build --release --quiet
fi
bin=${SPPM:-target/release/sppm}
out=${OUT:-/tmp/sppm-concrete-scenes}
printf '%-22s %10s %10s %8s %9s %9s %8s %8s %8s %9s\n' scene "peak kN" "ref kN" "ratio" "K/U" "energy J" cracked crushed yielded "wall s"
for s in uniaxial_tension uniaxial_compression split_cylinder dogbone_B dogbone_D; do
  "$bin" run "lattices/$s.toml" --quiet --out "$out/$s" "$@" || true
  python3 - "$out/$s/summary.json" "$s" <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
name = sys.argv[2]
v = {d["key"]: d["value"] for d in s["material_values"]}
ref = {
    "uniaxial_tension": v["ft"] * 0.15 * 0.15,
    "uniaxial_compression": v["fc"] * 0.15 * 0.15,
    "split_cylinder": math.pi / 2 * v["ft"] * 0.15 * 0.30 / (1 - (0.025 / 0.15) ** 2) ** 1.5,
    "dogbone_B": v["ft"] * 0.6 * 0.1 * 0.1,
    "dogbone_D": v["ft"] * 0.6 * 0.4 * 0.1,
}[name]
p = s["peak_force_N"]
print(f'{name:<22} {p/1e3:10.2f} {ref/1e3:10.2f} {p/ref:8.4f} {s["max_kinetic_to_internal_energy"]:9.2e} {s["dissipated_energy_J"]:9.3f} '
      f'{s["cracked_particles"]:8d} {s["crushed_particles"]:8d} {s["yielded_particles"]:8d} {s["wall_time_s"]:9.1f}')
PY
done
