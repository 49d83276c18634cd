"""Shared by the heap validation scripts: run templates/heap/in.heap in a
folder (or reuse a folder whose run finished), measure it with
`demx repose --json`, and keep finished results in a JSON cache written by
temporary file and rename.

A run folder holds in.heap's outputs (dump.heap, log.demx) and wall.txt,
the run's wall time in seconds; a folder whose log ends the deck (the
"heap: relaxation ended" line and a dump) is finished and is not run again.
"""

import json
import os
import re
import subprocess
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DECK = os.path.join(ROOT, "templates", "heap", "in.heap")


def repose(demx, dump, gamma=1e-30):
    """`demx repose --json` of a dump's last frame, or None."""
    r = subprocess.run([demx, "repose", dump, "--json", "--gamma", repr(max(gamma, 1e-30))],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        return None
    return json.loads(r.stdout)["repose"]


def work_done(log):
    """Steps and particle-steps of a run, from its `Loop time ... for S steps
    with A atoms` lines (A at the end of each run command)."""
    steps = psteps = 0
    for line in open(log):
        m = re.match(r"Loop time of \S+ on \d+ procs for (\d+) steps with (\d+) atoms", line)
        if m:
            steps += int(m.group(1))
            psteps += int(m.group(1)) * int(m.group(2))
    return steps, psteps


def finished(folder):
    log = os.path.join(folder, "log.demx")
    if not (os.path.exists(log) and os.path.exists(os.path.join(folder, "dump.heap"))):
        return False
    with open(log) as f:
        return "heap: relaxation ended" in f.read()


def run_heap(demx, folder, variables, gamma=1e-30, threads=1):
    """Run the heap deck with `-var NAME VALUE` for each item of `variables`
    in `folder` unless it already finished there; return the measurement
    (repose fields, steps, psteps, wall, finished) or {"error": ...}."""
    os.makedirs(folder, exist_ok=True)
    if not finished(folder):
        cmd = [demx, "run", DECK, "--threads", str(threads), "--quiet", "--log", "log.demx"]
        for k, v in variables.items():
            cmd += ["-var", k, str(v)]
        t0 = time.time()
        p = subprocess.run(cmd, cwd=folder, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        wall = time.time() - t0
        if p.returncode != 0:
            return {"error": (p.stderr.strip().splitlines() or ["exit %d" % p.returncode])[-1], "wall": wall}
        with open(os.path.join(folder, "wall.txt"), "w") as f:
            f.write(f"{wall:.1f}\n")
    rp = repose(demx, os.path.join(folder, "dump.heap"), gamma)
    if rp is None:
        return {"error": "demx repose failed on " + os.path.join(folder, "dump.heap")}
    wall_file = os.path.join(folder, "wall.txt")
    steps, psteps = work_done(os.path.join(folder, "log.demx"))
    out = {k: rp[k] for k in ("theta", "theta_xz", "theta_yz", "sd", "height", "particles", "diameter") if k in rp}
    out.update(steps=steps, psteps=psteps,
               wall=float(open(wall_file).read()) if os.path.exists(wall_file) else None,
               finished=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(os.path.getmtime(os.path.join(folder, "dump.heap")))))
    return out


def write_section(path, lines):
    """Write a VALIDATION section (temporary file and rename) and print it."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, path)
    print("\n".join(lines))


class Cache:
    """Finished results by key, in a JSON file rewritten atomically on each put."""

    def __init__(self, path):
        self.path = path
        self.data = json.load(open(path)) if os.path.exists(path) else {}

    def get(self, key):
        return self.data.get(key)

    def put(self, key, value):
        """Add one result; other processes may be adding theirs to the same
        file, so re-read it under a lock and merge before writing."""
        import fcntl
        os.makedirs(os.path.dirname(self.path), exist_ok=True)
        with open(self.path + ".lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if os.path.exists(self.path):
                self.data.update(json.load(open(self.path)))
            self.data[key] = value
            tmp = self.path + ".tmp"
            with open(tmp, "w") as f:
                json.dump(self.data, f, indent=1, sort_keys=True)
                f.write("\n")
            os.replace(tmp, self.path)
