#!/usr/bin/env bash
# The test command of the README: installs the engines if missing, then runs
# the whole default test suite (fast physics checks included; long runs are
# behind DEMX_LONG=1).
set -euo pipefail
cd "$(dirname "$0")/.."
# formatting and lints are part of the test (rustfmt.toml; Cargo.toml's
# [lints] says which clippy lints are allowed and why): a diff or a warning
# fails the run before the tests are built
cargo fmt --check
cargo clippy --all-targets --quiet -- -D warnings
bash scripts/setup.sh
# the one-node Slurm cluster the Slurm backend's test submits to
bash scripts/slurm_local.sh
# Open MPI (under both engines, even on one rank) creates its session
# directory /tmp/ompi.<host>.<uid> at start when it is missing, and an
# engine's end may remove it again; two engines starting at once can race on
# that mkdir, and the loser aborts in MPI_Init before reading its deck ("unable
# to create the desired directory ... File exists": a clean-clone CI run on
# 2026-12-06, in tests that start engines in parallel). For the tests, each
# engine runs through a wrapper, first on PATH, that starts it again when its
# output says it lost that race (a TMPDIR per run avoided the race but made
# PMIx print errors on every run, which the tests read).
wrap=$(mktemp -d)
trap 'rm -rf "$wrap"' EXIT
for e in liggghts lmp; do
    real=$(command -v "$e") || continue
    cat > "$wrap/$e" <<WRAP
#!/bin/sh
# a rank that mpirun starts has mpirun's session: run it as it is
[ -n "\$OMPI_COMM_WORLD_SIZE" ] && exec "$real" "\$@"
out=\$(mktemp); err=\$(mktemp)
# line-buffered: an engine's "ERROR on proc 0" line is written before MPI_Abort ends it
# (fully buffered into a file, LIGGGHTS 3.8 lost it and a failing test
# showed only Open MPI's banner)
for try in 1 2 3 4 5; do
    stdbuf -oL "$real" "\$@" > "\$out" 2> "\$err"
    rc=\$?
    [ \$rc -ne 0 ] && grep -qs "unable to create the desired directory" "\$out" "\$err" || break
    # the racers wait different times (their pids)
    sleep "0.\$(( \$\$ % 9 + 1 ))"
done
cat "\$out"; cat "\$err" >&2
rm -f "\$out" "\$err"
exit \$rc
WRAP
    chmod +x "$wrap/$e"
done
# The library compiles twice: for the binary and the integration tests at
# opt-level 1, near 12 minutes on one core (every contact-law combination is
# its own kernel), and for its unit tests (below). On a machine under 32 GB
# two library builds at once were killed for memory (2026-12-07, 24 GB):
# there they go one at a time.
jobs=()
# CI builds from a clean checkout: incremental compilation's caches only
# cost there (written, never read again).
export CARGO_INCREMENTAL=0
mem_kb=$(awk '/^MemTotal:/ {print $2}' /proc/meminfo 2>/dev/null || echo 0)
if [ "${mem_kb:-0}" -lt 33554432 ]; then
    jobs=(-j 1)
fi
status=0
# The library's unit tests at opt-level 0: 2.5 min to compile instead of 12
# (measured 2026-12-08, one core), 5 s to run. Unoptimised, the SIMD kernels
# keep large stack frames: the test threads get 64 MB (they overflowed 2 MB).
RUST_MIN_STACK=67108864 cargo test "${jobs[@]}" --no-fail-fast --lib --config 'profile.test.opt-level=0' "$@" || status=$?
# the binary, the example and the integration tests, at the suite's opt-level
PATH="$wrap:$PATH" cargo test "${jobs[@]}" --no-fail-fast --bins --examples --test it "$@" || status=$?
exit $status
