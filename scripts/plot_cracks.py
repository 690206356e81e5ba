#!/usr/bin/env python3
"""Crack paths of runs with fracture, from their fields.h5 (the damage field).


Usage: plot_cracks.py OUT.png RUN_DIR[:TITLE] [RUN_DIR[:TITLE] ...] [--axes xy]

For each run folder, the last frame of fields.h5 is read: every element with
damage > 0 (a cohesive facet, damage = largest delta_max / delta_c) is drawn
at its reference centroid, projected on the plane of --axes (default xy),
coloured by damage (grey: no traction left); the elements damaged in the
first frame that has any damage are circled in red: where the crack started
(to the output interval). The mesh outline is the bounding box of the nodes.
Needs python3-h5py and python3-matplotlib (scripts/install-deps.sh).
"""
import sys

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def frames(f):
    return sorted(k for k in f.keys() if k.startswith("step_"))


def centroids(f, frame):
    mesh = f["mesh"][str(int(f[frame].attrs["mesh"]))]
    X = mesh["coordinates"][()]
    T = mesh["topology"][()][:, :4]
    return X, X[T].mean(axis=1)


def main(argv):
    axes = "xy"
    if "--axes" in argv:
        i = argv.index("--axes")
        axes = argv[i + 1]
        del argv[i : i + 2]
    out, runs = argv[1], argv[2:]
    ia, ib = "xyz".index(axes[0]), "xyz".index(axes[1])
    fig, ax = plt.subplots(len(runs), 1, figsize=(8, 3.2 * len(runs)), squeeze=False)
    for a, run in zip(ax[:, 0], runs):
        path, _, title = run.partition(":")
        with h5py.File(f"{path}/fields.h5", "r") as f:
            fr = frames(f)
            last = fr[-1]
            X, c = centroids(f, last)
            d = f[last]["damage"][()]
            first = next((k for k in fr if (f[k]["damage"][()] > 0).any()), None)
            t_last = f[last].attrs["time"]
            lo, hi = X.min(axis=0), X.max(axis=0)
            a.add_patch(plt.Rectangle((lo[ia], lo[ib]), hi[ia] - lo[ia], hi[ib] - lo[ib], fill=False, color="k", lw=0.8))
            a.scatter(c[:, ia], c[:, ib], s=0.3, color="0.85", rasterized=True)  # the mesh (notch = gap)
            m = d > 0
            sc = a.scatter(c[m, ia], c[m, ib], c=d[m], s=6, cmap="viridis_r", vmin=0, vmax=1)
            if first is not None:
                X0, c0 = centroids(f, first)
                m0 = f[first]["damage"][()] > 0
                a.scatter(c0[m0, ia], c0[m0, ib], s=60, facecolors="none", edgecolors="r", lw=1.2,
                          label=f"damaged at t = {f[first].attrs['time'] * 1e6:.0f} us (first frame with damage)")
                a.legend(loc="upper right", fontsize=7)
        a.set_aspect("equal")
        a.set_title(f"{title or path}: damaged elements at t = {t_last * 1e6:.0f} us", fontsize=9)
        a.set_xlabel(f"{axes[0]}, m")
        a.set_ylabel(f"{axes[1]}, m")
        fig.colorbar(sc, ax=a, label="damage")
    fig.tight_layout()
    fig.savefig(out, dpi=120)


if __name__ == "__main__":
    main(sys.argv)
