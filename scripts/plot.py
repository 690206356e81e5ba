#!/usr/bin/env python3
"""shatter plot — figures of a run's time history (SCENE.md "Outputs in DIR").

Usage: plot.py OUTDIR          (or `shatter plot OUTDIR`)

Reads OUTDIR/history.csv (required), OUTDIR/bodies.csv and OUTDIR/fragments.csv
(when present) and writes PNGs into OUTDIR/plots/:

  energies.png   every ledger term of history.csv that is not 0 throughout
                 (contact_work too, when the file has it) and the total vs time
  momenta.png    linear momentum (px, py, pz) and angular momentum (Lx, Ly, Lz)
                 about the origin vs time
  contacts.png   active contacts vs time
  fragments.png  number of fragments vs time
  bodies.png     centre-of-mass velocity of each body vs time (bodies.csv)
  fragment_sizes.png  histogram of fragment masses (fragments.csv)

Uses matplotlib with the Agg backend (no display needed). Exit status 0 on
success, 2 when OUTDIR or history.csv is missing or history.csv is malformed.
"""
import csv
import os
import sys

# Columns of history.csv that are terms of the energy ledger, in the order of
# SCENE.md; `total` is drawn on top of them. contact_work is drawn when present:
# the history.csv of a shatter before it (issue 18) has no such column.
ENERGY_TERMS = ["kinetic", "strain", "cohesive_stored", "cohesive_dissipated", "contact_dissipated", "contact_work",
                "external_work"]
OPTIONAL_TERMS = ("contact_work",)
MOMENTA = ["px", "py", "pz", "Lx", "Ly", "Lz"]


def fail(message):
    print(f"shatter plot: error: {message}", file=sys.stderr)
    sys.exit(2)


def read_columns(path, text_columns=()):
    """Return {column name: list of floats} of a CSV file with a header row;
    the columns named in `text_columns` (body names) are kept as strings.
    A row that is not a row of numbers (corrupt, cut short, not text) ends
    the script through fail() naming the file and the line."""
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        fail(f"{path}: cannot be read: {e.strerror}")
    lines = []
    for number, line in enumerate(raw.split(b"\n"), 1):
        try:
            lines.append(line.decode("utf-8").rstrip("\r"))
        except UnicodeDecodeError:
            fail(f"{path}:{number}: not text (not UTF-8); expected a CSV row of numbers")
    if lines and lines[-1] == "":
        lines.pop()
    try:
        reader = csv.reader(lines)
        header = next(reader, None)
        if not header:
            fail(f"{path}: no header row")
        columns = {name: [] for name in header}
        for row in reader:
            where = f"{path}:{reader.line_num}"
            if len(row) != len(header):
                fail(f"{where}: expected {len(header)} comma-separated values, got {len(row)}")
            for name, value in zip(header, row):
                if name in text_columns:
                    columns[name].append(value)
                    continue
                try:
                    columns[name].append(float(value))
                except ValueError:
                    fail(f"{where}: column {name}: expected a number, got {value[:40]!r}")
    except csv.Error as e:
        fail(f"{path}:{reader.line_num + 1}: not a CSV row ({e})")
    return columns


def require(columns, names, path):
    missing = [n for n in names if n not in columns]
    if missing:
        fail(f"{path}: missing columns {', '.join(missing)}")


def new_figure(plt, title, rows=1):
    fig, axes = plt.subplots(rows, 1, figsize=(6.4, 2.6 + 1.6 * rows), dpi=80, sharex=True, squeeze=False)
    fig.suptitle(title)
    return fig, axes[:, 0]


def save(fig, plots_dir, name):
    fig.tight_layout()
    path = os.path.join(plots_dir, name)
    fig.savefig(path)
    print(path)


def plot_energies(plt, h, run, plots_dir):
    t = h["time"]
    fig, (ax,) = new_figure(plt, f"{run}: energy ledger")
    for term in ENERGY_TERMS:
        if term in h and any(v != 0 for v in h[term]):
            ax.plot(t, h[term], label=term)
    ax.plot(t, h["total"], "k--", linewidth=2, label="total")
    total0 = h["total"][0]
    scale = max(max(abs(v) for v in h["total"]), 1e-300)
    drift = max(abs(v - total0) for v in h["total"]) / scale
    ax.set_title(f"max |total - total(0)| / max |total| = {drift:.2e}", fontsize=9)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("energy [J]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    save(fig, plots_dir, "energies.png")


def plot_momenta(plt, h, run, plots_dir):
    t = h["time"]
    fig, (ax_p, ax_l) = new_figure(plt, f"{run}: momenta", rows=2)
    for name in MOMENTA[:3]:
        ax_p.plot(t, h[name], label=name)
    for name in MOMENTA[3:]:
        ax_l.plot(t, h[name], label=name)
    ax_p.set_ylabel("linear [kg m/s]")
    ax_l.set_ylabel("angular [kg m^2/s]")
    ax_l.set_xlabel("time [s]")
    for ax in (ax_p, ax_l):
        ax.legend(fontsize=8, ncol=3)
        ax.grid(alpha=0.3)
    save(fig, plots_dir, "momenta.png")


def plot_count(plt, h, run, plots_dir, column, label, name):
    fig, (ax,) = new_figure(plt, f"{run}: {label}")
    ax.step(h["time"], h[column], where="post")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(label)
    ax.grid(alpha=0.3)
    save(fig, plots_dir, name)


def plot_bodies(plt, path, run, plots_dir):
    b = read_columns(path, text_columns=("body",))
    require(b, ["time", "body", "vx", "vy", "vz"], path)
    names = list(dict.fromkeys(b["body"]))
    if len(names) > 12:
        # Many bodies: one line each would be unreadable; the ledger plots say it.
        return
    fig, axes = new_figure(plt, f"{run}: centre-of-mass velocity per body", rows=3)
    for body in names:
        rows = [i for i, n in enumerate(b["body"]) if n == body]
        t = [b["time"][i] for i in rows]
        for ax, c in zip(axes, ("vx", "vy", "vz")):
            ax.plot(t, [b[c][i] for i in rows], label=str(body))
    for ax, c in zip(axes, ("vx", "vy", "vz")):
        ax.set_ylabel(f"{c} [m/s]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, ncol=4)
    axes[-1].set_xlabel("time [s]")
    save(fig, plots_dir, "bodies.png")


def plot_fragment_sizes(plt, path, run, plots_dir):
    f = read_columns(path)
    require(f, ["mass"], path)
    masses = sorted(f["mass"])
    fig, (ax,) = new_figure(plt, f"{run}: fragment masses ({len(masses)} fragments)")
    if masses:
        ax.hist(masses, bins=min(40, max(5, len(masses) // 3)))
    ax.set_xlabel("fragment mass [kg]")
    ax.set_ylabel("fragments")
    ax.grid(alpha=0.3)
    save(fig, plots_dir, "fragment_sizes.png")


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    out_dir = argv[1]
    if not os.path.isdir(out_dir):
        fail(f"{out_dir}: no such output folder")
    history = os.path.join(out_dir, "history.csv")
    if not os.path.isfile(history):
        fail(f"{history}: no such file (is {out_dir} the output folder of a run?)")
    h = read_columns(history)
    required = [t for t in ENERGY_TERMS if t not in OPTIONAL_TERMS]
    require(h, ["time", "total", "contacts", "fragments"] + required + MOMENTA, history)
    if not h["time"]:
        fail(f"{history}: no rows")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plots_dir = os.path.join(out_dir, "plots")
    os.makedirs(plots_dir, exist_ok=True)
    run = os.path.basename(os.path.normpath(out_dir))
    plot_energies(plt, h, run, plots_dir)
    plot_momenta(plt, h, run, plots_dir)
    plot_count(plt, h, run, plots_dir, "contacts", "contacts", "contacts.png")
    plot_count(plt, h, run, plots_dir, "fragments", "fragments", "fragments.png")
    bodies = os.path.join(out_dir, "bodies.csv")
    if os.path.isfile(bodies):
        plot_bodies(plt, bodies, run, plots_dir)
    fragments = os.path.join(out_dir, "fragments.csv")
    if os.path.isfile(fragments):
        plot_fragment_sizes(plt, fragments, run, plots_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
