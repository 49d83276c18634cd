#!/usr/bin/env python3
"""The real-deck corpus (../shared/decks-run, the decks the real engines run,
with their files): each deck (its `.capped` copy where one exists) is run by
its engine and by `demx run`, each in its own copy of the deck's folder, and
compared by what the decks print: the thermo lines (their steps, and the
atom counts where a deck prints them). Writes the table between the corpus
markers of COMPAT.md and prints a summary.

Usage: python3 scripts/corpus.py [--demx target/release/demx] [--only SUBSTR]
"""
import argparse, csv, os, re, shutil, subprocess, sys, tempfile, time

from mdblock import replace_block

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.environ.get("DEMX_SHARED", os.path.join(os.path.dirname(ROOT), "shared")) + "/decks-run"
BEGIN, END = "<!-- corpus:begin (scripts/corpus.py) -->", "<!-- corpus:end -->"


def thermo(text):
    """Thermo blocks: [(header, [row, ...]), ...], rows as word lists."""
    blocks, cur = [], None
    for line in text.splitlines():
        w = line.split()
        if w and w[0] == "Step" and len(w) > 1:
            cur = (w, [])
            blocks.append(cur)
        elif line.startswith("Loop time"):
            cur = None
        elif cur is not None and w and re.fullmatch(r"-?\d+", w[0]) and len(w) == len(cur[0]):
            cur[1].append(w)
    return blocks


def go(cmd, cwd, limit):
    t = time.time()
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=limit)
        return p.returncode, p.stdout + p.stderr, time.time() - t
    except subprocess.TimeoutExpired as e:
        return "timeout", (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or ""), time.time() - t


def first_error(text):
    for line in text.splitlines():
        if re.search(r"(error|unsupported|ERROR)", line):
            return line.strip()[:220]
    return text.strip().splitlines()[-1][:220] if text.strip() else ""


def agree(theirs, ours):
    """How the thermo output compares: same blocks and steps; atom counts."""
    t, o = thermo(theirs), thermo(ours)
    if len(t) != len(o):
        return f"thermo blocks {len(o)} vs {len(t)}", False
    steps_ok, atoms_ok, atoms_seen, headers_ok = True, True, False, True
    for (th, tr), (oh, orows) in zip(t, o):
        headers_ok &= th == oh
        if [r[0] for r in tr] != [r[0] for r in orows]:
            steps_ok = False
        if "Atoms" in th and "Atoms" in oh:
            ti, oi = th.index("Atoms"), oh.index("Atoms")
            atoms_seen = True
            atoms_ok &= [r[ti] for r in tr] == [r[oi] for r in orows]
    parts = ["headers " + ("equal" if headers_ok else "differ"), "steps " + ("equal" if steps_ok else "differ")]
    if atoms_seen:
        parts.append("atoms " + ("equal" if atoms_ok else "differ"))
    return ", ".join(parts), steps_ok and atoms_ok and headers_ok


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--demx", default=os.path.join(ROOT, "target", "release", "demx"))
    ap.add_argument("--only", default="")
    ap.add_argument("--out", default=os.path.join(ROOT, "COMPAT.md"))
    a = ap.parse_args()
    rows = []
    with open(os.path.join(CORPUS, "MANIFEST.csv"), newline="") as f:
        manifest = [r for r in csv.DictReader(f) if a.only in r["path"]]
    for r in manifest:
        path = os.path.join(CORPUS, r["path"])
        folder, deck = os.path.dirname(path), os.path.basename(path)
        if os.path.exists(path + ".capped"):
            deck += ".capped"
        engine = "lmp" if r["engine"].startswith("lmp") else "liggghts"
        np_ = re.search(r"-np (\d+)", r["engine"])
        with tempfile.TemporaryDirectory() as tmp:
            # each copy keeps the folder's own name: decks name it in
            # relative paths (`log ../DEM/log.liggghts`)
            base = os.path.basename(folder)
            mine, theirs = os.path.join(tmp, "demx", base), os.path.join(tmp, "engine", base)
            shutil.copytree(folder, mine)
            shutil.copytree(folder, theirs)
            ecmd = ([] if not np_ else ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", np_.group(1)]) + [engine, "-in", deck, "-log", "none"]
            ec, eout, et = go(ecmd, theirs, 600)
            dc, dout, dt = go([a.demx, "run", deck, "--log", "none"], mine, 900)
        if dc == 0 and ec == 0:
            how, ok = agree(eout, dout)
            state = "agrees" if ok else "runs, differs"
        else:
            how, ok = (first_error(dout) if dc != 0 else ""), False
            state = {3: "unsupported (exit 3)", 2: "refused (exit 2)", "timeout": "timeout"}.get(dc, f"exit {dc}") if dc != 0 else f"engine exit {ec}"
        ratio = f"{et / dt:.2f}" if dc == 0 and ec == 0 and dt > 0 else "-"
        rows.append((r["path"], engine + (f" -np {np_.group(1)}" if np_ else ""), state, how, f"{et:.1f}", f"{dt:.1f}", ratio))
        print(f"{r['path']}: {state}; {how}; engine {et:.1f} s, demx {dt:.1f} s", flush=True)
    n = len(rows)
    counts = {}
    for row in rows:
        counts[row[2]] = counts.get(row[2], 0) + 1
    lines = [BEGIN, "", "## The real-deck corpus", "",
             f"Generated by `python3 scripts/corpus.py` on {time.strftime('%Y-%m-%d')}: each deck of `../shared/decks-run` (its `.capped` copy where",
             "one exists) run by its engine and by `demx run`, each in a copy of its folder; compared by their thermo output",
             "(headers, steps, and the atom counts where printed). The engine's and demx's wall times include start-up; the",
             "ratio is the engine's time over demx's (above 1: demx faster).", "",
             f"Decks: {n}. " + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items())) + ".", "",
             "| deck | engine | demx | how | engine s | demx s | ratio |", "| --- | --- | --- | --- | --- | --- | --- |"]
    esc = lambda x: str(x).replace("|", "\\|")
    lines += [f"| {' | '.join(esc(c) for c in row)} |" for row in rows]
    lines += ["", END]
    if not a.only:
        replace_block(a.out, BEGIN, END, "\n".join(lines), "# Deck compatibility")
        print("wrote", a.out)
    print(f"{n} decks: " + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items())))


if __name__ == "__main__":
    main()
