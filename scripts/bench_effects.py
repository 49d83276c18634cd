#!/usr/bin/env python3
"""What each contact effect costs: demx particle-steps/s on one bed with the
effects a scene can call for switched on one by one, and the cost of the
aeolian wind fix. Writes the "Effect costs" section of BENCHMARKS.md (between
its markers; the rest of the file is scripts/bench.py's).

Usage: python3 scripts/bench_effects.py [--reps 9] [--steps 1000]
Needs `cargo build --release` first.

The bed is bench/in.bed.liggghts on the settled 7,500-sphere bed that
scripts/bench.py prepares (target/bench/bed1x1.data): the spheres rest, so
every variant walks the same contacts and only the pair kernel differs (a
settling scene would not do: cohesion and rolling change how many contacts
form). The wall keeps plain Hertz.
"Switched off" means the scene does not name the effect (demx builds a kernel
without it); "switched on with a zero coefficient" names it with mu_r = 0,
which still runs its code on every contact.
"""
import argparse, datetime, os, re, statistics, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEMX = os.path.join(ROOT, "target", "release", "demx")
BEGIN, END = "<!-- effects:begin (scripts/bench_effects.py) -->", "<!-- effects:end -->"

ROLL = "fix mr all property/global coefficientRollingFriction peratomtypepair 1 {mu}\n"
COH = "fix mc all property/global cohesionEnergyDensity peratomtypepair 1 3000\n"
PAIR = "pair_style      gran model hertz tangential history"
PAPER = (ROLL.format(mu=0.1) + "fix mv all property/global restitutionReferenceVelocity scalar 1.0\n"
         "fix ms all property/global surfaceEnergy peratomtypepair 1 0.05\n"
         "fix md all property/global vdwMinDistance scalar 1.65e-10\nfix mx all property/global vdwCutoff scalar 1e-6\n")
EFFECTS = [
    ("Hertz + tangential history (alone)", "", ""),
    ("+ rolling friction epsd2 (mu_r = 0.1)", " rolling_friction epsd2", ROLL.format(mu=0.1)),
    ("+ cohesion sjkr", " cohesion sjkr", COH),
    ("+ cohesion sjkr + rolling epsd2", " cohesion sjkr rolling_friction epsd2", COH + ROLL.format(mu=0.1)),
    ("+ rolling friction epsd2 with mu_r = 0", " rolling_friction epsd2", ROLL.format(mu=0.0)),
    ("the paper's model (viscoelastic Hertz, history/paper, van der Waals, epsd/paper)",
     "=model hertz/viscoelastic tangential history/paper cohesion vdw rolling_friction epsd/paper", PAPER),
]

WIND_DECK = """# a sand bed settling onto a wall, periodic in x and y: 16 x 16 x 8 grains of
# 200 um on a 250 um lattice (16 spacings fit the box exactly, so the
# periodic images of the last column do not overlap the first)
atom_style      sphere
atom_modify     map array
boundary        p p f
comm_modify     vel yes
units           si
region          box block 0 0.004 0 0.004 0 0.02 units box
create_box      1 box
lattice         sc 2.5e-4
region          bed block 0 0.004 0 0.004 1e-4 0.0021 units box
create_atoms    1 region bed
set             type 1 diameter 2e-4
set             type 1 density 2650
pair_style      gran/hooke/history 157 52 0.2 0.2 0.3 1
pair_coeff      * *
neighbor        4e-5 bin
neigh_modify    delay 0
fix             floor all wall/gran hooke/history 157 52 0.2 0.2 0.3 1 zplane 0.0 NULL
fix             nve all nve/sphere
fix             grav all gravity 9.81 vector 0 0 -1
{wind}
timestep        2e-7
thermo          1000
run             {steps}
"""
WIND_FIX = ("fix             wind all aeolian/wind 0.4 6.667e-6 1.225 1.5e-5 drag cheng "
            "grid stretch 1.0e-4 0.01 1.1 0.05 bed phi 0.3 every 1 relax 0.05")


def run(deck, cwd):
    p = subprocess.run([DEMX, "run", deck, "--log", "none", "--threads", "1"], cwd=cwd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{deck} failed: {p.stderr[-800:]}")
    m = re.search(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms", p.stdout)
    t, n, at = float(m.group(1)), int(m.group(2)), int(m.group(3))
    return n * at / t


def bed_variant(extra_model, extra_props, steps, data):
    """bench/in.bed.liggghts with the pair_style line extended."""
    with open(os.path.join(ROOT, "bench/in.bed.liggghts")) as f:
        text = f.read()
    out = []
    for line in text.splitlines():
        w = line.split()
        if line.startswith(PAIR) and extra_model.startswith("="):
            line = extra_props + "pair_style gran " + extra_model[1:]
        elif line.startswith(PAIR):
            line = extra_props + PAIR + extra_model
        elif w[:2] == ["variable", "data"]:
            line = f"variable data index {data}"
        elif w[:2] == ["variable", "nsteps"]:
            line = f"variable nsteps index {steps}"
        out.append(line)
    return "\n".join(out) + "\n"


def measure(decks, reps, tmp):
    """Interleaved: one run of every deck per repetition; (median, fastest)."""
    paths = []
    for k, text in enumerate(decks):
        p = os.path.join(tmp, f"in.case{k}")
        with open(p, "w") as f:
            f.write(text)
        paths.append(p)
    got = [[] for _ in decks]
    for _ in range(reps):
        for k, p in enumerate(paths):
            got[k].append(run(p, tmp))
    for g in got:
        print(" ".join(f"{v:.3e}" for v in g), file=sys.stderr, flush=True)
    return [(statistics.median(g), max(g)) for g in got]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=9)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--wind-steps", type=int, default=4000)
    ap.add_argument("--out", default=os.path.join(ROOT, "BENCHMARKS.md"))
    a = ap.parse_args()
    cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    model = next((l.split(":", 1)[1].strip() for l in cpu.splitlines() if l.startswith("Model name")), "unknown")
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    import bench
    bed = bench.prepare_bed()
    with tempfile.TemporaryDirectory() as tmp:
        eff = measure([bed_variant(m, p, a.steps, bed) for _, m, p in EFFECTS], a.reps, tmp)
        wind = measure([WIND_DECK.format(wind="", steps=a.wind_steps), WIND_DECK.format(wind=WIND_FIX, steps=a.wind_steps)], a.reps, tmp)
    cmd = "python3 scripts/bench_effects.py" + ("" if a.reps == 9 else f" --reps {a.reps}") + ("" if a.steps == 1000 else f" --steps {a.steps}")
    lines = [BEGIN, "## Effect costs (demx only)", "",
             f"Generated by `{cmd}` (after `cargo build --release`) on {datetime.date.today()}, {model}, "
             f"{os.cpu_count()} cores; demx --threads 1, {a.reps} interleaved repetitions, the median and the fastest "
             "run's particle-steps/s from demx's "
             "`Loop time` line. Bed: bench/in.bed.liggghts, the settled 7,500-sphere bed of scripts/bench.py "
             f"({a.steps} steps; the spheres rest, so every variant has the same contacts), with only the pair_style changed. An effect the scene does not name is not in its kernel "
             "(demx picks the kernel once per scene); naming rolling friction with mu_r = 0 still pays for its code.", "",
             "On this virtual machine other tenants take 2-35% of the CPU at times (`vmstat` steal), which only slows "
             "runs down: the fastest run is the closest to the undisturbed cost, and the spread between median and fastest "
             "shows the noise.", "",
             "| pair model | particle-steps/s, median | fastest | fastest relative to Hertz alone |", "| --- | --- | --- | --- |"]
    for (name, _, _), (med, best) in zip(EFFECTS, eff):
        lines.append(f"| {name} | {med:.3e} | {best:.3e} | {best / eff[0][1]:.2f} |")
    lines += ["", f"Wind: a periodic 4 mm x 4 mm bed of 200 um grains (gran/hooke/history, {a.wind_steps} steps of 2e-7 s), without "
              "and with `fix aeolian/wind` (two-way coupling every step, the costliest setting):", "",
              "| scene | particle-steps/s, median | fastest | fastest relative |", "| --- | --- | --- | --- |",
              f"| bed without wind | {wind[0][0]:.3e} | {wind[0][1]:.3e} | 1.00 |",
              f"| bed with fix aeolian/wind (every 1) | {wind[1][0]:.3e} | {wind[1][1]:.3e} | {wind[1][1] / wind[0][1]:.2f} |", "",
              f"The grains of this bed mostly fall or rest on few contacts, so the ratio overstates the wind's share in a "
              f"transport run; in absolute terms the wind adds {1e9 * (1 / wind[1][1] - 1 / wind[0][1]):.0f} ns per grain "
              "and step (fastest runs): the profile lookup, Cheng's drag law (two powers) and the solid-fraction and "
              "stress bookkeeping of the feedback.", "", END]
    section = "\n".join(lines) + "\n"
    old = open(a.out).read() if os.path.exists(a.out) else "# Benchmarks\n"
    if BEGIN in old and END in old:
        new = old[:old.index(BEGIN)] + section + old[old.index(END) + len(END):].lstrip("\n")
    else:
        new = old.rstrip("\n") + "\n\n" + section
    tmpf = a.out + ".tmp"
    with open(tmpf, "w") as f:
        f.write(new)
    os.replace(tmpf, a.out)
    print(section)


if __name__ == "__main__":
    main()
