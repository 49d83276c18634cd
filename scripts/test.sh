#!/usr/bin/env bash
# The test command of the README: installs the engines if missing, then runs
# the whole default test suite (fast physics checks included; long runs are
# behind DEMX_LONG=1).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Open MPI (under LIGGGHTS and LAMMPS, even on one rank) makes its session
# directory ompi.<host>.<uid> under TMPDIR; two engines starting at the same
# moment race on that mkdir and one aborts ("File exists"; a CI run failed so
# on 2026-12-06). The tests start engines in parallel, so each engine they
# start gets a TMPDIR of its own through these wrappers, first on PATH.
wrap=$(mktemp -d)
trap 'rm -rf "$wrap"' EXIT
for e in liggghts lmp; do
    real=$(command -v "$e") || continue
    # (a rank that mpirun starts keeps mpirun's session: no wrapping there)
    printf '#!/bin/sh\n[ -n "$OMPI_COMM_WORLD_SIZE" ] && exec "%s" "$@"\nd=$(mktemp -d)\nTMPDIR="$d" "%s" "$@"\nrc=$?\nrm -rf "$d"\nexit $rc\n' "$real" "$real" > "$wrap/$e"
    chmod +x "$wrap/$e"
done
PATH="$wrap:$PATH" cargo test --no-fail-fast "$@"
