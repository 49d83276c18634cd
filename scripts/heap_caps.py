#!/usr/bin/env python3
"""Issue #4: which normal force bounds friction and rolling in the paper's
model, measured on the heap.

The paper's Eq. 11 caps the tangential force at mu_s |F^c_n| and Eq. 15 the
rolling torque at mu_r R* |F^c_n|, F^c_n the contact (Hertz) force alone;
demx's `cohesion vdw` does so by default. The paper's code extended LIGGGHTS
of 2013-2014 (its ref. 15), whose cohesion added the attractive force to the
normal force the tangential and rolling models read: the caps then use the
net force |F^c_n + F^a_n| (LIGGGHTS 3.8 keeps that behaviour as
`tangential_reduce on`). The difference is large for fine powders: a bonded
contact at rest carries F^c_n ~ F_vdW = pi gamma d, about 1,000 times a
100 um grain's weight, so contact-force caps let no bonded grain slide or
roll, while net-force caps let it do both while it holds.

Runs templates/heap/in.heap (model paper, the paper's Y = 63 GPa unless
--y) for each diameter with `tangential_reduce off` and `on`, measures
theta_r with `demx repose`, and writes validation/heap_caps.md (then run
`python3 scripts/validation.py --assemble`). Finished results are kept in
validation/heap_caps.json, which is committed: a later session (another
machine) resumes the grid and reruns nothing already measured. Run folders
are kept under target/heap_caps/runs; a folder whose run finished is not run
again either.

  python3 scripts/heap_caps.py [--d 2e-4,1e-4] [--n 1000] [--y 6.3e10]
        [--reduce off,on] [--seeds 1] [--jobs 2] [--report]

--report: run nothing; write the section from the cache.

Cost (one thread per run): at Y = 63 GPa and N = 1000, a 200 um heap takes
about half an hour and a 100 um one a quarter of an hour to an hour
(steps per insertion interval grow as d^-1/2; a blocked column ends early).
"""

import argparse
import concurrent.futures as cf
import math
import os
import sys
import time

from heaprun import ROOT, Cache, run_heap, write_section

SEEDS = [15485863, 49979687, 67867967, 86028121, 104395301]
MU_INF, D_E = 0.447, 87e-6


def key(d, n, y, gamma, reduce, seed):
    return f"d={d!r} n={n} Y={y!r} gamma={gamma!r} reduce={reduce} seed={seed}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--demx", default=os.path.join(ROOT, "target/release/demx"))
    ap.add_argument("--d", default="2e-4,1e-4")
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--y", type=float, default=6.3e10)
    ap.add_argument("--gamma", type=float, default=0.05)
    ap.add_argument("--reduce", default="off,on")
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--report", action="store_true")
    ap.add_argument("--runs", default=os.path.join(ROOT, "target/heap_caps/runs"))
    ap.add_argument("--cache", default=os.path.join(ROOT, "validation/heap_caps.json"))
    ap.add_argument("--out", default=os.path.join(ROOT, "validation/heap_caps.md"))
    a = ap.parse_args()
    ds = [float(x) for x in a.d.split(",")]
    reduces = a.reduce.split(",")
    cache = Cache(a.cache)
    jobs = [(d, r, s) for d in ds for r in reduces for s in SEEDS[:a.seeds]]
    todo = [j for j in jobs if cache.get(key(j[0], a.n, a.y, a.gamma, j[1], j[2])) is None]
    if todo and not a.report:
        if not os.path.exists(a.demx):
            sys.exit("build first: cargo build --release")

        def one(job):
            d, r, s = job
            folder = os.path.join(a.runs, f"d{d:g}-n{a.n}-Y{a.y:g}-g{a.gamma:g}-reduce_{r}-seed{s}")
            variables = {"model": "paper", "d": repr(d), "N": a.n, "Y": repr(a.y), "gamma": repr(a.gamma), "reduce": r, "seed": s}
            return run_heap(a.demx, folder, variables, gamma=a.gamma)

        with cf.ThreadPoolExecutor(a.jobs) as ex:
            futs = {ex.submit(one, j): j for j in todo}
            for f in cf.as_completed(futs):
                d, r, s = futs[f]
                res = f.result()
                if "theta" in res:
                    res.update(d=d, n=a.n, Y=a.y, gamma=a.gamma, reduce=r, seed=s)
                    cache.put(key(d, a.n, a.y, a.gamma, r, s), res)
                print(f"d={d:g} reduce={r} seed={s}: "
                      + (f"theta_r={res['theta']:.2f} on the plate {res['particles']} wall={res['wall']:.0f}s" if "theta" in res
                         else res.get("error", "?")), file=sys.stderr, flush=True)

    lines = [
        "## Cohesive heap: contact-force or net-force caps (`scripts/heap_caps.py`)", "",
        f"Deck templates/heap/in.heap, model paper (viscoelastic Hertz, the paper's tangential and rolling laws, Hamaker "
        "van der Waals with D_min = 1.65 Å, D_max = 1 µm, γ as the row says; the paper's Table 1 has 0.05 J/m²), g = 9.81 m/s², one thread per run, seeds from 15485863 on. `off`: the Coulomb and rolling caps use the contact force |F^c_n| "
        "(Eqs. 11 and 15 as printed; LIGGGHTS 3.8's default for its cohesion models); `on` (`tangential_reduce on`): "
        "the net normal force |F^c_n + F^a_n|, as LIGGGHTS's cohesion did before 3.8 and so, we take it, the paper's "
        "LIGGGHTS-based code. θr from the last frame (`demx repose`, mean of the two projections, ± their SD); "
        f"Eq. 1 with the paper's fit (μ_eff,∞ = {MU_INF}, D = {D_E * 1e6:g} µm).", "",
        "| d (µm) | N poured | Y (Pa) | γ (J/m²) | Bo = 12γ/(d²gρ) | paper Eq. 1 (°) | caps | seeds | θr (°) | on the plate | heap height (d) | particle-steps | wall time / run (s) | finished |",
        "|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    # every measured case in the cache, not only this invocation's grid
    groups = {}
    for res in cache.data.values():
        groups.setdefault((res["d"], res["n"], res["Y"], res["gamma"], res["reduce"]), []).append(res)
    for (d, n, y, gamma, r) in sorted(groups, key=lambda g: (g[3], -g[2], -g[0], g[1], g[4])):
        ok = groups[(d, n, y, gamma, r)]
        bo = 12 * gamma / (d ** 2 * 9.81 * 2500)
        eq1 = math.degrees(math.atan(MU_INF * (1 + D_E / d)))
        th = [x["theta"] for x in ok]
        per = [v for x in ok for v in (x["theta_xz"], x["theta_yz"])]
        mean = sum(th) / len(th)
        sd = (sum((v - mean) ** 2 for v in per) / max(len(per) - 1, 1)) ** 0.5
        avg = lambda f: sum(x[f] for x in ok) / len(ok)
        walls = [x["wall"] for x in ok if x.get("wall")]
        lines.append(f"| {d * 1e6:g} | {n} | {y:g} | {gamma:g} | {bo:.3g} | {eq1:.1f} | {r} | {len(ok)} | {mean:.1f} ± {sd:.1f} | {avg('particles'):.0f} "
                     f"| {avg('height') / d:.1f} | {avg('psteps'):.3g} | "
                     + (f"{sum(walls) / len(walls):.0f}" if walls else "-") + f" | {max(x['finished'] for x in ok)} |")
    missing = [j for j in jobs if cache.get(key(j[0], a.n, a.y, a.gamma, j[1], j[2])) is None]
    if missing:
        lines += ["", "Not run yet: " + "; ".join(f"d = {d * 1e6:g} µm, N = {a.n}, {r}, seed {s}" for d, r, s in missing) + "."]
    reading = os.path.join(os.path.dirname(a.out), "heap_caps_reading.txt")
    if os.path.exists(reading):
        lines += ["", open(reading).read().strip()]
    lines += ["", "Command: `python3 scripts/heap_caps.py " + " ".join(sys.argv[1:]) + "` (results kept in "
              "validation/heap_caps.json; `--report` rewrites this section from them)", ""]
    write_section(a.out, lines)


if __name__ == "__main__":
    main()
