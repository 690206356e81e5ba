#!/usr/bin/python3
"""speed_accuracy.py -- what each knob buys: error against an analytic or
published value, and wall time, as one knob at a time moves away from the
defaults (issue 7; results in docs/speed-accuracy.md).

Cases (scene files beside this script, the ring from scenes/):
  bars   two equal bars head-on (two_bars.yaml): contact duration against
         2 L / c and the velocity exchange (a stops, b takes v);
  hertz  two steel spheres (hertz_spheres.yaml): contact duration against
         Hertz t_c = 2.87 (m*^2 / (R* E*^2 v))^(1/5) and the peak force
         m dv/dt of one sphere against 4/3 E* sqrt(R*) d_max^(3/2);
  ring   the expanding ring at 1e4 /s (scenes/expanding_ring.yaml, run to
         2 us): mean fragment size L / N_big against Zhou-Molinari-Ramesh
         (and Grady), as in bench/expanding_ring.sh.
Knobs: element size, element order (TET10 at the TET4 node spacing and at
the same element size), time.safety, contact.max_sweeps,
contact.search_margin, time.fracture_check_every (docs/scenes.md).

Every run is `shatter run ... --threads 1`, one at a time; the load average
before and after each run goes into the CSV beside its wall time and its CPU
time (user + system of the process; the machine is shared: compare CPU times,
wall times are noisy). The plots and the time ratios use the CPU time.

Run:     /usr/bin/python3 bench/speed_accuracy/speed_accuracy.py BUILD_DIR
           [--cases bars,hertz,ring] [--runs DIR] [--plot-only]
Output:  bench/results/speed_accuracy_<case>.csv, docs/plots/speed_accuracy_<case>.png,
         bench/results/speed_accuracy_machine.txt, and a markdown table per
         case on stdout.
Expect:  about 20-30 minutes with both cores loaded (most of it the ring and
         the fine Hertz spheres).
"""
import argparse
import csv
import json
import math
import os
import platform
import resource
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
RESULTS = os.path.join(ROOT, "bench", "results")
PLOTS = os.path.join(ROOT, "docs", "plots")


def knob_runs(sizes, order2_sizes, safeties, sweeps, margins, checks, base_size):
    """(knob, value, --set list) for one case: the defaults once, then one knob at a time."""
    def sz(h, order=1):
        return [f"bodies[{b}].mesh.element_size={h}" for b in (0, 1)] + \
               [f"bodies[{b}].mesh.order={order}" for b in (0, 1)]
    runs = [("default", "", sz(base_size))]
    runs += [("element_size", h, sz(h)) for h in sizes if h != base_size]
    runs += [("order2", h, sz(h, 2)) for h in order2_sizes]
    runs += [("safety", s, sz(base_size) + [f"time.safety={s}"]) for s in safeties]
    runs += [("max_sweeps", n, sz(base_size) + [f"contact.max_sweeps={n}"]) for n in sweeps]
    runs += [("search_margin", m, sz(base_size) + [f"contact.search_margin={m}"]) for m in margins]
    runs += [("fracture_check_every", c, sz(base_size) + [f"time.fracture_check_every={c}"]) for c in checks]
    return runs


def ring_runs():
    """The ring has one body: its knobs set bodies[0] only."""
    out = []
    for knob, value, sets in knob_runs([1.4e-4, 1.0e-4, 7.0e-5], [2.0e-4], [0.8, 0.3], [], [], [2, 5, 20], 1.0e-4):
        out.append((knob, value, [s for s in sets if not s.startswith("bodies[1]")]))
    return out


CASES = {
    "bars": dict(scene=os.path.join(HERE, "two_bars.yaml"),
                 runs=knob_runs([0.005, 0.0025, 0.00125], [0.005, 0.0025], [0.9, 0.25], [1, 3, 10],
                                [0.0, 0.3, 1.0], [], 0.0025)),
    "hertz": dict(scene=os.path.join(HERE, "hertz_spheres.yaml"),
                  runs=knob_runs([1.4e-3, 1.0e-3, 7.0e-4], [2.0e-3, 1.4e-3], [0.9, 0.25], [1, 3, 10],
                                 [0.0, 0.3, 1.0], [], 1.0e-3)),
    "ring": dict(scene=os.path.join(ROOT, "scenes", "expanding_ring.yaml"), runs=ring_runs(),
                 extra=["time.end=2.0e-6", "output.every=0", "output.history_every=20"]),
}


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def contact_window(hist):
    """First and last time with resolved contact pairs, s."""
    t_on = [float(r["time"]) for r in hist if int(r["contacts"]) > 0]
    return (t_on[0], t_on[-1]) if t_on else (0.0, 0.0)


def bars_metrics(d, h):
    """Contact duration against 2 L / c; velocity exchange (a stops, b takes v)."""
    E, rho, L, v = 210.0e9, 7850.0, 0.05, 1.0
    t0, t1 = contact_window(read_csv(f"{d}/history.csv"))
    last = {r["body"]: r for r in read_csv(f"{d}/bodies.csv")[-2:]}
    va, vb = float(last["a"]["vx"]), float(last["b"]["vx"])
    dur = 2 * L / math.sqrt(E / rho)
    return dict(duration_error=(t1 - t0) / dur - 1, exchange_error=max(abs(va), abs(vb - v)) / v)


def hertz_metrics(d, h, v=50.0):
    """Contact duration and peak force of two steel spheres (R = 5 mm) meeting at the
    approach speed v (m/s) against Hertz; also used by bench/hertz.sh."""
    E, nu, R = 210.0e9, 0.3, 5.0e-3
    t0, t1 = contact_window(read_csv(f"{d}/history.csv"))
    rows = [r for r in read_csv(f"{d}/bodies.csv") if r["body"] == "left"]
    m = float(rows[0]["mass"])  # the meshed sphere's mass
    ms, Rs, Es = m / 2, R / 2, E / (2 * (1 - nu * nu))
    t_h = 2.87 * (ms * ms / (Rs * Es * Es * v)) ** 0.2
    d_max = (15 * ms * v * v / (16 * Es * math.sqrt(Rs))) ** 0.4
    f_h = 4.0 / 3.0 * Es * math.sqrt(Rs) * d_max ** 1.5
    t = [float(r["time"]) for r in rows]
    u = [float(r["vx"]) for r in rows]
    k = 5
    f_peak = max(abs(m * (u[i + k] - u[i - k]) / (t[i + k] - t[i - k])) for i in range(k, len(t) - k))
    return dict(duration_error=(t1 - t0) / t_h - 1, force_error=f_peak / f_h - 1, t_contact=t1 - t0, t_hertz=t_h,
                f_peak=f_peak, f_hertz=f_h)


def ring_metrics(d, h):
    """Mean fragment size L / N_big (fragments of at least one element length) against ZMR and Grady."""
    E, rho, sc, Gc, R, a, rate = 275e9, 2750.0, 300e6, 100.0, 5.0e-3, 2.0e-4, 1.0e4
    s0 = E * Gc / sc ** 2
    eps0 = math.sqrt(E / rho) * sc ** 3 / (E ** 2 * Gc)
    zmr = s0 * 4.5 / (1 + 4.5 * (rate / eps0) ** (2 / 3))
    grady = (24 * Gc / (rho * rate ** 2)) ** (1 / 3)
    masses = [float(f["mass"]) for f in read_csv(f"{d}/fragments.csv")]
    big = sum(1 for mi in masses if mi >= rho * a * a * h)
    size = 2 * math.pi * R / max(big, 1)
    return dict(zmr_error=size / zmr - 1, grady_ratio=size / grady, fragments_big=big,
                fragments=len(masses))


METRICS = {"bars": (bars_metrics, ["duration_error", "exchange_error"]),
           "hertz": (hertz_metrics, ["duration_error", "force_error"]),
           "ring": (ring_metrics, ["zmr_error"])}


def run_case(build, name, runs_dir):
    case = CASES[name]
    rows = []
    for knob, value, sets in case["runs"]:
        tag = f"{knob}_{value}" if value != "" else knob
        d = os.path.join(runs_dir, name, tag)
        sets = sets + case.get("extra", [])
        h = next(float(s.split("=")[1]) for s in sets if "element_size" in s)
        load0 = os.getloadavg()[0]
        cmd = [os.path.join(build, "apps", "shatter"), "run", case["scene"], "--out", d, "--threads", "1", "--quiet"]
        for s in sets:
            cmd += ["--set", s]
        t0 = time.time()
        cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        proc = subprocess.run(cmd, capture_output=True, text=True)
        cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        load1 = os.getloadavg()[0]
        row = dict(case=name, knob=knob, value=value, element_size=h, status=proc.returncode,
                   load_before=f"{load0:.2f}", load_after=f"{load1:.2f}")
        if proc.returncode == 0:
            s = json.load(open(f"{d}/summary.json"))
            cpu = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
            row.update(elements=s["elements"], steps=s["steps"], wall_time=f"{s['wall_time']:.3f}",
                       cpu_time=f"{cpu:.3f}",
                       energy_error=f"{s['energy_error']:+.3e}",
                       capped_steps=s.get("contact_capped_steps", 0),
                       searches=s.get("contact_searches", ""))
            row.update({k: (f"{v:+.4g}" if isinstance(v, float) else v) for k, v in METRICS[name][0](d, h).items()})
        else:
            row.update(wall_time=f"{time.time() - t0:.3f}", error=proc.stderr.strip().splitlines()[-1:])
        print(json.dumps(row), file=sys.stderr)
        rows.append(row)
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(os.path.join(RESULTS, f"speed_accuracy_{name}.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


MARKERS = {"default": ("k", "*"), "element_size": ("C0", "o"), "order2": ("C1", "s"), "safety": ("C2", "^"),
           "max_sweeps": ("C3", "v"), "search_margin": ("C4", "D"), "fracture_check_every": ("C5", "P")}


def pareto(points):
    """The lower-left front of (time, error) points."""
    front, best = [], math.inf
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def seconds(r):
    """The run's CPU time (user + system, meshing included) where recorded, else its wall time:
    on the shared machine only the CPU time compares."""
    return float(r.get("cpu_time") or r["wall_time"])


def plot_case(name):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [r for r in read_csv(os.path.join(RESULTS, f"speed_accuracy_{name}.csv")) if r["status"] == "0"]
    metrics = METRICS[name][1]
    fig, axes = plt.subplots(1, len(metrics), figsize=(6.5 * len(metrics), 4.8), squeeze=False)
    for ax, m in zip(axes[0], metrics):
        pts = []
        for knob, (col, mk) in MARKERS.items():
            sel = [r for r in rows if r["knob"] == knob]
            if not sel:
                continue
            x = [seconds(r) for r in sel]
            y = [max(abs(float(r[m])), 1e-4) for r in sel]
            pts += list(zip(x, y))
            ax.loglog(x, y, mk, color=col, ms=9 if knob == "default" else 7, label=knob.replace("_", " "))
            for r, xi, yi in zip(sel, x, y):
                if knob != "default":
                    ax.annotate(str(r["value"]), (xi, yi), fontsize=7, xytext=(3, 3), textcoords="offset points")
        front = pareto(pts)
        ax.loglog([p[0] for p in front], [p[1] for p in front], "k:", lw=1, label="Pareto front")
        ax.set_xlabel(("CPU" if rows[0].get("cpu_time") else "wall") + " time, s (1 thread)")
        ax.set_ylabel(f"|{m.replace('_', ' ')}|")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    load = [float(r["load_before"]) for r in rows]
    fig.suptitle(f"speed-accuracy: {name} (load average {min(load):.1f}-{max(load):.1f} on 2 cores)")
    fig.tight_layout()
    os.makedirs(PLOTS, exist_ok=True)
    fig.savefig(os.path.join(PLOTS, f"speed_accuracy_{name}.png"), dpi=90)
    # The markdown table of docs/speed-accuracy.md.
    print(f"\n### {name}\n")
    print("| knob | value | elements | steps | wall s | CPU s | " + " | ".join(metrics) + " | energy error | load |")
    print("|---|---|---|---|---|---|" + "---|" * len(metrics) + "---|---|")
    for r in rows:
        print(f"| {r['knob']} | {r['value']} | {r['elements']} | {r['steps']} | {float(r['wall_time']):.2f} | "
              f"{r.get('cpu_time') or ''} | " +
              " | ".join(f"{float(r[m]):+.3f}" for m in metrics) + f" | {r['energy_error']} | {r['load_before']} |")
    # What each move away from the defaults buys: the change of the worst |error| over the
    # metrics against the change of time, CPU where recorded (both relative to the default run).
    base = next(r for r in rows if r["knob"] == "default")
    worst = lambda r: max(abs(float(r[m])) for m in metrics)
    e0, t0 = worst(base), seconds(base)
    print(f"\n| knob | value | time / default | worst error (default {e0:.3f}) | error change per doubling of time |")
    print("|---|---|---|---|---|")
    for r in rows:
        if r is base:
            continue
        ratio = seconds(r) / t0
        de = worst(r) - e0
        per = de / math.log2(ratio) if abs(math.log2(ratio)) > 0.15 else float("nan")
        print(f"| {r['knob']} | {r['value']} | {ratio:.2f} | {worst(r):.3f} | {per:+.3f} |")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("build")
    p.add_argument("--cases", default="bars,hertz,ring")
    p.add_argument("--runs", default="/tmp/speed_accuracy_runs")
    p.add_argument("--plot-only", action="store_true")
    a = p.parse_args()
    os.makedirs(RESULTS, exist_ok=True)
    cases = a.cases.split(",")
    if not a.plot_only:
        with open(os.path.join(RESULTS, "speed_accuracy_machine.txt"), "w") as f:
            f.write(f"{platform.node()} {platform.machine()} cpus {os.cpu_count()}\n")
            f.write(f"started {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}, load {os.getloadavg()}\n")
        for c in cases:
            run_case(a.build, c, a.runs)
        with open(os.path.join(RESULTS, "speed_accuracy_machine.txt"), "a") as f:
            f.write(f"finished {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}, load {os.getloadavg()}\n")
    for c in cases:
        plot_case(c)


if __name__ == "__main__":
    main()
