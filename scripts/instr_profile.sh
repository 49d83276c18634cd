#!/usr/bin/env bash
# Instructions executed per source line of demx on bench deck (a)'s bed
# (the 7,500-sphere tile target/bench/bed.data, one thread), counted by
# valgrind's callgrind: the one measure of "how much work" this VM gives,
# whose `perf` has no hardware counters (no cycles, instructions or cache
# misses; only cpu-clock samples, which land on whatever waits).
#
# valgrind 3.19 cannot decode AVX-512, so demx is built here for x86-64-v3
# (AVX2, as the lane kernel's `wide` module is written for) into target/v3;
# the counts are those of that build, close to but not the native one.
#
#   bash scripts/instr_profile.sh            # 100 steps, a few minutes with the build
#   STEPS=50 bash scripts/instr_profile.sh
# Needs valgrind (Debian: apt-get install -y valgrind) and target/bench from
# `python3 scripts/bench.py` (or its prepare()). Writes target/v3/callgrind.out
# and, per source line, target/v3/callgrind.txt.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
STEPS=${STEPS:-100}
command -v valgrind > /dev/null || { echo "instr_profile.sh: needs valgrind (apt-get install -y valgrind)" >&2; exit 2; }
[ -f "$ROOT/target/bench/bed.data" ] || { echo "instr_profile.sh: no target/bench/bed.data; run python3 scripts/bench.py once" >&2; exit 2; }
(cd "$ROOT" && RUSTFLAGS="-C target-cpu=x86-64-v3" cargo build --release --target-dir "$ROOT/target/v3")
OUT=$ROOT/target/v3/callgrind.out
cd "$ROOT/target/bench"
valgrind --tool=callgrind --callgrind-out-file="$OUT" "$ROOT/target/v3/release/demx" run "$ROOT/bench/in.bed.liggghts" \
  --log none --threads 1 -var data bed.data -var nsteps "$STEPS" > "$ROOT/target/v3/run.out" 2>&1
grep -E "^Pairs per particle" "$ROOT/target/v3/run.out" || true
(cd "$ROOT" && callgrind_annotate --auto=yes "$OUT" > "$ROOT/target/v3/callgrind.txt")
atoms=$(awk '/ atoms$/ {print $1; exit}' "$ROOT/target/bench/bed.data")
# inclusive count of the force pass's blocks, and the whole run, per particle-step
python3 - "$OUT" "$atoms" "$STEPS" <<'EOF'
import re, subprocess, sys
out, atoms, steps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
text = subprocess.run(["callgrind_annotate", "--inclusive=yes", out], capture_output=True, text=True).stdout
ps = atoms * steps
total = int(re.search(r"([\d,]+) \([^)]*\)\s+PROGRAM TOTALS", text).group(1).replace(",", ""))
print(f"whole run (start-up included): {total / ps:.0f} instructions per particle-step")
def inclusive(pattern):
    """The first inclusive count whose symbol matches `pattern` (a line of
    its own, not a call line `=>`), or None."""
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+) \(\s*[\d.]+%\)\s+(\S+)", line)
        if m and m.group(2) != "=>" and re.search(pattern, m.group(2) + line[m.end():]):
            return int(m.group(1).replace(",", ""))
    return None

# the pass: its blocks (dense and walked, compiled as functions of their
# own) and what the block closure adds around them (the bounds check, the
# zero fills); the closure also runs each finished block's tail (the cross
# shares and the integration), which is not the pass and is taken off
closure = inclusive(r"kernel\.rs:<demx::engine::kernel::Laws.*force_pass::\{\{closure\}\} ")
tails = [inclusive(r"kernel\.rs:demx::engine::kernel::cross_gather_chunk "), inclusive(r"sim\.rs:demx::engine::sim::Sim::fused_pass::\{\{closure\}\} ")]
blocks = [inclusive(r"kernel\.rs:demx::engine::kernel::Laws.*::block_dense "), inclusive(r"kernel\.rs:demx::engine::kernel::Laws.*::block_walk ")]
if closure is None or None in tails:
    # the compiler's names for closures may change
    print("force pass: its closure's symbol was not found; read target/v3/callgrind.txt")
else:
    print(f"force pass (its closure less the finished blocks' tails): {(closure - sum(tails)) / ps:.0f} instructions per particle-step")
print(f"of which the blocks' pairs (block_dense + block_walk): {sum(b or 0 for b in blocks) / ps:.0f}")
EOF
echo "per source line: target/v3/callgrind.txt"
