#!/usr/bin/env python3
"""Regenerates COMPAT.md: `demx check` (and the script-language-only check)
on every deck of ../shared/decks (MANIFEST.csv) and Debian's LIGGGHTS and
LAMMPS granular examples, each run from the deck's own folder.

Usage: python3 scripts/compat.py [--demx target/release/demx] [--out COMPAT.md]
"""
import argparse, csv, glob, os, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "decks")
DEBIAN = (sorted(glob.glob("/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public/*/in.*"))
          + sorted(glob.glob("/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public/*/*/in.*"))
          + sorted(glob.glob("/usr/share/lammps/examples/pour/in.pour*"))
          + sorted(glob.glob("/usr/share/lammps/examples/granular/in.*"))
          + sorted(glob.glob("/usr/share/lammps/examples/granregion/in.*"))
          + [p for p in ["/usr/share/lammps/examples/multi/in.granular", "/usr/share/lammps/examples/multi/in.powerlaw",
                         "/usr/share/lammps/examples/rigid/in.rigid.gravity", "/usr/share/lammps/examples/body/in.pour3d"]
             if os.path.exists(p)])


def decks():
    out = []
    man = os.path.join(SHARED, "MANIFEST.csv")
    if os.path.exists(man):
        with open(man, newline="") as f:
            for row in csv.DictReader(f):
                out.append((os.path.join(SHARED, row["path"]), row["dialect"], "shared/decks/" + row["path"]))
    for p in DEBIAN:
        dialect = "liggghts3" if "/liggghts/" in p else "lammps"
        out.append((p, dialect, p.replace("/usr/share/doc/liggghts/examples/", "debian liggghts-doc: ").replace("/usr/share/lammps/examples/", "debian lammps-examples: ")))
    return out


def run(demx, deck, extra):
    d, f = os.path.dirname(deck), os.path.basename(deck)
    t = time.time()
    try:
        p = subprocess.run([demx, "check", f] + extra, cwd=d, capture_output=True, text=True, timeout=120)
        code, err = p.returncode, p.stderr
    except subprocess.TimeoutExpired:
        code, err = "timeout", ""
    first = next((l for l in err.splitlines() if l.strip()), "")
    return code, first, time.time() - t


def run_deck(demx, deck, steps):
    """`demx run --max-steps` in a temporary copy of the deck's folder."""
    import shutil, tempfile
    src = os.path.dirname(deck)
    with tempfile.TemporaryDirectory() as tmp:
        work = os.path.join(tmp, "deck")
        try:
            shutil.copytree(src, work, symlinks=True)
        except Exception as e:  # unreadable files: copy what we can
            os.makedirs(work, exist_ok=True)
            for f in os.listdir(src):
                try:
                    shutil.copy(os.path.join(src, f), work)
                except Exception:
                    pass
        for sub in ("post", "post/restart", "../DEM/post", "../DEM/post/restart", "output", "vtk"):
            try:
                os.makedirs(os.path.join(work, sub), exist_ok=True)
            except Exception:
                pass
        def go(cap):
            p = subprocess.run([demx, "run", os.path.basename(deck), "--log", "none", "--quiet"] + cap,
                               cwd=work, capture_output=True, text=True, timeout=120)
            return p.returncode, next((l for l in p.stderr.splitlines() if l.strip()), "")
        try:
            code, first = go(["--max-steps", str(steps)])
        except subprocess.TimeoutExpired:
            return "limit", ""
        if code == 1 and "stability guard" in first:
            # a cut-short run can leave a deck's later stages in a state the
            # full run never reaches (a mesh switched on inside particles that
            # have not settled yet): run it whole before calling it a failure
            try:
                full, _ = go([])
            except subprocess.TimeoutExpired:
                full = None
            if full == 0:
                return "capped", first
    return code, first


def convert(demx, deck, dialect):
    """`demx convert` of a deck: legacy LIGGGHTS to 3.x, 3.x to LAMMPS, LAMMPS to LIGGGHTS."""
    target = {"liggghts2": "liggghts", "liggghts3": "lammps", "lammps": "liggghts"}[dialect]
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        try:
            p = subprocess.run([demx, "convert", deck, "--to", target, "-o", os.path.join(tmp, "out")],
                               capture_output=True, text=True, timeout=60)
        except subprocess.TimeoutExpired:
            return f"-> {target}: timeout"
    word = {0: "exact", 4: "approximated/dropped lines", 2: "error"}.get(p.returncode, f"exit {p.returncode}")
    return f"-> {target}: {p.returncode} ({word})"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--demx", default=os.path.join(ROOT, "target", "release", "demx"))
    ap.add_argument("--out", default=os.path.join(ROOT, "COMPAT.md"))
    ap.add_argument("--steps", type=int, default=200, help="steps per run command for the run column")
    a = ap.parse_args()
    rows, script_ok, codes, runs = [], 0, {}, {}
    for deck, dialect, name in decks():
        sc, smsg, _ = run(a.demx, deck, ["--script-only"])
        c, msg, _ = run(a.demx, deck, [])
        if c == 0:
            rc, rmsg = run_deck(a.demx, deck, a.steps)
            runcol = "runs" if rc == 0 else ("runs (stopped at the 120 s limit: long run loop)" if rc == "limit" else
                      f"runs in full (exit 0); only the capped run stops: {rmsg}" if rc == "capped" else f"fails ({rc}): {rmsg}")
        elif c == 3:
            runcol = "unsupported feature"
        else:
            runcol = "deck error / missing file"
        runs[runcol.split(" ")[0]] = runs.get(runcol.split(" ")[0], 0) + 1
        script_ok += sc == 0
        codes[c] = codes.get(c, 0) + 1
        conv = convert(a.demx, deck, dialect)
        rows.append((name, dialect, "ok" if sc == 0 else f"{sc}: {smsg}", c, msg, runcol, conv))
    n = len(rows)
    # the real-deck corpus table (scripts/corpus.py) is kept as it is
    old = open(a.out).read() if os.path.exists(a.out) else ""
    corpus = old[old.find("<!-- corpus:begin"):] if "<!-- corpus:begin" in old else ""
    with open(a.out, "w") as f:
        f.write("# Deck compatibility\n\nGenerated by `python3 scripts/compat.py` (do not edit by hand): `demx check` on every deck of\n")
        f.write("`../shared/decks` and Debian's LIGGGHTS/LAMMPS granular examples, run from the deck's own folder.\n\n")
        f.write("Exit codes: 0 = the deck is understood, 2 = the deck is wrong (or a file it reads is missing), 3 = valid but uses\n")
        f.write("something demx does not support yet. `script` = the script-language check (`demx check --script-only`):\n")
        f.write("variables, loops, includes and conditionals resolved through the whole deck. `run` = for decks that check\n")
        f.write(f"with exit 0, `demx run --max-steps {a.steps}` (every run command capped at {a.steps} steps) in a copy of the deck's folder;\n")
        f.write("a capped run that the stability guard stops is run again in full (120 s limit), since cutting a deck short can\n")
        f.write("start its later stages from a state the full run never reaches.\n\n")
        f.write(f"Decks: {n}. Script language passes: {script_ok}/{n} ({100.0 * script_ok / max(n, 1):.0f}%). ")
        f.write("Exit codes: " + ", ".join(f"{k}: {v}" for k, v in sorted(codes.items(), key=lambda kv: str(kv[0]))) + ". ")
        f.write("Run column: " + ", ".join(f"{k}: {v}" for k, v in sorted(runs.items())) + ".\n\n")
        f.write("`convert` = `demx convert` (liggghts2 decks to LIGGGHTS 3.x, liggghts3 decks to LAMMPS, LAMMPS decks to LIGGGHTS):\n")
        f.write("exit 0 = exact, 4 = converted with approximations or dropped lines, 2 = error.\n\n")
        f.write("| deck | dialect | script | check exit | first message | run | convert |\n| --- | --- | --- | --- | --- | --- | --- |\n")
        for name, dialect, s, c, msg, runcol, conv in rows:
            esc = lambda x: str(x).replace("|", "\\|")
            f.write(f"| {esc(name)} | {dialect} | {esc(s)} | {c} | {esc(msg)} | {esc(runcol)} | {esc(conv)} |\n")
        if corpus:
            f.write("\n" + corpus)
    print(f"wrote {a.out}: {n} decks, script ok {script_ok}, exit codes {codes}")
    panics = [r for r in rows if r[3] not in (0, 2, 3)]
    if panics:
        print("decks with unexpected exit codes:", panics, file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
