#!/bin/bash
# The Monte Carlo size-effect study of benchmarks/RESULTS.md ("Random fields and the Monte Carlo
# size effect"): dog-bones A–E × 100 realisations and F × N_F (default 40), two jobs
# at a time, then one report over A–F and the realisations per hour per size.
#
#   bash benchmarks/montecarlo.sh [N_F]
#
# Each command resumes where it stopped; the run of every size is recorded in
# output/mc-AE/realisations.csv and output/mc-F/realisations.csv as it finishes.
set -euo pipefail
cd "$(dirname "$0")/.."
NF=${1:-40}
cargo build --release --quiet
B=target/release/sppm
S=lattices/dogbone_montecarlo.toml
date -u +"A–E start %H:%M:%S"
$B study montecarlo $S --realisations 100 --seed 1 --sizes A,B,C,D,E --jobs 2 --quiet --out output/mc-AE
date -u +"F start %H:%M:%S"
$B study montecarlo $S --realisations "$NF" --seed 1 --sizes F --jobs 2 --quiet --out output/mc-F
date -u +"done %H:%M:%S"
$B study merge output/mc-AE output/mc-F --out output/mc-AF
python3 benchmarks/montecarlo_rates.py output/mc-AE
python3 benchmarks/montecarlo_rates.py output/mc-F
