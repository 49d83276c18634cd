#!/usr/bin/env python3
"""Benchmarks demx against the real LIGGGHTS 3.8 and LAMMPS on the same decks in
the same run, interleaved, and writes BENCHMARKS.md: median particle-steps/s of
each program, their ratio, peak memory, where the time goes (each program's own
section timing), the machine, the date and this command.

Usage: python3 scripts/bench.py [--reps 5] [--only a,b1,...] [--quick]
Needs `cargo build --release` first; makes its inputs once in target/bench/.

Decks (bench/ and ../shared/bench/chute, as the performance issue lists them):
  a   settled bed of 30,000 Hertz spheres, tangential history (LIGGGHTS dialect);
      one thread vs one rank, and two threads vs `mpirun -np 2`
  b1  the same bed with rolling friction epsd2;  b2  with cohesion sjkr
  c   the LAMMPS chute-flow benchmark (gran/hooke/history, 32,000 particles)
  d   the stock heap template at d = 1 mm and full glass stiffness (Y = 63 GPa),
      the first chunks of the pour
  e   scaling: the bed tiled from 7,500 to 1,080,000 particles (demx alone)
  f   Debian's meshGran tutorial (LIGGGHTS): spheres streamed into a hopper of
      triangle-mesh walls, its second run cut to 20,000 steps in all
  g   isotropic compression of 15,625 grains between six moving STL plates
      (bench/compression: mesh/surface/stress x 6, move/mesh linear, rolling
      friction; the deck the performance issue found 5x slower), one thread vs
      one rank and two threads vs `mpirun -np 2`
The bed is made by bench/in.bed_prepare.liggghts (7,500 spheres settled in a
20 x 20 mm periodic box) and tiled in x and y.
"""
import argparse, datetime, os, re, shutil, statistics, subprocess, sys

from mdblock import replace_block

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEMX = os.path.join(ROOT, "target", "release", "demx")
WORK = os.path.join(ROOT, "target", "bench")
CHUTE = os.path.join(os.path.dirname(ROOT), "shared", "bench", "chute")
MESHGRAN = "/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public/meshGran"
PROFILE_BEGIN, PROFILE_END = "<!-- bench:begin (scripts/bench.py) -->", "<!-- bench:end -->"


def prepare_meshgran():
    """The meshGran tutorial in target/bench/meshGran (it reads meshes/ and
    writes post/ where it runs), its last run ending at step ${nsteps}."""
    d = os.path.join(WORK, "meshGran")
    os.makedirs(os.path.join(d, "post"), exist_ok=True)
    shutil.copytree(os.path.join(MESHGRAN, "meshes"), os.path.join(d, "meshes"), dirs_exist_ok=True)
    text = open(os.path.join(MESHGRAN, "in.meshGran")).read()
    deck = re.sub(r"^run\s+40000 upto", "run ${nsteps} upto", text, flags=re.M)
    if deck == text:
        raise RuntimeError("in.meshGran: its `run 40000 upto` line was not found")
    with open(os.path.join(d, "in.meshGran"), "w") as f:
        f.write(deck)
    return d


def prepare_compression():
    """The compression deck and its six plates in target/bench/compression."""
    d = os.path.join(WORK, "compression")
    os.makedirs(d, exist_ok=True)
    shutil.copy(os.path.join(ROOT, "bench", "compression", "in.compression"), d)
    subprocess.run([sys.executable, os.path.join(ROOT, "bench", "compression", "make_plates.py"), d], check=True)
    return d


def run(cmd, cwd, env=None):
    p = subprocess.run(["/usr/bin/time", "-f", "MAXRSS %M"] + cmd, cwd=cwd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed in {cwd}:\n{p.stdout[-1500:]}\n{p.stderr[-1500:]}")
    rss = int(re.search(r"MAXRSS (\d+)", p.stderr).group(1))
    return p.stdout, rss


def loops(text):
    """All runs of a log: (loop seconds, steps, atoms) per `Loop time` line."""
    return [(float(t), int(n), int(a)) for t, n, a in
            re.findall(r"Loop time of ([0-9.eE+-]+) on \d+ procs(?: \(\d+ threads\))? for (\d+) steps with (\d+) atoms", text)]


def sections(text, engine):
    """Seconds per section of the last run, as the program prints them."""
    out = {}
    if engine == "demx":
        for name, t in re.findall(r"^(Pair|Neigh|Modify|Output)\s*\|\s*([0-9.eE+-]+)", text, re.M):
            out[name] = out.get(name, 0.0) + float(t)
    else:
        # LIGGGHTS: "Pair  time (%) = 7.73 (88.8)"; LAMMPS: "Pair    | 1.23 | 1.23 | 1.23 | 0.0 | 88.8"
        for name, t in re.findall(r"^(Pair|Neigh|Comm|Output|Outpt|Modify|Other)\s+time \(%\) = ([0-9.eE+-]+)", text, re.M):
            out[name] = out.get(name, 0.0) + float(t)
        for name, t in re.findall(r"^(Pair|Neigh|Comm|Output|Modify|Other)\s*\|\s*([0-9.eE+-]+)", text, re.M):
            out[name] = out.get(name, 0.0) + float(t)
    return out


def rate(text):
    ls = loops(text)
    secs = sum(t for t, _, _ in ls)
    psteps = sum(n * a for _, n, a in ls)
    return psteps / secs, psteps, secs


def prepare_bed():
    """The settled 7,500-sphere bed (target/bench/bed.data), made once."""
    os.makedirs(WORK, exist_ok=True)
    bed = os.path.join(WORK, "bed.data")
    if not os.path.exists(bed):
        print("preparing the bed (7,500 spheres settling, a few minutes)", flush=True)
        run([DEMX, "run", os.path.join(ROOT, "bench", "in.bed_prepare.liggghts"), "-var", "out", "bed.data.tmp", "--log", "none"], WORK)
        os.replace(os.path.join(WORK, "bed.data.tmp"), bed)
    return bed


def tiles(quick):
    """The scaling beds' tilings (x, y) of the 7,500-sphere bed: 7,500 and
    15,000 on either side of the performance issue's 10^4, up to 1,080,000."""
    return [(1, 1), (2, 2)] if quick else [(1, 1), (2, 1), (2, 2), (4, 4), (8, 8), (12, 12)]


def prepare(quick):
    bed = prepare_bed()
    for nx, ny in tiles(quick):
        out = os.path.join(WORK, f"bed{nx}x{ny}.data")
        if not os.path.exists(out):
            tile_data(bed, out, nx, ny)
    chute = os.path.join(WORK, "data.chute")
    if not os.path.exists(chute):
        print("preparing data.chute (LAMMPS settles the generated lattice, about a minute)", flush=True)
        subprocess.run([sys.executable, os.path.join(CHUTE, "gen_chute_init.py")], cwd=WORK, check=True, capture_output=True)
        run(["lmp", "-in", os.path.join(CHUTE, "settle_chute.lmp"), "-log", "none"], WORK)
    return bed


CEILING = {}


def tile_data(src, dst, nx, ny):
    """Copies of a periodic bed side by side in x and y (ids renumbered)."""
    box, atoms, vel, sec = {}, [], {}, None
    for line in open(src):
        w = line.split()
        if len(w) == 4 and w[2] in ("xlo", "ylo", "zlo"):
            box[w[2][0]] = (float(w[0]), float(w[1]))
        elif w and w[0] in ("Atoms", "Velocities"):
            sec = w[0]
        elif sec == "Atoms" and len(w) >= 7:
            atoms.append(w)
        elif sec == "Velocities" and len(w) >= 7:
            vel[w[0]] = w[1:7]
    lx, ly = box["x"][1] - box["x"][0], box["y"][1] - box["y"][0]
    n = len(atoms) * nx * ny
    head = [f"bench bed tiled {nx} x {ny} (scripts/bench.py)", "", f"{n} atoms", "1 atom types", "",
            f"{box['x'][0]!r} {box['x'][0] + nx * lx!r} xlo xhi", f"{box['y'][0]!r} {box['y'][0] + ny * ly!r} ylo yhi",
            f"{box['z'][0]!r} {box['z'][1]!r} zlo zhi", "", "Atoms", ""]
    body, vbody, t = [], ["", "Velocities", ""], 0
    for i in range(nx):
        for j in range(ny):
            for w in atoms:
                t += 1
                body.append(f"{t} {w[1]} {w[2]} {w[3]} {float(w[4]) + i * lx!r} {float(w[5]) + j * ly!r} {w[6]}")
                vbody.append(f"{t} " + " ".join(vel.get(w[0], ["0"] * 6)))
    with open(dst + ".tmp", "w") as f:
        f.write("\n".join(head + body + vbody) + "\n")
    os.replace(dst + ".tmp", dst)


def demx_cmd(deck, threads, var):
    cmd = [DEMX, "run", deck, "--log", "none", "--threads", str(threads)]
    for k, v in var.items():
        cmd += ["-var", k, str(v)]
    return cmd


def engine_cmd(engine, deck, ranks, var):
    exe = {"liggghts": "liggghts", "lammps": "lmp"}[engine]
    cmd = ([] if ranks == 1 else ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)]) + [exe, "-in", deck, "-log", "none"]
    for k, v in var.items():
        cmd += ["-var", k, str(v)]
    return cmd


# The spread of a program's repetitions (fastest over slowest) above which
# a row is flagged: runs of one binary on a quiet machine stay within a few
# percent of each other.
UNSTEADY = 1.15


def case(name, deck, engine, var, reps, threads=1, ranks=1, engine_deck=None, cwd=WORK):
    """Interleaved runs of demx and the engine; medians."""
    d_ps, e_ps, d_rss, e_rss, d_sec, e_sec = [], [], [], [], [], []
    for _ in range(reps):
        out, rss = run(demx_cmd(deck, threads, var), cwd)
        d_ps.append(rate(out)[0]); d_rss.append(rss); d_sec.append(sections(out, "demx"))
        if engine:
            out, rss = run(engine_cmd(engine, engine_deck or deck, ranks, var), cwd)
            e_ps.append(rate(out)[0]); e_rss.append(rss); e_sec.append(sections(out, engine))
    md = statistics.median(d_ps)
    me = statistics.median(e_ps) if e_ps else None
    spread = lambda v: max(v) / min(v) if v and min(v) > 0 else None
    row = dict(name=name, demx=md, engine=me, eng=engine, ranks=ranks, threads=threads, drss=max(d_rss),
               dspread=spread(d_ps), espread=spread(e_ps),
               erss=max(e_rss) if e_rss else None, dsec=d_sec[len(d_sec) // 2], esec=e_sec[len(e_sec) // 2] if e_sec else None,
               atoms=loops(out)[-1][2] if loops(out) else 0)
    ratio = f", ratio {md / me:.2f}" if me else ""
    print(f"{name}: demx {md:.3e}" + (f", {engine} {me:.3e}" if me else "") + ratio, flush=True)
    return row


def ceiling(deck, var, reps):
    """The machine's own limit for two threads: two one-thread demx runs at
    once (separate processes, no shared data), their summed rate per run;
    median over `reps`. Against one run alone it shows what two cores give
    when both are busy (shared cache, memory, clock)."""
    from concurrent.futures import ThreadPoolExecutor
    sums = []
    for _ in range(reps):
        with ThreadPoolExecutor(2) as ex:
            outs = list(ex.map(lambda _: run(demx_cmd(deck, 1, var), WORK)[0], range(2)))
        sums.append(sum(rate(o)[0] for o in outs))
    m = statistics.median(sums)
    print(f"two one-thread runs at once: {m:.3e} together", flush=True)
    return m


def own_two(deck, var, reps):
    """demx's two threads against its one on the same deck, interleaved in
    one loop (one thread, then two, `reps` rounds): the issue's 1.8x is a
    ratio of demx to itself, and the two table rows come from runs minutes
    apart, between which this machine's speed moves by more than the margin.
    Medians of each, and the median of the per-round ratios."""
    one, two = [], []
    for _ in range(reps):
        one.append(rate(run(demx_cmd(deck, 1, var), WORK)[0])[0])
        two.append(rate(run(demx_cmd(deck, 2, var), WORK)[0])[0])
    r = dict(one=statistics.median(one), two=statistics.median(two), ratio=statistics.median(t / o for o, t in zip(one, two)))
    print(f"demx 2 threads / 1 thread, interleaved: {r['two']:.3e} / {r['one']:.3e}, per-round ratio {r['ratio']:.2f}", flush=True)
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--only", default="a,a2,b1,b2,c,d,e,f,g")
    ap.add_argument("--quick", action="store_true", help="small beds and few steps (checks the harness)")
    ap.add_argument("--steps", type=int, default=1000, help="steps per bed run (the chute runs twice as many)")
    ap.add_argument("--out", default=os.path.join(ROOT, "BENCHMARKS.md"))
    a = ap.parse_args()
    only = a.only.split(",")
    prepare(a.quick)
    bench = lambda f: os.path.join(ROOT, "bench", f)
    big = "bed1x1.data" if a.quick else "bed2x2.data"
    steps = 100 if a.quick else a.steps
    rows = []
    if "a" in only:
        rows.append(case("(a) settled bed, Hertz + history, 1 thread / 1 rank", bench("in.bed.liggghts"), "liggghts",
                         dict(data=big, nsteps=steps), a.reps))
    if "a2" in only:
        CEILING["both"] = ceiling(bench("in.bed.liggghts"), dict(data=big, nsteps=steps), a.reps)
        CEILING["own"] = own_two(bench("in.bed.liggghts"), dict(data=big, nsteps=steps), a.reps)
        rows.append(case("(a) bed, 2 threads / `mpirun -np 2`", bench("in.bed.liggghts"), "liggghts",
                         dict(data=big, nsteps=steps), a.reps, threads=2, ranks=2))
    if "b1" in only:
        rows.append(case("(b1) bed + rolling friction epsd2", bench("in.bed_rolling.liggghts"), "liggghts",
                         dict(data=big, nsteps=steps), a.reps))
    if "b2" in only:
        rows.append(case("(b2) bed + cohesion sjkr", bench("in.bed_cohesion.liggghts"), "liggghts",
                         dict(data=big, nsteps=steps), a.reps))
    if "c" in only:
        chute = os.path.join(CHUTE, "in.chute")
        rows.append(case("(c) LAMMPS chute benchmark, gran/hooke/history", chute, "lammps",
                         dict(nsteps=steps * 2), a.reps))
        rows.append(case("(c) chute, LIGGGHTS translation (in.chute.liggghts)", os.path.join(CHUTE, "in.chute.liggghts"), "liggghts",
                         dict(nsteps=steps * 2), a.reps))
    if "d" in only:
        rows.append(case("(d) stock heap, d = 1 mm, Y = 63 GPa, first chunks of the pour",
                         os.path.join(ROOT, "templates", "heap", "in.heap"), "liggghts",
                         dict(model="stock", Y="6.3e10", N=100 if a.quick else 300, relax=1), 1 if a.quick else min(3, a.reps)))
    if "f" in only:
        mg = prepare_meshgran()
        rows.append(case("(f) meshGran tutorial, mesh walls + insert/stream, 20,000 steps", os.path.join(mg, "in.meshGran"), "liggghts",
                         dict(nsteps=11000 if a.quick else 20000), 1 if a.quick else min(3, a.reps), cwd=mg))
    if "g" in only:
        cd = prepare_compression()
        deck = os.path.join(cd, "in.compression")
        var = dict(nsteps=400 if a.quick else 4000)
        reps = 1 if a.quick else min(3, a.reps)
        rows.append(case("(g) compression, six moving STL plates, 1 thread / 1 rank", deck, "liggghts", var, reps, cwd=cd))
        rows.append(case("(g) compression, 2 threads / `mpirun -np 2`", deck, "liggghts", var, reps, threads=2, ranks=2, cwd=cd))
    scaling = []
    if "e" in only:
        for nx, ny in tiles(a.quick):
            n = 7500 * nx * ny
            nsteps = max(20 if a.quick else 100, int((2e5 if a.quick else 2e7) / n))
            r = case(f"(e) bed {n:,} spheres", bench("in.bed.liggghts"), None, dict(data=f"bed{nx}x{ny}.data", nsteps=nsteps),
                     1 if a.quick else min(3, a.reps))
            r["n"], r["steps"] = n, nsteps
            scaling.append(r)
    write(a, rows, scaling)


def fmt_sec(s, total_keys):
    if not s:
        return ""
    tot = sum(s.values()) or 1.0
    return ", ".join(f"{k} {100 * s[k] / tot:.0f}%" for k in total_keys if k in s)


def write(a, rows, scaling):
    cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    model = next((l.split(":", 1)[1].strip() for l in cpu.splitlines() if l.startswith("Model name")), "unknown")
    cmd = "python3 scripts/bench.py" + "".join(f" {x}" for x in sys.argv[1:])
    lines = [PROFILE_BEGIN, "",
             f"Generated by `{cmd}` (after `cargo build --release`) on {datetime.date.today()}, {model}, {os.cpu_count()} cores.",
             f"Each case runs demx and the engine on the same deck, interleaved, {a.reps} times each (the heap and the scaling",
             f"rows {min(3, a.reps)} times; the scaling rows demx alone); figures are medians of particle-steps per second from each program's own",
             "`Loop time` lines (summed over the runs of a deck), so start-up is excluded. Peak memory is the maximum resident",
             "set size of the whole process (`/usr/bin/time -f %M`).", "",
             "| case | particles (end) | demx (particle-steps/s) | engine (particle-steps/s) | ratio demx/engine | peak RSS demx / engine (MB) |",
             "| --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        eng = f"{r['engine']:.3e} ({r['eng']}{', ' + str(r['ranks']) + ' ranks' if r['ranks'] > 1 else ', 1 rank'})" if r["engine"] else "-"
        ratio = f"{r['demx'] / r['engine']:.2f}" if r["engine"] else "-"
        rss = f"{r['drss'] / 1024:.0f} / {r['erss'] / 1024:.0f}" if r["erss"] else f"{r['drss'] / 1024:.0f}"
        lines.append(f"| {r['name']} (demx --threads {r['threads']}) | {r['atoms']:,} | {r['demx']:.3e} | {eng} | {ratio} | {rss} |")
    # a median hides a slow repetition: the spread of each program's
    # repetitions shows whether the machine's speed moved during a case (a
    # machine slow for a whole case shows only against earlier tables)
    named = rows + [dict(r, name=f"(e) {r['n']} spheres") for r in scaling]
    label = lambda r: r["name"].split(",")[0]
    spreads = [(r, k, r[k]) for r in named for k in ("dspread", "espread") if r.get(k)]
    if spreads:
        lines += ["", "Spread of the repetitions (fastest over slowest, each program): " + "; ".join(
            f"{label(r)} demx {r['dspread']:.2f}" + (f", {r['eng']} {r['espread']:.2f}" if r.get("espread") else "")
            for r in named if r.get("dspread")) + "."]
        unsteady = [(r, k, v) for r, k, v in spreads if v > UNSTEADY]
        if unsteady:
            lines += ["", "**Unsteady rows:** " + "; ".join(
                f"{label(r)} {'demx' if k == 'dspread' else r['eng']} ({v:.2f})" for r, k, v in unsteady) +
                f": one program's repetitions differ by more than {100 * (UNSTEADY - 1):.0f}%, so the machine's speed moved "
                "during the case. Their figures are not to be trusted; run the bench again (`--only` writes a table of the cases it runs "
                "alone)."]
    one = next((r["demx"] for r in rows if r["name"].startswith("(a) settled bed")), None)
    if CEILING.get("both") and one:
        lines += ["", f"What two cores give this machine: two one-thread demx runs of (a) at once (separate processes) ran at "
                  f"{CEILING['both']:.3e} particle-steps/s together, {CEILING['both'] / one:.2f}x one run alone (median of {a.reps}); "
                  "demx's own 2-thread figure is best read against that."]
    own = CEILING.get("own")
    if own:
        lines += ["", f"demx's two threads against its one, interleaved in one loop ({a.reps} rounds of one run each, "
                  f"one thread then two): {own['two']:.3e} against {own['one']:.3e} particle-steps/s, per-round ratio "
                  f"{own['ratio']:.2f} (median); the two table rows above come from runs minutes apart."]
        two = next((r["demx"] for r in rows if r["name"].startswith("(a) bed, 2 threads")), None)
        if one and two and abs((two / one) / own["ratio"] - 1) > 0.15:
            # the rows' ratio far from the loop's: a run lost its second
            # core (on a shared machine another tenant takes it at times)
            lines += ["", f"**Disturbed run:** the table's two (a) rows give {two / one:.2f}x for two threads against one, "
                      f"the loop above {own['ratio']:.2f}x; a run of one of them lost a core to the machine. Read the "
                      "loop's ratio, and run the bench again for the table."]
    lines += ["", "Where the time goes (the median run's section timing, as each program prints it):", "",
              "| case | demx | engine |", "| --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r['name']} | {fmt_sec(r['dsec'], ['Pair', 'Neigh', 'Modify', 'Output'])} | "
                     f"{fmt_sec(r['esec'], ['Pair', 'Neigh', 'Comm', 'Modify', 'Outpt', 'Output', 'Other'])} |")
    if scaling:
        base = scaling[0]["demx"]
        lines += ["", "Scaling (demx, one thread; the bed tiled in x and y):", "",
                  "| particles | steps | particle-steps/s | relative to the smallest | peak RSS (MB) | bytes per particle |",
                  "| --- | --- | --- | --- | --- | --- |"]
        for r in scaling:
            lines.append(f"| {r['n']:,} | {r['steps']} | {r['demx']:.3e} | {r['demx'] / base:.2f} | {r['drss'] / 1024:.0f} | "
                         f"{r['drss'] * 1024 / r['n']:.0f} |")
        # the range: 10^4 to 10^6 particles (1,080,000 counted as 10^6)
        within = [r for r in scaling if 1e4 <= r["n"] <= 1.1e6]
        if len(within) > 1:
            lo, hi = min(within, key=lambda r: r["demx"]), max(within, key=lambda r: r["demx"])
            lines += ["", f"From {within[0]['n']:,} to {within[-1]['n']:,} particles (the issue's 10^4 to 10^6): the slowest "
                          f"({lo['n']:,}, {lo['demx']:.3e}) is {100 * (1 - lo['demx'] / hi['demx']):.0f}% below the fastest "
                          f"({hi['n']:,}, {hi['demx']:.3e})."]
    lines += ["", PROFILE_END]
    replace_block(a.out, PROFILE_BEGIN, PROFILE_END, "\n".join(lines), "# Benchmarks")
    print("wrote", a.out)


if __name__ == "__main__":
    main()
