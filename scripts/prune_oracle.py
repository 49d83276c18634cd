#!/usr/bin/env python3
"""How many listed pairs a prune could leave out on the chute (c): by travel
(as demx prunes now) against along the particles' paths.

    python3 scripts/prune_oracle.py [--steps 16] [--at 500] [--demx target/release/demx]

Runs demx on the LAMMPS chute (target/bench/data.chute, which
scripts/bench.py makes) to step `--at`, dumps every 4 steps for `--steps`
more, and counts per particle, over the pairs within the skin at `--at`:
- those touching at some dumped step of the window (what any prune must keep);
- those a prune by travel keeps: within twice what the fastest particle
  covers in the window (PairList::next_buffer);
- those a prune along paths keeps: whose paths (position plus velocity at
  `--at` times the time since) come within twice a stray allowance of
  touching during the window, for allowances from 1e-4 to the largest stray
  measured (how far a particle strayed from its path in the window).
The pairs a force pass walks cost it most of its time on this deck
(BENCHMARKS.md); this tells how many a prune could spare, before its cost.
"""
import argparse, math, os, subprocess, sys, tempfile
from collections import defaultdict

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DECK = """units lj
atom_style sphere
boundary p p fs
newton off
comm_modify vel yes
read_data {data}
pair_style gran/hooke/history 200000.0 NULL 50.0 NULL 0.5 0
pair_coeff * *
neighbor 0.1 bin
neigh_modify every 1 delay 0
timestep 0.0001
group bottom type 2
group active subtract all bottom
neigh_modify exclude group bottom bottom
fix 1 all gravity 1.0 chute 26.0
fix 2 bottom freeze
fix 3 active nve/sphere
run {at}
dump d all custom 4 dump.oracle id type x y z vx vy vz radius
run {steps}
"""


def frames(path):
    with open(path) as f:
        while True:
            if not f.readline():
                return
            step = int(f.readline())
            f.readline()
            n = int(f.readline())
            f.readline()
            box = [list(map(float, f.readline().split())) for _ in range(3)]
            f.readline()
            d = {}
            for _ in range(n):
                w = f.readline().split()
                d[int(w[0])] = (int(w[1]),) + tuple(map(float, w[2:9]))
            yield step, box, d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=16, help="the window, a multiple of 4")
    ap.add_argument("--at", type=int, default=500)
    ap.add_argument("--demx", default=os.path.join(ROOT, "target", "release", "demx"))
    a = ap.parse_args()
    data = os.path.join(ROOT, "target", "bench", "data.chute")
    if not os.path.exists(data):
        sys.exit("no target/bench/data.chute: run scripts/bench.py once (or its prepare())")
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "in.oracle"), "w") as f:
            f.write(DECK.format(data=data, at=a.at, steps=a.steps))
        subprocess.run([a.demx, "run", "in.oracle", "--log", "none"], cwd=tmp, check=True, stdout=subprocess.DEVNULL)
        fr, box = {}, None
        for step, b, d in frames(os.path.join(tmp, "dump.oracle")):
            fr[step], box = d, b
    lx, ly = box[0][1] - box[0][0], box[1][1] - box[1][0]
    dt, skin = 1e-4, 0.1
    d0 = fr[a.at]
    n = len(d0)
    cut = 1.0 + skin

    def sep(p, q):
        dx, dy, dz = p[1] - q[1], p[2] - q[2], p[3] - q[3]
        return dx - lx * round(dx / lx), dy - ly * round(dy / ly), dz

    # the pairs within the skin at the start (bottom-bottom excluded, as the deck)
    nx, ny = int(lx / cut), int(ly / cut)
    cells = defaultdict(list)
    key = lambda p: (int((p[1] - box[0][0]) / lx * nx) % nx, int((p[2] - box[1][0]) / ly * ny) % ny, int(p[3] / cut))
    for i, p in d0.items():
        cells[key(p)].append(i)
    pairs = []
    for i, p in d0.items():
        cx, cy, cz = key(p)
        for ox in (-1, 0, 1):
            for oy in (-1, 0, 1):
                for oz in (-1, 0, 1):
                    for j in cells.get(((cx + ox) % nx, (cy + oy) % ny, cz + oz), ()):
                        q = d0[j]
                        if j <= i or (p[0] == 2 and q[0] == 2):
                            continue
                        r = math.sqrt(sum(c * c for c in sep(p, q)))
                        if r < p[7] + q[7] + skin:
                            pairs.append((i, j))
    steps = sorted(fr)
    tau = a.steps * dt
    # each particle's largest stray from its path over the window
    strays = []
    for i, p in d0.items():
        m = 0.0
        for s in steps[1:]:
            t = (s - a.at) * dt
            d = sep(fr[s][i], p)
            m = max(m, math.sqrt(sum((d[k] - p[4 + k] * t) ** 2 for k in range(3))))
        strays.append(m)
    strays.sort()
    touch = sum(1 for i, j in pairs if any(math.sqrt(sum(c * c for c in sep(fr[s][i], fr[s][j]))) < fr[s][i][7] + fr[s][j][7] for s in steps))
    vmax = max(math.sqrt(p[4] ** 2 + p[5] ** 2 + p[6] ** 2) for p in d0.values())
    buf = 2 * vmax * tau

    def gap(i, j):
        p, q = d0[i], d0[j]
        r = sep(p, q)
        return math.sqrt(sum(c * c for c in r)) - p[7] - q[7]

    def closest(i, j):
        p, q = d0[i], d0[j]
        r, w = sep(p, q), [p[4 + k] - q[4 + k] for k in range(3)]
        ww = sum(c * c for c in w)
        t = 0.0 if ww == 0 else max(0.0, min(tau, -sum(r[k] * w[k] for k in range(3)) / ww))
        return math.sqrt(sum((r[k] + w[k] * t) ** 2 for k in range(3))) - p[7] - q[7]

    print(f"chute, steps {a.at}..{a.at + a.steps} (dumps every 4), {n} particles; per particle:")
    print(f"  pairs within the skin at step {a.at}: {len(pairs) / n:.3f}")
    print(f"  touching at step {a.at}: {sum(1 for i, j in pairs if gap(i, j) < 0) / n:.3f}; at some dumped step of the window: {touch / n:.3f}")
    print(f"  kept by travel (buffer 2 x {vmax:.2f} x {a.steps} dt = {buf:.3e}): {sum(1 for i, j in pairs if gap(i, j) < buf) / n:.3f}")
    q = lambda f: strays[min(n - 1, int(f * n))]
    print(f"  stray from the path over the window: median {q(0.5):.2e}, 99% {q(0.99):.2e}, largest {strays[-1]:.2e}")
    cl = [closest(i, j) for i, j in pairs]
    for e in sorted({1e-4, 3e-4, 1e-3, strays[-1]}):
        print(f"  kept along paths, allowance {e:.2e}: {sum(1 for c in cl if c < 2 * e) / n:.3f}")


if __name__ == "__main__":
    main()
