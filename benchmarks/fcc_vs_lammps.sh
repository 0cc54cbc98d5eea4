#!/usr/bin/env bash
# The 3D elastic kernel against LAMMPS peridynamics on the same FCC block.
#
#   bash benchmarks/fcc_vs_lammps.sh [PARTICLES, default 100000] [SPPM_STEPS, default 200]
#
# Both codes run an FCC cube of N cubic cells per side, faces included: LAMMPS's `lattice fcc a`
# with `region block 0 N 0 N 0 N` and shrink-wrapped boundaries (cubic constant a, so the
# nearest spacing is a/√2 and 4 atoms per a³; horizon 1.05·a takes the 12 nearest and the 6
# second neighbours), and `sppm bench --dim 3` (`bench::fcc_block`, the same points). Both
# have 4N³ + 6N² + 3N + 1 particles; N is the one nearest PARTICLES. Each code runs on 1 and
# 2 threads (sppm) / MPI processes (LAMMPS: the script named by LAMMPS_BENCH, e.g. one that installs
# Debian's lammps package with apt if `lmp` is missing, times 400 − 100 steps of peri/lps and
# so excludes its set-up; sppm excludes set-up too). Prints every rate, the per-core rates
# and the ratios sppm/LAMMPS, as a Markdown table. Set SPPM to another binary, LAMMPS_STYLE
# to peri/pmb.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
particles=${1:-100000}
steps=${2:-200}
sppm=${SPPM:-$root/target/release/sppm}
lammps=${LAMMPS_BENCH:?set LAMMPS_BENCH to a script that times LAMMPS on the block}
style=${LAMMPS_STYLE:-peri/lps}
[ -x "$sppm" ] || (cd "$root" && cargo build --release -q)
# N with 4N³ + 6N² + 3N + 1 nearest PARTICLES
read -r cells count < <(python3 -c "
p = $particles
f = lambda n: 4*n**3 + 6*n**2 + 3*n + 1
n = min(range(1, 1000), key=lambda n: abs(f(n) - p))
print(n, f(n))")
echo "FCC cube: $cells cells per side, $count particles; sppm $steps steps; LAMMPS $style" >&2
rate() { python3 -c 'import json,sys; print(json.loads(sys.stdin.read().strip().splitlines()[-1])["particle_steps_per_s"])'; }
declare -A s l
for t in 1 2; do
  out=$("$sppm" bench --dim 3 --particles "$count" --steps "$steps" --threads "$t")
  echo "sppm $t threads: $out" >&2
  n=$(python3 -c 'import json,sys; print(json.loads(sys.argv[1])["particles"])' "$out")
  [ "$n" = "$count" ] || { echo "sppm built $n particles, not $count" >&2; exit 1; }
  s[$t]=$(echo "$out" | rate)
  line=$(bash "$lammps" "$cells" "$t" "$style" | tail -1)
  echo "$line" >&2
  n=$(echo "$line" | awk '{print $3}')
  [ "$n" = "$count" ] || { echo "LAMMPS built $n particles, not $count" >&2; exit 1; }
  l[$t]=$(echo "$line" | awk '{print $(NF-1)}')
done
echo "| particles | threads/procs | sppm (M particle-steps/s) | per core | LAMMPS $style (M particle-steps/s) | per core | sppm/LAMMPS |"
echo "|---|---|---|---|---|---|---|"
for t in 1 2; do
  python3 -c "
s, l, t, n = ${s[$t]}, ${l[$t]}, $t, $count
print(f'| {n} | {t} | {s/1e6:.2f} | {s/t/1e6:.2f} | {l/1e6:.3f} | {l/t/1e6:.3f} | {s/l:.1f} |')"
done
