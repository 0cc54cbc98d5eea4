#!/usr/bin/env bash
# Bit-for-bit check of two sppm binaries on short 3D concrete runs: each case runs with both
# binaries (2 threads) and every output file must be identical, apart from summary.json's
# wall times and set-up seconds. The cases cover the tension and the full kernel on the FCC
# lattice (coarse shipped scenes), random particles (neighbourhood criteria), and the
# relaxation and quasi-static solvers (the scalar, held-state path).
#
#   bash benchmarks/bitwise_3d.sh OLD_BIN NEW_BIN
set -euo pipefail
old=${1:?usage: bitwise_3d.sh OLD_BIN NEW_BIN}
new=${2:?usage: bitwise_3d.sh OLD_BIN NEW_BIN}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
tension="--set concrete.compressive_damage=false --set concrete.plasticity=false"
cases=(
  "prism_full|lattices/tension_prism_3d.toml|--set discretisation.spacing=0.02"
  "prism_tension|lattices/tension_prism_3d.toml|--set discretisation.spacing=0.02 $tension"
  "cylinder_full|lattices/split_cylinder_3d.toml|--set discretisation.spacing=0.025"
  "dogbone_full|lattices/dogbone_B_3d.toml|--set discretisation.spacing=0.01"
  "notched_random|lattices/tension_prism_notched_3d.toml|--set discretisation.spacing=0.03"
  "prism_relaxation|lattices/tension_prism_3d.toml|--set discretisation.spacing=0.03 --set solver.method=relaxation --set solver.increments=20"
  "prism_quasi_static|lattices/tension_prism_3d.toml|--set discretisation.spacing=0.03 --set solver.method=quasi_static --set solver.increments=10"
)
fail=0
for c in "${cases[@]}"; do
  IFS='|' read -r name scene sets <<<"$c"
  for b in old new; do
    bin=$old; [ "$b" = new ] && bin=$new
    # shellcheck disable=SC2086
    "$bin" run "$scene" --quiet --threads 2 --out "$tmp/$name.$b" $sets >/dev/null 2>"$tmp/$name.$b.err" || true
    sed -i -E '/"(wall_time|seconds_)/d' "$tmp/$name.$b/summary.json" 2>/dev/null || true
  done
  if diff -rq "$tmp/$name.old" "$tmp/$name.new" >/dev/null && cmp -s "$tmp/$name.old.err" "$tmp/$name.new.err"; then
    printf '%-20s identical (%s files; %s)\n' "$name" "$(ls "$tmp/$name.new" | wc -l)" \
      "$(grep -o '"kernel": *"[a-z]*"' "$tmp/$name.new/summary.json" || echo 'no summary')"
  else
    printf '%-20s DIFFERENT\n' "$name"; diff -rq "$tmp/$name.old" "$tmp/$name.new" || true
    fail=1
  fi
done
exit $fail
