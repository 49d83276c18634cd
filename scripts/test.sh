#!/usr/bin/env bash
# The test command of the README: installs the engines if missing, then runs
# the whole default test suite (fast physics checks included; long runs are
# behind DEMX_LONG=1).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo test --no-fail-fast "$@"
