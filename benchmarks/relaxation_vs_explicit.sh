#!/usr/bin/env bash
# Adaptive dynamic relaxation against the damped explicit solver on every shipped scene
# (docs/relaxation.md): wall time to the peak record, total wall time, peak force, and the
# peak's error against a converged quasi-static reference at the same spacing: the explicit
# run loaded 4× more slowly (loading.end_periods × 4) at solver.safety = 0.5 ("ref"). A second
# reference is the relaxation converged tightly (800 increments, tolerance 1e-5,
# max_iterations 1000; "tight").
#
# Each run writes its own folder under $OUT and is skipped when its summary.json exists, so
# an interrupted study resumes where it stopped. One simulation at a time (the timings).
#
# Usage: benchmarks/relaxation_vs_explicit.sh [scene ...]     (default: every lattices/*.toml)
#   OUT=dir (default /tmp/sppm-relaxation)   RELAX="--set solver.increments=100 ..." (extra
#   settings of the relaxation runs)   REF=0 skips the explicit reference runs, TIGHT=0 the
#   tight relaxation runs (their columns then empty)
# Needs python3 to read summary.json.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
out=${OUT:-/tmp/sppm-relaxation}
relax=${RELAX:-}
ref=${REF:-1}
tight=${TIGHT:-1}
scenes=("$@")
if [ ${#scenes[@]} -eq 0 ]; then
  scenes=(lattices/*.toml)
fi
bin=target/release/sppm

run() { # dir scene args...
  local d=$1 scene=$2
  shift 2
  if [ ! -f "$d/summary.json" ]; then
    nice "$bin" run "$scene" --quiet --out "$d" "$@" >/dev/null || true
  fi
}

for scene in "${scenes[@]}"; do
  n=$(basename "$scene" .toml)
  periods=$(python3 -c 'import sys,tomllib; print(tomllib.load(open(sys.argv[1],"rb")).get("loading",{}).get("end_periods",10.0))' "$scene")
  run "$out/$n/explicit" "$scene"
  # shellcheck disable=SC2086
  run "$out/$n/relaxation" "$scene" --set solver.method=relaxation $relax
  if [ "$ref" = 1 ]; then
    run "$out/$n/reference" "$scene" --set loading.end_periods="$(python3 -c "print(4*$periods)")" --set solver.safety=0.5
  fi
  if [ "$tight" = 1 ]; then
    run "$out/$n/relaxation_tight" "$scene" --set solver.method=relaxation --set solver.increments=800 \
      --set solver.tolerance=1e-5 --set solver.max_iterations=1000
  fi
done

python3 - "$out" "${scenes[@]}" <<'PY'
import json, os, sys
out = sys.argv[1]
def load(p):
    try:
        return json.load(open(p))
    except OSError:
        return None
print(f'{"scene":<22} {"method":<11} {"to peak s":>9} {"total s":>8} {"steps":>8} {"peak kN":>9} '
      f'{"ref kN":>9} {"error %":>8} {"tight kN":>9} {"err t %":>8} {"W_d J":>8} {"unconv":>6}')
for scene in sys.argv[2:]:
    n = os.path.basename(scene)[:-5]
    ref = load(f'{out}/{n}/reference/summary.json')
    tight = load(f'{out}/{n}/relaxation_tight/summary.json')
    t = tight["peak_force_N"] if tight else float("nan")
    for m in ("explicit", "relaxation"):
        s = load(f'{out}/{n}/{m}/summary.json')
        if s is None:
            print(f'{n:<22} {m:<11} (no result)')
            continue
        pk = s["peak_force_N"]
        r = ref["peak_force_N"] if ref else float("nan")
        err = 100 * (pk / r - 1) if ref else float("nan")
        unconv = s.get("unconverged_increments")
        print(f'{n:<22} {m:<11} {s["wall_time_to_peak_s"]:9.3f} {s["wall_time_s"]:8.2f} {s["steps"]:8d} '
              f'{pk/1e3:9.3f} {r/1e3:9.3f} {err:8.2f} {t/1e3:9.3f} {100*(pk/t-1):8.2f} {s["dissipated_energy_J"]:8.3f} '
              f'{"" if unconv is None else unconv:>6}')
PY
