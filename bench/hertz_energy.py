#!/usr/bin/env python3
"""hertz_energy.py — where the Hertz spheres' total energy error comes from
(issue 18, done-when 2; docs/contact.md "The Hertz spheres' energy at 0.5 m/s").

What it shows: the run of bench/hertz_refine.py (two steel spheres, R = 5 mm,
head-on at v, frictionless, e = 1, refined at the contact point), and from its
history.csv the change of each ledger term relative to total(0): kinetic,
strain, their sum (mechanical), contact_work, contact_dissipated, total;
at the first contact, at the largest compression, at separation (the last step
with a resolved pair) and at the end; the spheres' rigid-body kinetic energy
(1/2 m v_cm^2) at the end over the start (end_rigid); and the smallest and
largest total during contact and after separation (after separation no
contact acts: the total only oscillates about central differences' modified
energy).

Run:    python3 bench/hertz_energy.py BUILD_DIR CASE [CASE ...]
        CASE = v:H:h:r:order[:safety] (m/s, m, m, m as in hertz_refine.py;
        safety the time.safety, default the scene's). Each run --threads 1 under nice;
        with HERTZ_KEEP=DIR each run's history.csv and bodies.csv are copied into DIR;
        HERTZ_SET=KEY=VALUE adds one --set to every run (e.g. contact.placement=middle).
Output: per case one CSV row (header first) on stdout.
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hertz_refine as hr  # noqa: E402


def terms(r, t0):
    k, s = float(r["kinetic"]), float(r["strain"])
    return dict(kin=k / t0, strain=s / t0, mech=(k + s) / t0 - 1, work=float(r["contact_work"]) / t0,
                diss=float(r["contact_dissipated"]) / t0, total=float(r["total"]) / t0 - 1)


def run(build, v, H, h, r, order, safety):
    sets = hr.case_sets(v, H, h, r, order)
    if safety:
        sets += [f"time.safety={safety}"]
    extra = os.environ.get("HERTZ_SET")  # one more --set for every case, e.g. contact.placement=middle
    if extra:
        sets += [extra]
    with tempfile.TemporaryDirectory() as d:
        cpu = hr.run_shatter(build, sets, d)
        summary = json.load(open(os.path.join(d, "summary.json")))
        hist = list(csv.DictReader(open(os.path.join(d, "history.csv"))))
        bodies = list(csv.DictReader(open(os.path.join(d, "bodies.csv"))))
        keep = os.environ.get("HERTZ_KEEP")  # a folder to keep each run's history.csv and bodies.csv in
        if keep:
            name = f"v{v}_H{H}_h{h}_r{r}_o{order}_s{safety or ''}{'_' + extra if extra else ''}.csv"
            for f in ("history", "bodies"):
                subprocess.run(["cp", os.path.join(d, f + ".csv"), os.path.join(keep, f + "_" + name)], check=True)
    t0 = float(hist[0]["total"])
    touching = [i for i, q in enumerate(hist) if int(q["contacts"]) > 0]
    if not touching:  # e.g. TET4 facets a sagitta h^2 / 8R inside the sphere, deeper than the approach
        sys.exit(f"hertz_energy.py: case {v}:{H}:{h}:{r}:{order}: the spheres never touched")
    first, last = touching[0], touching[-1]
    peak = max(range(len(hist)), key=lambda i: float(hist[i]["strain"]))
    after = [float(q["total"]) / t0 - 1 for q in hist[last + 1:]]
    during = [float(q["total"]) / t0 - 1 for q in hist[first:last + 1]]
    row = dict(v=v, H=H, h=h, r=r, order=order, safety=safety or "", set=extra or "", elements=summary["elements"],
               steps=summary["steps"], dt_min=min(float(q["dt"]) for q in hist[1:]),
               contact_steps=len(touching), energy_error=summary["energy_error"])
    for name, i in (("first", first), ("peak", peak), ("sep", last), ("end", len(hist) - 1)):
        for k, x in terms(hist[i], t0).items():
            row[f"{name}_{k}"] = x
    # The spheres' rigid-body kinetic energy, 1/2 m |v_cm|^2 summed, at the end over at the start.
    def rigid_ke(rows):
        return sum(0.5 * float(q["mass"]) * (float(q["vx"]) ** 2 + float(q["vy"]) ** 2 + float(q["vz"]) ** 2)
                   for q in rows)
    n_bodies = len({q["body"] for q in bodies})
    row.update(end_rigid=rigid_ke(bodies[-n_bodies:]) / rigid_ke(bodies[:n_bodies]))
    row.update(during_min=min(during), during_max=max(during),
               after_min=min(after) if after else "", after_max=max(after) if after else "",
               cpu_time=cpu, load=os.getloadavg()[0])
    return row


def main():
    build = sys.argv[1]

    def case(v, H, h, r, more):
        order = int(more[0]) if more else 1
        safety = float(more[1]) if len(more) > 1 and more[1] else None
        return run(build, v, H, h, r, order, safety)

    hr.rows_to_csv(sys.argv[2:], case, 5)


if __name__ == "__main__":
    main()
