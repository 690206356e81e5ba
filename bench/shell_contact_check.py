#!/usr/bin/python3
"""Checks a run of shells in contact from its outputs, without DCR code
(docs/shells.md "Contact", docs/examples.md "Two spherical shells").

For every frame of fields.h5: the smallest distance from a vertex of one shell
to the triangles of another (closest point on the triangle, brute force over
the triangles near it), on the control net (`coordinates` + `displacement`,
the contact surface) and on the mid-surface (the limit points of the control
vertices, `shell_coordinates` + `shell_displacement`, with the control
triangles), relative to the thickness t (two shells keep their control nets t
apart). From history.csv: the ledger's total error, the largest |P - P0| and
|L - L0|, the contact dissipation. With --plot, a PNG of the energies; with
--shapes, a PNG of the mid-surfaces' points near z = 0 (a slice through the
centres) at five frames.

Usage: /usr/bin/python3 bench/shell_contact_check.py OUT_DIR THICKNESS [--plot FILE.png] [--shapes FILE.png]
"""
import csv
import subprocess
import sys

import numpy as np


def h5_dataset(path, name):
    """A dataset of fields.h5 as a float array, through h5dump (no h5py here)."""
    text = subprocess.run(["h5dump", "-d", name, "-y", "-w", "0", path], capture_output=True, text=True,
                          check=True).stdout
    start = text.index("DATA {") + 6
    body = text[start:text.index("}", start)]
    values = [float(v) for v in body.replace(",", " ").split()]
    return np.array(values)


def frames(path):
    text = subprocess.run(["h5ls", path], capture_output=True, text=True, check=True).stdout
    return [line.split()[0] for line in text.splitlines() if line.startswith("step_")]


def point_triangle_distances(p, a, b, c):
    """Distance from each point p[k] to the triangle (a[k], b[k], c[k]) (arrays of rows)."""
    ab, ac, ap = b - a, c - a, p - a
    n = np.cross(ab, ac)
    nn = np.einsum("ij,ij->i", n, n)
    lb = np.einsum("ij,ij->i", np.cross(ap, ac), n) / nn
    lc = np.einsum("ij,ij->i", np.cross(ab, ap), n) / nn
    inside = (lb >= 0) & (lc >= 0) & (lb + lc <= 1)
    face = np.abs(np.einsum("ij,ij->i", ap, n)) / np.sqrt(nn)

    def segment(u, v):
        d = v - u
        s = np.clip(np.einsum("ij,ij->i", p - u, d) / np.einsum("ij,ij->i", d, d), 0, 1)
        return np.linalg.norm(p - (u + s[:, None] * d), axis=1)

    edge = np.minimum(np.minimum(segment(a, b), segment(b, c)), segment(c, a))
    return np.where(inside, face, edge)


def smallest_distance(x, triangles, body):
    """Smallest distance from a vertex of one body to a triangle of another."""
    vertex_body = np.full(len(x), -1)
    for k in range(3):
        vertex_body[triangles[:, k]] = body
    best = np.inf
    centres = x[triangles].mean(axis=1)
    radius = np.max(np.linalg.norm(x[triangles] - centres[:, None, :], axis=2), axis=1)
    for b in np.unique(body):
        mine = np.where(vertex_body == b)[0]
        theirs = np.where(body != b)[0]
        # Candidates: triangles whose bounding sphere comes within the current best of the vertex.
        lo, hi = x[mine].min(axis=0), x[mine].max(axis=0)
        near = theirs[np.all((centres[theirs] + radius[theirs, None] > lo - 0.2) &
                             (centres[theirs] - radius[theirs, None] < hi + 0.2), axis=1)]
        for v in mine:
            d2 = np.linalg.norm(centres[near] - x[v], axis=1) - radius[near]
            cand = near[d2 < min(best, 0.2)]
            if len(cand) == 0:
                continue
            t = triangles[cand]
            p = np.repeat(x[v][None, :], len(cand), axis=0)
            best = min(best, point_triangle_distances(p, x[t[:, 0]], x[t[:, 1]], x[t[:, 2]]).min())
    return best


def main():
    out, t = sys.argv[1], float(sys.argv[2])
    plot = sys.argv[sys.argv.index("--plot") + 1] if "--plot" in sys.argv else None
    fields = out + "/fields.h5"
    tri = h5_dataset(fields, "/mesh/0/shell_topology").astype(int).reshape(-1, 3)
    body = h5_dataset(fields, "/mesh/0/shell_body").astype(int)
    X = h5_dataset(fields, "/mesh/0/coordinates").reshape(-1, 3)
    Y = h5_dataset(fields, "/mesh/0/shell_coordinates").reshape(-1, 3)
    worst_net, worst_mid = np.inf, np.inf
    slices = []
    for f in frames(fields):
        u = h5_dataset(fields, "/" + f + "/displacement").reshape(-1, 3)
        w = h5_dataset(fields, "/" + f + "/shell_displacement").reshape(-1, 3)
        net, mid = smallest_distance(X + u, tri, body) / t, smallest_distance(Y + w, tri, body) / t
        worst_net, worst_mid = min(worst_net, net), min(worst_mid, mid)
        slices.append((f, Y + w))
        print(f"{f}: smallest distance / t: control nets {net:.6f}, mid-surfaces {mid:.6f}")
    print(f"smallest over the frames: control nets {worst_net:.6f} t, mid-surfaces {worst_mid:.6f} t")
    if "--shapes" in sys.argv:
        plot_shapes(slices, t, sys.argv[sys.argv.index("--shapes") + 1])

    rows = list(csv.DictReader(open(out + "/history.csv")))
    col = lambda k: np.array([float(r[k]) for r in rows])
    total, kinetic, strain = col("total"), col("kinetic"), col("strain")
    P = np.stack([col("px"), col("py"), col("pz")], axis=1)
    L = np.stack([col("Lx"), col("Ly"), col("Lz")], axis=1)
    e0 = total[0]
    print(f"ledger total: final {(total[-1] - e0) / e0:+.3e}, largest |error| {np.max(np.abs(total - e0)) / e0:.3e}"
          f" of the initial energy {e0:.6g}")
    print(f"kinetic + strain at the end: {(kinetic[-1] + strain[-1] - e0) / e0:+.3e}; contact_dissipated "
          f"{col('contact_dissipated')[-1] / e0:.3e}, contact_work {col('contact_work')[-1] / e0:+.3e} of it")
    print(f"|P - P0| largest {np.max(np.linalg.norm(P - P[0], axis=1)):.3e} (|P0| = {np.linalg.norm(P[0]):.3e}, "
          f"sum m|v| scale: see the test); |L - L0| largest {np.max(np.linalg.norm(L - L[0], axis=1)):.3e}")
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        time = col("time")
        fig, ax = plt.subplots(figsize=(7, 4))
        for key, label in [("kinetic", "kinetic"), ("strain", "strain"), ("contact_dissipated", "contact dissipated"),
                           ("contact_work", "contact work"), ("total", "total (ledger)")]:
            ax.plot(time * 1e3, col(key), label=label)
        ax.set_xlabel("time (ms)")
        ax.set_ylabel("energy")
        ax.set_title(out.rstrip("/").split("/")[-1])
        ax.legend()
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(plot, dpi=110)


def plot_shapes(slices, t, path):
    """The mid-surfaces' limit points within 2 t of z = 0, at five frames."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    picks = [slices[round(k * (len(slices) - 1) / 4)] for k in range(5)]
    fig, axes = plt.subplots(1, 5, figsize=(15, 3.4), sharey=True)
    for ax, (name, y) in zip(axes, picks):
        near = np.abs(y[:, 2]) < 2 * t
        ax.plot(y[near, 0], y[near, 1], ".", markersize=2)
        ax.set_title(name)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


if __name__ == "__main__":
    main()
