#!/usr/bin/env bash
# Throughput of LAMMPS bond-based peridynamics (pair_style peri/pmb) on one core, set-up excluded.
#
#   bash benchmarks/lammps_pmb.sh [N cells per side, default 100]
#
# Runs benchmarks/lammps/pmb_cubic.in (an N x N x N simple cubic grid, horizon pi*dx, 122
# partners per interior particle, nothing breaks) with serial `lmp` twice, for SHORT_STEPS
# (default 10) and LONG_STEPS (default 60) steps, and divides the extra steps by the difference
# of the two "Loop time" lines, so the set-up (neighbour list, partner search) cancels out.
# The bonds per particle are LAMMPS's own count ("total # of bonds" / atoms, every bond counted
# once from each end, as peri/pmb computes it; surface particles have fewer than 122).
# Prints particles, bonds per particle, particle-steps/s and bond-updates/s
# (particles x bonds per particle x steps / time), and the peak memory of the longer run if
# /usr/bin/time is available. Needs `lmp` with the PERI package on PATH; installs nothing.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
deck=$here/lammps/pmb_cubic.in
n=${1:-100}
short=${SHORT_STEPS:-10}
long=${LONG_STEPS:-60}
[ "$long" -gt "$short" ] || { echo "LONG_STEPS ($long) must exceed SHORT_STEPS ($short)" >&2; exit 1; }
if ! command -v lmp >/dev/null 2>&1; then
  echo "lmp (LAMMPS with the PERI package) is not on PATH; install it first" >&2
  exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# run STEPS: serial lmp in the scratch directory, log to $tmp/log.STEPS, peak RSS (kB) to $tmp/rss.STEPS
run() {
  local steps=$1
  local cmd=(lmp -nocite -screen none -log "$tmp/log.$steps" -var N "$n" -var STEPS "$steps" -in "$deck")
  if [ -x /usr/bin/time ]; then
    (cd "$tmp" && /usr/bin/time -f %M -o "$tmp/rss.$steps" "${cmd[@]}")
  else
    (cd "$tmp" && "${cmd[@]}")
  fi
  grep -q '^Loop time of' "$tmp/log.$steps" || { echo "no Loop time in the LAMMPS log:" >&2; tail -20 "$tmp/log.$steps" >&2; exit 1; }
}
echo "LAMMPS peri/pmb, simple cubic ${n}^3, serial; runs of $short and $long steps ..." >&2
run "$short"
run "$long"

# "Loop time of T on P procs for S steps with A atoms"; "  total # of bonds = B"
loop() { awk '/^Loop time of/ {print $4, $6, $9, $12}' "$tmp/log.$1"; }
read -r t1 p1 s1 a1 < <(loop "$short")
read -r t2 p2 s2 a2 < <(loop "$long")
bonds=$(awk '/total # of bonds =/ {print $NF}' "$tmp/log.$long")
[ "$p1" = 1 ] && [ "$p2" = 1 ] || { echo "expected 1 process, got $p1 and $p2" >&2; exit 1; }
[ "$a1" = "$a2" ] || { echo "atom counts differ: $a1 vs $a2" >&2; exit 1; }
# interior count for comparison: lattice offsets 0 < |o| <= pi (in units of dx)
bulk=$(awk 'BEGIN { pi = atan2(0, -1); c = 0
  for (i = -4; i <= 4; i++) for (j = -4; j <= 4; j++) for (k = -4; k <= 4; k++) {
    r2 = i*i + j*j + k*k; if (r2 > 0 && r2 <= pi*pi) c++ }
  print c }')
rss=""
[ -f "$tmp/rss.$long" ] && rss=$(tail -1 "$tmp/rss.$long")

awk -v n="$n" -v a="$a2" -v b="$bonds" -v bulk="$bulk" -v s1="$s1" -v s2="$s2" \
    -v t1="$t1" -v t2="$t2" -v rss="$rss" 'BEGIN {
  ds = s2 - s1; dt = t2 - t1
  if (dt <= 0) { print "non-positive time difference: " t2 " - " t1 > "/dev/stderr"; exit 1 }
  printf "cells per side:      %d\n", n
  printf "particles:           %d\n", a
  printf "bonds per particle:  %.3f (LAMMPS: %d bonds counted from both ends; interior %d)\n", b / a, b, bulk
  printf "loop time:           %.3f s (%d steps) - %.3f s (%d steps) = %.3f s for %d steps\n", t2, s2, t1, s1, dt, ds
  printf "s per step:          %.4g\n", dt / ds
  printf "particle-steps/s:    %.4g\n", a * ds / dt
  printf "bond-updates/s:      %.4g (per core)\n", b * ds / dt
  if (rss != "") printf "peak RSS:            %.1f MB (%d-step run)\n", rss / 1024, s2
}'
