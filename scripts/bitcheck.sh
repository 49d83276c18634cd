#!/usr/bin/env bash
# Fingerprints of what a demx binary computes, for checking that a change
# meant to be speed-only keeps every bit: for each binary given and for 1 and
# 2 threads, the md5 (first 8 hex digits) of
#   - the LAMMPS chute benchmark's thermo lines (../shared/bench/chute/in.chute,
#     2,000 steps, target/bench/data.chute),
#   - bench deck (a)'s dumps (bench/in.bed.liggghts on target/bench/bed.data,
#     7,500 spheres, 1,000 steps, x v omega f every 500 steps, %.17g thermo),
#   - the settle template's dump.settle.
# Equal lines for two binaries (and for 1 and 2 threads) mean equal results.
# Run `python3 scripts/bench.py` once first (or its prepare()) for target/bench.
#   bash scripts/bitcheck.sh OLD/demx target/release/demx
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BENCH=$ROOT/target/bench
CHUTE=$ROOT/../shared/bench/chute
for bin in "$@"; do
  bin=$(realpath "$bin")
  for t in 1 2; do
    d=$(mktemp -d)
    (
      cd "$d"
      cp "$CHUTE/in.chute" "$BENCH/data.chute" .
      "$bin" run in.chute -v nsteps 2000 --log none --threads "$t" > chute.out 2>&1 || true
      a=$(grep -E "^ +[0-9]+ " chute.out | md5sum | cut -c1-8)
      sed -e 's/^thermo .*/thermo 100\nthermo_modify format float %.17g/' \
          -e 's/^run /dump d all custom 500 bed.dump id x y z vx vy vz omegax fx\nrun /' "$ROOT/bench/in.bed.liggghts" > in.bed
      cp "$BENCH/bed.data" .
      "$bin" run in.bed -v nsteps 1000 --log none --threads "$t" > bed.out 2>&1 || true
      b=$(md5sum < bed.dump | cut -c1-8)
      mkdir s && cd s && cp "$ROOT"/templates/settle/* .
      "$bin" run in.settle.liggghts --threads "$t" > s.out 2>&1 || true
      c=$(md5sum < dump.settle | cut -c1-8)
      echo "$bin threads=$t chute $a bed $b settle $c"
    )
    rm -rf "$d"
  done
done
