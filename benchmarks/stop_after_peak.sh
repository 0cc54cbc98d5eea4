#!/usr/bin/env bash
# Run time with and without loading.stop_after_peak on the shipped concrete scenes, one run
# after the other on 2 threads: the peak is the same bit for bit, the run ends once the force
# has fallen below FRACTION of the peak and a particle has failed.
# Usage: benchmarks/stop_after_peak.sh [FRACTION]
set -euo pipefail
cd "$(dirname "$0")/.."
fraction=${1:-0.5}
cargo build --release --quiet
bin=target/release/sppm
out=$(mktemp -d)
printf '%-22s %-10s %-10s %-8s %-16s %-16s %s\n' scene full_s stop_s ratio peak_full_N peak_stop_N same_peak
for s in uniaxial_tension uniaxial_compression split_cylinder dogbone_B dogbone_D; do
  "$bin" run "lattices/$s.toml" --quiet --threads 2 --out "$out/$s-full"
  "$bin" run "lattices/$s.toml" --quiet --threads 2 --out "$out/$s-stop" --set "loading.stop_after_peak=$fraction"
  python3 - "$out/$s-full/summary.json" "$out/$s-stop/summary.json" "$s" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
print(f"{sys.argv[3]:<22} {a['wall_time_s']:<10.2f} {b['wall_time_s']:<10.2f} {a['wall_time_s'] / b['wall_time_s']:<8.2f} "
      f"{a['peak_force_N']:<16.8e} {b['peak_force_N']:<16.8e} {a['peak_force_N'] == b['peak_force_N']}")
PY
done
rm -rf "$out"
