#!/usr/bin/env python3
"""Interleaved A/B timing of demx binaries on bench deck (a).

    python3 scripts/ab.py --reps 5 --threads 2 OLD/demx target/release/demx
    python3 scripts/ab.py --reps 6 --side-by-side OLD/demx target/release/demx
    python3 scripts/ab.py --chute --steps 1000 --side-by-side OLD/demx target/release/demx

Runs each binary in turn, `--reps` rounds, on bench/in.bed.liggghts with the
tiled bed of scripts/bench.py (target/bench/bed2x2.data, 30,000 spheres; run
scripts/bench.py once, or its prepare(), to make it), and prints the minimum
and median of each section time from demx's own log. This machine's speed
drifts by tens of percent within minutes: interleaving and several rounds
are what make two binaries comparable. --chute runs deck (c) instead, the
LAMMPS chute (../shared/bench/chute/in.chute, run in target/bench, where
scripts/bench.py puts its data.chute).

--side-by-side runs two binaries at once, one thread each, each pinned to its
own core (`taskset`, the cores swapped every round), so that both see the
same moment of the machine; it prints each section's medians and the median
of the per-round ratios new/old. Two runs share the memory bus and L3, so the
rates are not those of a run alone: compare the ratio.
"""
import argparse, os, statistics, subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORK = os.path.join(ROOT, "target", "bench")
CHUTE = os.path.join(os.path.dirname(ROOT), "shared", "bench", "chute", "in.chute")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bins", nargs="+")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--threads", default="1")
    ap.add_argument("--steps", default="500")
    ap.add_argument("--data", default="bed2x2.data")
    ap.add_argument("--chute", action="store_true", help="deck (c), the LAMMPS chute, instead of the bed")
    ap.add_argument("--side-by-side", action="store_true", help="two binaries at once, one core each")
    a = ap.parse_args()
    keys = ("Loop", "Pair", "Neigh", "Modify")
    res = {b: {k: [] for k in keys} for b in a.bins}

    def cmd(b, threads):
        if a.chute:
            return [os.path.abspath(b), "run", CHUTE, "--log", "none", "--threads", threads, "-var", "nsteps", a.steps]
        return [os.path.abspath(b), "run", os.path.join(ROOT, "bench", "in.bed.liggghts"), "--log", "none",
                "--threads", threads, "-var", "data", a.data, "-var", "nsteps", a.steps]

    def record(b, out):
        for line in out.splitlines():
            w = line.split()
            if line.startswith("Loop time"):
                res[b]["Loop"].append(float(w[3]))
            elif len(w) > 2 and w[0] in keys and w[1] == "|":
                res[b][w[0]].append(float(w[2]))

    if a.side_by_side:
        if len(a.bins) != 2:
            ap.error("--side-by-side compares two binaries")
        for r in range(a.reps):
            cores = (r % 2, 1 - r % 2)
            procs = [subprocess.Popen(["taskset", "-c", str(c)] + cmd(b, "1"), cwd=WORK, stdout=subprocess.PIPE, text=True)
                     for b, c in zip(a.bins, cores)]
            for b, p in zip(a.bins, procs):
                out, _ = p.communicate()
                if p.returncode != 0:
                    raise SystemExit(f"{b} failed with exit code {p.returncode}")
                record(b, out)
    else:
        for _ in range(a.reps):
            for b in a.bins:
                record(b, subprocess.run(cmd(b, a.threads), cwd=WORK, capture_output=True, text=True, check=True).stdout)
    for b in a.bins:
        print(b, "  ".join(f"{k} min {min(v):.3f} med {statistics.median(v):.3f}" for k, v in res[b].items() if v))
    if a.side_by_side:
        old, new = a.bins
        print("new/old per round, median:", "  ".join(
            f"{k} {statistics.median(n / o for o, n in zip(res[old][k], res[new][k])):.3f}" for k in keys if res[old][k]))


if __name__ == "__main__":
    main()
