#!/usr/bin/env python3
"""Issue #7: aeolian transport against the SI of Kamath, Shao & Parteli (2022).

Runs templates/saltation/ (bed preparation, then the transport run with
`fix aeolian/wind`) for
  - the erodible bed (delta_0 = 15 d_m) at several shear velocities u*, with
    the Table S1 damping as LAMMPS reads it (gamma = 0.2 1/s, variant A), and
    at one u* with gamma = 1.13e4 1/s (e ~ 0.9, variant B);
  - thin sand layers (delta_0 of a few d_m) over a rigid bed, on a sheet of
    frozen grains and on a flat wall,
measures each run with `demx saltation --json` (Q, Q-hat, Theta, delta_s,
l_nu, hops), and writes validation/saltation.md (the VALIDATION.md section)
with plots, then reassembles VALIDATION.md.

  python3 scripts/saltation_validation.py [--demx target/release/demx] [--jobs 2]
        [--lx 20] [--ly 6] [--time 3.0] [--from 1.5] [--out target/saltation] [--quick] [--reanalyse]

--lx/--ly are the periodic box in d_m (the templates' default is 40 x 6),
--time the simulated seconds of each transport run (dt = 1e-6 s), --from the
start of the averaging window. Finished runs are cached in --out (a run is
redone when its folder has no result.json). --quick: a few hundredths of a
second per run, to try the pipeline (its numbers mean nothing). --reanalyse:
measure the finished runs again with the current `demx saltation` and report
them; runs not finished are listed as not run (none is started).

Cost on the 2-core machine, one thread per run: the erodible bed of 20 x 6 d_m
holds ~2,300 grains and runs ~2,000 steps/s, so 3 s of transport take ~25 min.
"""

import argparse
import concurrent.futures as cf
import datetime
import json
import math
import os
import shutil
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TEMPLATES = os.path.join(ROOT, "templates", "saltation")
DM = 200e-6
DT = 1e-6
RHO_P, RHO_F, G = 2650.0, 1.225, 9.81
GAMMA_A, GAMMA_B = "0.2", "1.13e4"

# Creyssels et al. (2009) wind-tunnel fluxes, d = 242 um (physics note 6.1)
CREYSSELS = [(0.24, 5.25), (0.32, 12.84), (0.40, 21.09), (0.48, 32.0), (0.56, 48.85), (0.67, 79.55)]
CREY_D, CREY_RHO_P, CREY_RHO_F = 242e-6, 2500.0, 1.2365


def shields(u, rho_p=RHO_P, rho_f=RHO_F, d=DM):
    return rho_f * u * u / ((rho_p - rho_f) * G * d)


def qnorm(rho_p=RHO_P, rho_f=RHO_F, d=DM):
    """rho_p sqrt((s - 1) g d^3), kg/(m s) (SI Eq. 9)."""
    return rho_p * math.sqrt((rho_p / rho_f - 1.0) * G * d ** 3)


def kamath_q(u, a=0.5, theta_t=0.0064):
    """Q (g/(m s)) of the SI's fit Q-hat = a (Theta - Theta_t)."""
    return max(0.0, a * (shields(u) - theta_t)) * qnorm() * 1e3


def creyssels_q(u):
    """Creyssels' Q-hat(Theta), interpolated linearly, rescaled to 200 um sand (g/(m s))."""
    pts = [(shields(uc, CREY_RHO_P, CREY_RHO_F, CREY_D), q * 1e-3 / qnorm(CREY_RHO_P, CREY_RHO_F, CREY_D)) for uc, q in CREYSSELS]
    th = shields(u)
    for (t0, q0), (t1, q1) in zip(pts, pts[1:]):
        if th <= t1 or (t1, q1) == pts[-1]:
            qh = q0 + (q1 - q0) * (th - t0) / (t1 - t0)
            return max(qh, 0.0) * qnorm() * 1e3
    return float("nan")


def cases(args):
    """The runs, each with its simulated time and the start of its averaging window (s)."""
    out = []
    for u in args.ustar:
        t = args.time_at.get(u, args.time)
        out.append(dict(kind="erodible", delta0=15, sheet=0, gamma=GAMMA_A, ustar=u, time=t, avg_from=args.avg_from))
    out.append(dict(kind="erodible", delta0=15, sheet=0, gamma=GAMMA_B, ustar=args.ustar_thin, time=args.b_time, avg_from=args.b_from))
    for d0 in args.thin:
        out.append(dict(kind="thin, sheet", delta0=d0, sheet=1, gamma=GAMMA_A, ustar=args.ustar_thin, time=args.thin_time, avg_from=args.thin_from))
    for d0 in args.thin_flat:
        out.append(dict(kind="thin, flat", delta0=d0, sheet=0, gamma=GAMMA_A, ustar=args.ustar_thin, time=args.thin_time, avg_from=args.thin_from))
    return out


def bed_name(c):
    return f"bed_d{c['delta0']:g}_s{c['sheet']}_g{c['gamma']}"


def run_name(c):
    return f"run_d{c['delta0']:g}_s{c['sheet']}_g{c['gamma']}_u{c['ustar']:g}"


def sh(cmd, cwd):
    t = time.time()
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} (in {cwd}): exit {p.returncode}\n{p.stderr[-2000:]}")
    return time.time() - t, p.stdout


def loop_atoms(log):
    """Atoms of the last `Loop time` line of a demx log."""
    n = None
    with open(log) as f:
        for line in f:
            if line.startswith("Loop time of"):
                n = int(line.split(" with ")[1].split()[0])
    return n


BED_LOCKS = {}
BED_LOCKS_GUARD = threading.Lock()


def prepare_bed(args, c):
    """The settled bed of a case (made once; runs that share it wait for it)."""
    with BED_LOCKS_GUARD:
        lock = BED_LOCKS.setdefault(bed_name(c), threading.Lock())
    with lock:
        return prepare_bed_locked(args, c)


def prepare_bed_locked(args, c):
    d = os.path.join(args.out, bed_name(c))
    if os.path.exists(os.path.join(d, "bed.data")):
        return d
    os.makedirs(d, exist_ok=True)
    shutil.copy(os.path.join(TEMPLATES, "in.bed.lammps"), d)
    settle = "20000" if args.quick else "200000"
    rest = "5000" if args.quick else "50000"
    wall, _ = sh([args.demx, "run", "in.bed.lammps", "--threads", "1", "--quiet",
                  "-var", "delta0", str(c["delta0"]), "-var", "sheet", str(c["sheet"]), "-var", "gamma", c["gamma"],
                  "-var", "lx", f"{args.lx * DM:.6g}", "-var", "ly", f"{args.ly * DM:.6g}",
                  "-var", "settle", settle, "-var", "rest", rest], d)
    with open(os.path.join(d, "bed.json"), "w") as f:
        json.dump({"wall_s": wall}, f)
    return d


def transport(args, c):
    d = os.path.join(args.out, run_name(c))
    res = os.path.join(d, "result.json")
    if os.path.exists(res):
        with open(res) as fh:
            r = json.load(fh)
        if not args.reanalyse:
            return r
        wall, steps = r["wall_s"], r["steps"]
    elif args.reanalyse:
        raise RuntimeError("not run (--reanalyse measures finished runs only)")
    else:
        bed = prepare_bed(args, c)
        os.makedirs(d, exist_ok=True)
        shutil.copy(os.path.join(TEMPLATES, "in.transport.lammps"), d)
        shutil.copy(os.path.join(bed, "bed.data"), d)
        steps = int(round(c.get("time", args.time) / DT))
        wall, _ = sh([args.demx, "run", "in.transport.lammps", "--threads", "1", "--quiet",
                      "-var", "ustar", f"{c['ustar']:g}", "-var", "gamma", c["gamma"], "-var", "steps", str(steps)], d)
    bed = os.path.join(args.out, bed_name(c))
    ana = [args.demx, "saltation", "--json", "--ustar", f"{c['ustar']:g}", "--dt", f"{DT:g}", "--from", f"{c.get('avg_from', args.avg_from):g}",
           "--group-type", "1", "--delta0", str(c["delta0"]), "--hop-layer", "3", "--profile", "profile.csv", "-o", "q.csv", "--plot", "saltation.png"]
    if c["sheet"]:
        ana += ["--rigid-type", "2"]
    _, out = sh(ana + ["dump.salt"], d)
    r = dict(case=c, summary=json.loads(out), wall_s=wall, steps=steps,
             atoms=loop_atoms(os.path.join(d, "log.demx")),
             command=" ".join(["demx"] + ana[1:] + ["dump.salt"]))
    with open(os.path.join(bed, "bed.json")) as fh:
        r["bed_wall_s"] = json.load(fh)["wall_s"]
    with open(res + ".tmp", "w") as f:
        json.dump(r, f, indent=1)
    os.replace(res + ".tmp", res)
    return r


def f(x, spec=".3g", scale=1.0):
    """A number for the table ('' when missing or not finite), times `scale`."""
    return "" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x * scale, spec)


def write_section(args, results, started, finished):
    ok = [r for r in results if "summary" in r]
    ero = sorted([r for r in ok if r["case"]["kind"] == "erodible" and r["case"]["gamma"] == GAMMA_A], key=lambda r: r["case"]["ustar"])
    lines = ["## Aeolian transport (Kamath, Shao & Parteli 2022, SI)", "",
             f"Generated by `python3 scripts/saltation_validation.py{' --quick' if args.quick else ''} --lx {args.lx:g} --ly {args.ly:g} "
             f"--time {args.time:g} --from {args.avg_from:g}{args.extra_flags}{' --reanalyse' if args.reanalyse else ''}` "
             f"({'measured again ' if args.reanalyse else ''}{started}-{finished} UTC; the runs: {args.jobs} at a time on the 2-core "
             "machine, one thread each, wall times per row). Decks: templates/saltation/in.bed.lammps (grains of 160-240 um, rho 2650, settled "
             "without wind) and in.transport.lammps (gran/hooke/history with Table S1's k_n = 157, k_t = 52 N/m, mu = 0.3; "
             "`fix aeolian/wind` with Cheng's drag, two-way coupling every step, relax 0.05, bed at solid fraction 0.3). "
             f"Domain {args.lx:g} d_m x {args.ly:g} d_m periodic (d_m = 200 um), dt = {DT:g} s; each row gives its simulated time "
             "and the window its averages are taken over (the SI: 2-3 s of transient, then 5-10 s of averaging; these runs are "
             "shorter, so Q carries the noise of a short window and perhaps a transient not yet over). Transport is started "
             "by a kick of the bed's top grains (templates/saltation/README.md). "
             "Measured by `demx saltation` on the run's dump (every 0.01 s): Q (Eq. 8), Q-hat (Eq. 9), Theta (Eq. 10), the "
             "mobile-layer thickness delta_s (bed surface minus the rigid ground) beside Eq. 16, l_nu (Eq. 17, fitted from 2 d_m "
             "above the bed), and the hops of grains with |v_z| >= sqrt(6 g d_m) within 3 d_m of the bed (Eqs. 12-15, hop length "
             "with the sum u_0down + u_0up; see the physics note).", ""]
    lines += ["### Erodible bed (delta_0 = 15 d_m): Q(u*)", "",
              "| u* (m/s) | Theta | grains | simulated (s) / averaged from (s) | Q demx (g/(m s)) | Q-hat | Kamath fit a = 0.5, Theta_t = 0.0064 | Creyssels (via Q-hat(Theta)) | "
              "tau_g/tau at the bed | l_nu (d_m) | u_0 (m/s) | l_hop (mm) | hop samples (up/down) | wall (s) |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in ero:
        s, u = r["summary"], r["case"]["ustar"]
        lines.append(f"| {u:g} | {f(s['theta'], '.4f')} | {r['atoms']} | {window(r)} | {f(s['q_mean'], scale=1e3)} | {f(s['q_hat'], '.4f')} | "
                     f"{f(kamath_q(u))} | {f(creyssels_q(u))} | {f(r.get('tau_ratio'))} | {f(s['l_nu_dm'])} | {f(s['hops']['u0'])} | "
                     f"{f(s['hops']['l_hop'], scale=1e3)} | {s['hops']['samples_up']}/{s['hops']['samples_down']} | {r['wall_s']:.0f} |")
    byu = {r["case"]["ustar"]: r["summary"]["q_mean"] for r in ero}
    lines.append("")
    if 0.3 in byu and 0.5 in byu and byu[0.3] > 0:
        ratio = byu[0.5] / byu[0.3]
        lines.append(f"Q(0.5)/Q(0.3) = {ratio:.2f} (Kamath fit: {kamath_q(0.5) / kamath_q(0.3):.2f}, Creyssels: "
                     f"{creyssels_q(0.5) / creyssels_q(0.3):.2f}; a quadratic law gives ~3.5, Bagnold's cubic 4.6).")
    if len(ero) >= 2:
        xs = [shields(r["case"]["ustar"]) for r in ero]
        ys = [r["summary"]["q_hat"] for r in ero]
        n = len(xs)
        mx, my = sum(xs) / n, sum(ys) / n
        sxx = sum((x - mx) ** 2 for x in xs)
        a = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")
        b = my - a * mx
        tt = -b / a if a else float("nan")
        ut = math.sqrt(tt * (RHO_P - RHO_F) * G * DM / RHO_F) if tt > 0 else float("nan")
        lines.append(f"Least-squares line Q-hat = a Theta + b over these runs: a = {a:.3f}, b = {b:.4f}, threshold Theta_t = "
                     f"{f(tt, '.4f')} (u*_t = {f(ut, '.3f') or 'none: the line does not cross zero at a positive Theta'}" + (" m/s" if ut == ut else "") + "); the SI: a ~ 0.5, Theta_t ~ 0.0064 (u*_t ~ 0.165 m/s).")
    vb = [r for r in ok if r["case"]["kind"] == "erodible" and r["case"]["gamma"] == GAMMA_B]
    for r in vb:
        u = r["case"]["ustar"]
        same = [x for x in ero if x["case"]["ustar"] == u]
        lines.append("")
        t0, t1 = r["case"]["avg_from"], r["steps"] * DT
        a_same = window_mean(args, same[0], t0, t1) if same else None
        lines.append(f"Damping variant B (gamma = {GAMMA_B} 1/s, e ~ 0.9 for 200 um pairs) at u* = {u:g}, {window(r)}: Q = "
                     f"{f(r['summary']['q_mean'], scale=1e3)} g/(m s)" + (f" against {f(a_same, scale=1e3)} with variant A "
                     f"(gamma = {GAMMA_A} 1/s, nearly elastic normal contacts) over the same window of its run." if same else "."))
    lines += ["", "### Thin layers over a rigid bed: Q, delta_s and l_nu against delta_0", "",
              "| ground | delta_0 (d_m) | u* (m/s) | grains (mobile + rigid) | simulated (s) / averaged from (s) | Q (g/(m s)) | delta at t = 0 (d_m) | delta_s (d_m) | "
              "thinning delta(0) - delta_s (d_m) | Eq. 16 erosion C_b u*/sqrt(g d_m) (d_m) | l_nu (d_m) | u_0 (m/s) | l_hop (mm) | hop samples (up/down) | wall (s) |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    rows = sorted(ok, key=lambda r: (r["case"]["kind"], r["case"]["delta0"], r["case"]["ustar"]))
    for r in rows:
        c, s = r["case"], r["summary"]
        if c["gamma"] != GAMMA_A or (c["kind"] == "erodible" and c["ustar"] != args.ustar_thin):
            continue
        ground = {"erodible": "flat (erodible bed)", "thin, sheet": "sheet of frozen grains", "thin, flat": "flat wall"}[c["kind"]]
        lines.append(f"| {ground} | {c['delta0']:g} | {c['ustar']:g} | {r['atoms']} | {window(r)} | {f(s['q_mean'], scale=1e3)} | {f(s['delta_first_dm'])} | "
                     f"{f(s['delta_s_dm'])} | {f(s['delta_first_dm'] - s['delta_s_dm'] if s['delta_first_dm'] is not None and s['delta_s_dm'] is not None else None)} | "
                     f"{f(0.02 * c['ustar'] / math.sqrt(G * DM), '.2f')} | {f(s['l_nu_dm'])} | {f(s['hops']['u0'])} | "
                     f"{f(s['hops']['l_hop'], scale=1e3)} | {s['hops']['samples_up']}/{s['hops']['samples_down']} | {r['wall_s']:.0f} |")
    failed = [r for r in results if "error" in r]
    if failed:
        lines += ["", "Runs missing from the tables:", ""] + [f"- {run_name(r['case'])}: {r['error'].splitlines()[0]}" for r in failed]
    lines += ["", "Per run: `demx run in.bed.lammps -var delta0 D -var sheet S -var gamma G -var lx LX -var ly LY`, then "
              "`demx run in.transport.lammps -var ustar U -var gamma G -var steps N` and the `demx saltation` command in the "
              f"run's result.json (folders under {os.path.relpath(args.out, ROOT)}/). Plots of Q(t) and the concentration profile: "
              "`saltation.png` in each run folder.", ""]
    lines.insert(-1, "delta at t = 0 and delta_s are measured alike (bed surface, solid fraction 0.3, minus the ground), so their "
                 "difference holds both the erosion Eq. 16 describes and any compaction of the settled bed under transport.")
    lines.insert(-1, "")
    reading = os.path.join(ROOT, "validation", "saltation_reading.txt")
    if os.path.exists(reading):
        with open(reading) as fh:
            lines.append(fh.read().rstrip() + "\n")
    path = os.path.join(ROOT, "validation", "saltation.md")
    with open(path + ".tmp", "w") as fh:
        fh.write("\n".join(lines))
    os.replace(path + ".tmp", path)


def window(r):
    return f"{r['steps'] * DT:g} / {r['case'].get('avg_from', 0):g}"


def window_mean(args, r, t0, t1):
    """Mean Q of a run's flux series (q.csv) over t0 <= t <= t1."""
    vals = []
    with open(os.path.join(args.out, run_name(r["case"]), "q.csv")) as fh:
        for line in fh:
            w = line.split(",")
            if line.startswith(("#", "step")) or len(w) < 3:
                continue
            if t0 <= float(w[1]) <= t1 + 1e-12:
                vals.append(float(w[2]))
    return sum(vals) / len(vals) if vals else None


def tau_ratio(args, r):
    """Mean tau_g(z_b)/(rho_f u*^2) over the averaging window from the thermo (f_wind[2])."""
    log = os.path.join(args.out, run_name(r["case"]), "log.demx")
    vals, cols = [], None
    with open(log) as fh:
        for line in fh:
            w = line.split()
            if w[:2] == ["Step", "Atoms"]:
                cols = w
                continue
            if cols and len(w) == len(cols):
                try:
                    step = int(w[0])
                    if step * DT >= r["case"].get("avg_from", args.avg_from):
                        vals.append(float(w[cols.index("f_wind[2]")]))
                except ValueError:
                    cols = None
    return sum(vals) / len(vals) if vals else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--demx", default=os.path.join(ROOT, "target", "release", "demx"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--lx", type=float, default=20)
    ap.add_argument("--ly", type=float, default=6)
    ap.add_argument("--time", type=float, default=3.0)
    ap.add_argument("--from", dest="avg_from", type=float, default=1.5)
    ap.add_argument("--ustar", type=lambda s: [float(x) for x in s.split(",")], default=[0.3, 0.4, 0.5])
    ap.add_argument("--ustar-thin", type=float, default=0.4)
    ap.add_argument("--thin", type=lambda s: [float(x) for x in s.split(",")], default=[1, 2, 4])
    ap.add_argument("--thin-flat", type=lambda s: [float(x) for x in s.split(",")], default=[2])
    ap.add_argument("--time-at", default="", help="U:T,...: simulated time T for the erodible run at u* = U (default --time)")
    ap.add_argument("--b-time", type=float, default=None, help="simulated time of the damping variant B run [--time]")
    ap.add_argument("--b-from", type=float, default=None, help="its averaging start [--from]")
    ap.add_argument("--thin-time", type=float, default=None, help="simulated time of the thin-layer runs [--time]")
    ap.add_argument("--thin-from", type=float, default=None, help="their averaging start [--from]")
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "saltation"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--reanalyse", action="store_true", help="measure finished runs again from their dumps (no new runs)")
    args = ap.parse_args()
    if args.quick:
        args.time, args.avg_from = 0.03, 0.01
        args.out += "_quick"
    args.time_at = {float(k): float(v) for k, v in (x.split(":") for x in args.time_at.split(",") if x)}
    args.b_time = args.time if args.b_time is None else args.b_time
    args.b_from = args.avg_from if args.b_from is None else args.b_from
    args.thin_time = args.time if args.thin_time is None else args.thin_time
    args.thin_from = args.avg_from if args.thin_from is None else args.thin_from
    args.extra_flags = "".join(f" {k} {v}" for k, v in [("--time-at", ",".join(f"{u:g}:{t:g}" for u, t in args.time_at.items())),
                                                         ("--b-time", f"{args.b_time:g}"), ("--b-from", f"{args.b_from:g}"),
                                                         ("--thin-time", f"{args.thin_time:g}"), ("--thin-from", f"{args.thin_from:g}")] if v)
    args.out = os.path.abspath(args.out)
    os.makedirs(args.out, exist_ok=True)
    started = datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M")
    todo = cases(args)
    # beds first (shared by runs), the longest transport runs first
    todo.sort(key=lambda c: -c["delta0"])
    results = []
    with cf.ThreadPoolExecutor(args.jobs) as ex:
        futs = {ex.submit(transport, args, c): c for c in todo}
        for fu in cf.as_completed(futs):
            c = futs[fu]
            try:
                r = fu.result()
                r["tau_ratio"] = tau_ratio(args, r)
                print(f"{run_name(c)}: Q = {f(r['summary']['q_mean'], scale=1e3)} g/(m s), {r['wall_s']:.0f} s", file=sys.stderr)
            except Exception as e:  # a failed run is reported in the table
                r = dict(case=c, error=str(e))
                print(f"{run_name(c)}: FAILED {e}", file=sys.stderr)
            results.append(r)
    finished = datetime.datetime.utcnow().strftime("%H:%M")
    write_section(args, results, started, finished)
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "validation.py"), "--assemble"], check=True)


if __name__ == "__main__":
    main()
