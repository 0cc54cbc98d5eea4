#!/usr/bin/env bash
# The quasi-static solver (solver.method = "quasi_static", docs/quasi_static.md) against the
# explicit solver and the adaptive relaxation on the shipped 2D concrete scenes:
# peak force, the force at equal displacement down the softening branch to 30% of the
# peak, the dissipated energy, and the wall time to the peak. Reference: the explicit run
# loaded 4× more slowly (loading.end_periods × 4) at solver.safety = 0.5 ("ref").
# Two energy ratios: W_d/ref compares the summaries' dissipated_energy_J (W − U − K − the
# dampers' energy); W-U/ref compares W − U − K, which counts what the explicit run's dampers
# absorbed as lost too (a quasi-static solver has no dampers: the energy a snap releases is
# in its W − U).
#
# Each run writes its own folder under $OUT and is skipped when its summary.json exists, so
# an interrupted comparison resumes where it stopped. One simulation at a time (the timings).
#
# Usage: benchmarks/quasi_static_vs_explicit.sh [scene ...]
#   (default: uniaxial_tension uniaxial_compression split_cylinder dogbone_B dogbone_D)
#   OUT=dir (default /tmp/sppm-quasi-static)   REF=0 skips the reference runs
#   QS="--set solver.increments=400 ..." extra settings of the quasi-static runs
# Needs python3 to read summary.json and force_displacement.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
out=${OUT:-/tmp/sppm-quasi-static}
ref=${REF:-1}
qs=${QS:-}
scenes=("$@")
if [ ${#scenes[@]} -eq 0 ]; then
  scenes=(uniaxial_tension uniaxial_compression split_cylinder dogbone_B dogbone_D)
fi
bin=target/release/sppm

run() { # dir scene args...
  local d=$1 scene=$2
  shift 2
  if [ ! -f "$d/summary.json" ]; then
    nice "$bin" run "lattices/$scene.toml" --quiet --out "$d" "$@" >/dev/null || true
  fi
}

for n in "${scenes[@]}"; do
  periods=$(python3 -c 'import sys,tomllib; print(tomllib.load(open(sys.argv[1],"rb")).get("loading",{}).get("end_periods",10.0))' "lattices/$n.toml")
  # shellcheck disable=SC2086
  run "$out/$n/quasi_static" "$n" --set solver.method=quasi_static $qs
  run "$out/$n/relaxation" "$n" --set solver.method=relaxation
  run "$out/$n/explicit" "$n"
  if [ "$ref" = 1 ]; then
    run "$out/$n/reference" "$n" --set loading.end_periods="$(python3 -c "print(4*$periods)")" --set solver.safety=0.5
  fi
done

python3 - "$out" "${scenes[@]}" <<'PY'
import csv, json, sys
out = sys.argv[1]

def load(n, m):
    try:
        s = json.load(open(f'{out}/{n}/{m}/summary.json'))
        rows = list(csv.DictReader(open(f'{out}/{n}/{m}/force_displacement.csv')))
    except OSError:
        return None, None
    sign = -1.0 if s["peak_force_N"] * float(rows[-1]["force_N"] or 0) < 0 else 1.0
    # (|displacement|, force along the loading direction)
    curve = [(abs(float(r["displacement_m"])), abs(float(r["force_N"]))) for r in rows]
    return s, curve

def at(curve, u):
    """The force of a curve at displacement u (linear between records; the softening part
    after the peak, so that the rising branch does not answer)."""
    for (u0, f0), (u1, f1) in zip(curve, curve[1:]):
        if u0 <= u <= u1 and u1 > u0:
            return f0 + (f1 - f0) * (u - u0) / (u1 - u0)
    return None

def softening_error(curve, ref):
    """Largest |F(u) − F_ref(u)| / F_ref,peak over the reference's softening branch down to
    30% of its peak."""
    pk = max(range(len(ref)), key=lambda i: ref[i][1])
    fpk = ref[pk][1]
    worst = 0.0
    ipk = max(range(len(curve)), key=lambda i: curve[i][1])
    post = curve[ipk:]
    for u, f in ref[pk:]:
        if f < 0.3 * fpk:
            break
        g = at(post, u)
        if g is None:
            continue
        worst = max(worst, abs(g - f) / fpk)
    return worst

def lost(s):
    """W − U − K: the dissipated energy with the dampers' share, the whole irrecoverable work."""
    return s["dissipated_energy_J"] + s.get("damping_energy_J", 0.0)

print(f'{"scene":<22} {"method":<13} {"to peak s":>9} {"total s":>8} {"peak kN":>9} {"ref kN":>9} '
      f'{"peak err %":>10} {"soft err %":>10} {"W_d J":>8} {"W_d/ref":>8} {"W-U/ref":>8} {"unconv":>6}')
for n in sys.argv[2:]:
    r, rc = load(n, "reference")
    for m in ("explicit", "relaxation", "quasi_static"):
        s, c = load(n, m)
        if s is None:
            print(f'{n:<22} {m:<13} (no result)')
            continue
        pk = s["peak_force_N"]
        rp = r["peak_force_N"] if r else float("nan")
        soft = 100 * softening_error(c, rc) if r else float("nan")
        wr = s["dissipated_energy_J"] / r["dissipated_energy_J"] if r else float("nan")
        lr = lost(s) / lost(r) if r else float("nan")
        un = s.get("unconverged_increments")
        print(f'{n:<22} {m:<13} {s["wall_time_to_peak_s"]:9.3f} {s["wall_time_s"]:8.2f} {pk/1e3:9.3f} '
              f'{rp/1e3:9.3f} {100*(pk/rp-1):10.2f} {soft:10.2f} {s["dissipated_energy_J"]:8.3f} {wr:8.3f} {lr:8.3f} '
              f'{"" if un is None else un:>6}  {s["status"]}')
PY
