#!/usr/bin/env python3
"""Interleaved A/B timing of demx binaries on bench deck (a).

    python3 scripts/ab.py --reps 5 --threads 2 OLD/demx target/release/demx

Runs each binary in turn, `--reps` rounds, on bench/in.bed.liggghts with the
tiled bed of scripts/bench.py (target/bench/bed2x2.data, 30,000 spheres; run
scripts/bench.py once, or its prepare(), to make it), and prints the minimum
and median of each section time from demx's own log. This machine's speed
drifts by tens of percent within minutes: interleaving and several rounds
are what make two binaries comparable.
"""
import argparse, os, statistics, subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORK = os.path.join(ROOT, "target", "bench")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bins", nargs="+")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--threads", default="1")
    ap.add_argument("--steps", default="500")
    ap.add_argument("--data", default="bed2x2.data")
    a = ap.parse_args()
    keys = ("Loop", "Pair", "Neigh", "Modify")
    res = {b: {k: [] for k in keys} for b in a.bins}
    for _ in range(a.reps):
        for b in a.bins:
            out = subprocess.run([os.path.abspath(b), "run", os.path.join(ROOT, "bench", "in.bed.liggghts"), "--log", "none",
                                  "--threads", a.threads, "-var", "data", a.data, "-var", "nsteps", a.steps],
                                 cwd=WORK, capture_output=True, text=True, check=True).stdout
            for line in out.splitlines():
                w = line.split()
                if line.startswith("Loop time"):
                    res[b]["Loop"].append(float(w[3]))
                elif len(w) > 2 and w[0] in keys and w[1] == "|":
                    res[b][w[0]].append(float(w[2]))
    for b in a.bins:
        print(b, "  ".join(f"{k} min {min(v):.3f} med {statistics.median(v):.3f}" for k, v in res[b].items() if v))


if __name__ == "__main__":
    main()
