#!/usr/bin/env python3
"""contact_momenta.py - what a contact run keeps: energy, angular momentum, DCR cost.

What it shows: for each scene, one run (`shatter run --threads 1`, no field
output) per build given, the builds interleaved scene by scene so that their
times see the same load: the ledger total's error (final and largest over the
run, relative to the initial total), the kinetic + strain energy's final error
(what the ledger total books in contact_work is left out of it), the largest
change of the angular momentum |L - L(0)| over the run relative to |L(0)|
(history.csv; 0 where L(0) vanishes), DCR rounds per step, the DCR time and the
wall time (summary.json). docs/contact.md "Angular momentum" tabulates it.
Run:     python3 bench/contact_momenta.py BUILD_DIR[,BUILD_DIR...] SCENE... [--set key=value ...]
Output:  bench/results/contact_momenta.csv (appended) and the rows on stdout.
Expect:  seconds for the regression scenes, minutes for the full seed scenes.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile


def run(build, scene, sets, out):
    subprocess.run([os.path.join(build, "apps", "shatter"), "run", scene, "--out", out, "--threads", "1", "--quiet",
                    "--set", "output.every=0"] + sets, check=True)
    s = json.load(open(os.path.join(out, "summary.json")))
    rows = list(csv.DictReader(open(os.path.join(out, "history.csv"))))
    total0 = float(rows[0]["total"])
    L = [(float(r["Lx"]), float(r["Ly"]), float(r["Lz"])) for r in rows]
    dL = max(math.dist(l, L[0]) for l in L)
    L0 = math.hypot(*L[0])
    last = rows[-1]
    return {
        "steps": s["steps"],
        "energy_error": s["energy_error"],
        "energy_error_max": max(abs(float(r["total"]) - total0) for r in rows) / total0,
        "mechanical_error": (float(last["kinetic"]) + float(last["strain"])) / total0 - 1,
        "contact_work": s.get("contact_work", 0.0) / total0,
        "dL_over_L0": dL / L0 if L0 > 0 else 0.0,
        "sweeps_per_step": s.get("contact_sweeps_per_step", 0.0),
        "dcr_time": s.get("contact_dcr_time", 0.0),
        "wall_time": s["wall_time"],
        "capped": s.get("contact_capped_steps", 0),
    }


def main():
    args = sys.argv[1:]
    sets = []
    while "--set" in args:
        k = args.index("--set")
        sets += ["--set", args[k + 1]]
        del args[k:k + 2]
    if len(args) < 2:
        sys.exit(__doc__)
    builds, scenes = args[0].split(","), args[1:]
    here = os.path.dirname(os.path.abspath(__file__))
    os.makedirs(os.path.join(here, "results"), exist_ok=True)
    path = os.path.join(here, "results", "contact_momenta.csv")
    keys = ["steps", "energy_error", "energy_error_max", "mechanical_error", "contact_work", "dL_over_L0",
            "sweeps_per_step", "dcr_time", "wall_time", "capped"]
    new = not os.path.exists(path)
    with open(path, "a") as f, tempfile.TemporaryDirectory() as work:
        w = csv.writer(f)
        if new:
            w.writerow(["build", "scene", "sets"] + keys)
        for scene in scenes:
            for b, build in enumerate(builds):
                r = run(build, scene, sets, os.path.join(work, f"{b}_{os.path.basename(scene)}"))
                name = os.path.relpath(os.path.abspath(scene), os.path.dirname(here))
                row = [build, name, " ".join(sets[1::2])] + [r[k] for k in keys]
                w.writerow(row)
                f.flush()
                print(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in
                               zip(["build", "scene", "sets"] + keys, row)), flush=True)


if __name__ == "__main__":
    main()
