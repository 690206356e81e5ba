#!/usr/bin/env python3
"""hertz_refine.py — Hertz spheres with local refinement at the contact point
against uniform meshes (issue 18, done-when 3).

What it shows: two equal steel spheres (R = 5 mm, E = 210 GPa, nu = 0.3,
bench/speed_accuracy/hertz_spheres.yaml) meeting head-on at an approach speed
v, frictionless, e = 1; per mesh the contact duration (first to last step with
a resolved contact pair) against t_c = 2.87 (m*^2 / (R* E*^2 v))^(1/5) and the
peak force m dv_cm/dt of one sphere against F_max = 4/3 E* sqrt(R*) d_max^(3/2),
d_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5) (Johnson, Contact Mechanics,
1985, ch. 4 and 11), m* = m/2 with m the meshed sphere's mass,
R* = R/2, E* = E / (2 (1 - nu^2)). The force is the secant slope of v_cm over
a window of t_c / 50 (a fixed time, so meshes of different steps compare;
it lowers a half-sine peak by (pi / 50)^2 / 24 = 2e-4).
A refined mesh is `bodies[i].mesh.refine: [{center: [0, 0, 0], radius: r,
element_size: h}]` on both spheres (the contact point is the origin).

Run:    python3 bench/hertz_refine.py BUILD_DIR CASE [CASE ...] > out.csv
        CASE = v:H:h:r[:order] (m/s, m, m, m; h = H or r = 0 for a uniform
        mesh of H; order 1 or 2, default 1), e.g. 50:1e-3:1.5e-4:1.2e-3. Each run uses --threads 1 under nice.
Output: one CSV row per case on stdout (header first): v,H,h,r,order,elements,steps,
        t_contact,t_hertz,duration_error,f_peak,f_hertz,force_error,
        energy_error,wall_time,cpu_time,load: wall_time is the run's (summary.json),
        cpu_time the process's user + system time, meshing included; on a
        loaded machine (load above the core count) compare cpu_time.
"""
import csv
import json
import math
import os
import resource
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "speed_accuracy", "hertz_spheres.yaml")
E, NU, R = 210.0e9, 0.3, 5.0e-3


def hertz(m, v):
    ms, rs, es = m / 2, R / 2, E / (2 * (1 - NU * NU))
    t_h = 2.87 * (ms * ms / (rs * es * es * v)) ** 0.2
    d_max = (15 * ms * v * v / (16 * es * math.sqrt(rs))) ** 0.4
    return t_h, 4.0 / 3.0 * es * math.sqrt(rs) * d_max ** 1.5


def metrics(d, v):
    hist = list(csv.DictReader(open(os.path.join(d, "history.csv"))))
    touching = [float(r["time"]) for r in hist if int(r["contacts"]) > 0]
    rows = [r for r in csv.DictReader(open(os.path.join(d, "bodies.csv"))) if r["body"] == "left"]
    m = float(rows[0]["mass"])
    t_h, f_h = hertz(m, v)
    t = [float(r["time"]) for r in rows]
    u = [float(r["vx"]) for r in rows]
    half = t_h / 100
    f_peak, j = 0.0, 0
    for i in range(len(t)):  # secant over [t_i - half, t_i + half], two pointers
        if t[i] - half < t[0] or t[i] + half > t[-1]:
            continue
        while t[j] < t[i] - half:
            j += 1
        k = j
        while t[k] < t[i] + half:
            k += 1
        f_peak = max(f_peak, abs(m * (u[k] - u[j]) / (t[k] - t[j])))
    tc = touching[-1] - touching[0]
    return dict(t_contact=tc, t_hertz=t_h, duration_error=tc / t_h - 1, f_peak=f_peak, f_hertz=f_h,
                force_error=f_peak / f_h - 1)


def case_sets(v, H, h, r, order):
    """The --set list of one case: mesh, speeds, a gap of 0.4 us of approach, 1.3 t_c after it,
    and the refinement at the contact point."""
    sets = [f"bodies[{b}].mesh.element_size={H}" for b in (0, 1)]
    sets += [f"bodies[{b}].mesh.order={order}" for b in (0, 1)]
    sets += [f"bodies[0].initial_velocity=[{v / 2},0,0]", f"bodies[1].initial_velocity=[{-v / 2},0,0]"]
    gap = v * 4e-7  # between the poles: 0.4 us of approach
    sets += [f"bodies[0].mesh.center=[{-R - gap / 2},0,0]", f"bodies[1].mesh.center=[{R + gap / 2},0,0]"]
    t_h, _ = hertz(7850 * 4 / 3 * math.pi * R ** 3, v)
    sets += [f"time.end={gap / v + 1.3 * t_h}"]
    if h < H and r > 0:
        sets += [f"bodies[{b}].mesh.refine=[{{center: [0, 0, 0], radius: {r}, element_size: {h}}}]" for b in (0, 1)]
    return sets


def run_shatter(build, sets, d):
    """Runs the scene with `sets` into folder d at --threads 1 under nice; returns its CPU time, s
    (user + system, meshing included)."""
    cmd = ["nice", "-n", "15", os.path.join(build, "apps", "shatter"), "run", SCENE, "--out", d, "--threads", "1",
           "--quiet"]
    for s in sets:
        cmd += ["--set", s]
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True)
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime


def run(build, v, H, h, r, order):
    with tempfile.TemporaryDirectory() as d:
        cpu = run_shatter(build, case_sets(v, H, h, r, order), d)
        s = json.load(open(os.path.join(d, "summary.json")))
        row = dict(v=v, H=H, h=h, r=r, order=order, elements=s["elements"], steps=s["steps"])
        row.update(metrics(d, v))
        row.update(energy_error=s["energy_error"], wall_time=s["wall_time"], cpu_time=cpu, load=os.getloadavg()[0])
        return row


def rows_to_csv(cases, run_case, digits):
    """Each case "v:H:h:r[:more...]" run by run_case(v, H, h, r, more) as one CSV row on
    stdout (numbers to `digits` significant digits), the header first."""
    out = None
    for c in cases:
        f = c.split(":")
        v, H, h, r = (float(x) for x in f[:4])
        row = run_case(v, H, h, r, f[4:])
        if out is None:
            out = csv.DictWriter(sys.stdout, fieldnames=list(row))
            out.writeheader()
        out.writerow({k: (f"{x:.{digits}g}" if isinstance(x, float) else x) for k, x in row.items()})
        sys.stdout.flush()


def main():
    build = sys.argv[1]
    rows_to_csv(sys.argv[2:], lambda v, H, h, r, more: run(build, v, H, h, r, int(more[0]) if more else 1), 6)


if __name__ == "__main__":
    main()
