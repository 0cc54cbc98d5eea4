#!/usr/bin/env bash
# The bond-based kernel against LAMMPS's peri/pmb on the same simple cubic grid (N^3 points,
# horizon pi*dx, about 122 bonds a point inside), each on one core, set-up excluded, in one
# run of this script so that both see the same machine: bond-updates per second per core and
# their ratio. LAMMPS runs first (benchmarks/lammps_pmb.sh), then
# `cargo run --release --example bond_kernel -- N 1`.
#
#   bash benchmarks/bond_vs_lammps.sh [N cells per side, default 100]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=${1:-100}
lammps=$(bash "$here/lammps_pmb.sh" "$n")
echo "$lammps"
cargo build --release --quiet --example bond_kernel
sppm=$("$here/../target/release/examples/bond_kernel" "$n" 1 2>/dev/null)
echo "$sppm"
l=$(echo "$lammps" | awk '/bond-updates\/s:/ {print $2}')
s=$(echo "$sppm" | sed -n 's/.*, \([0-9.e+]*\) bond-updates\/s.*/\1/p')
awk -v l="$l" -v s="$s" 'BEGIN { printf "sppm / LAMMPS, bond-updates per second per core: %.2f\n", s / l }'
