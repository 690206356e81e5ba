#!/usr/bin/env python3
"""Crack paths of runs with fracture, from their fields.h5 (the damage field).


Usage: plot_cracks.py OUT.png RUN_DIR[:TITLE] [RUN_DIR[:TITLE] ...] [--axes xy]

For each run folder, the last frame of fields.h5 (and of its restart_*
folders; read with scripts/crack_frames.py) is read: every element with
damage > 0 (a cohesive facet, damage = largest delta_max / delta_c) is drawn
at its reference centroid, projected on the plane of --axes (default xy),
coloured by damage (grey: no traction left); the elements damaged in the
first frame that has any damage are circled in red: where the crack started
(to the output interval). The mesh outline is the bounding box of the nodes.
Needs python3-h5py and python3-matplotlib (scripts/install-deps.sh).
"""
import sys

import matplotlib

from crack_frames import field_paths, frames

matplotlib.use("Agg")
import matplotlib.pyplot as plt


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
        fr = frames(field_paths(path))
        t_last, X, c, d = fr[-1]
        lo, hi = X.min(axis=0), X.max(axis=0)
        a.add_patch(plt.Rectangle((lo[ia], lo[ib]), hi[ia] - lo[ia], hi[ib] - lo[ib], fill=False, color="k", lw=0.8))
        a.scatter(c[:, ia], c[:, ib], s=0.3, color="0.85", rasterized=True)  # the mesh (notch = gap)
        m = d > 0
        sc = a.scatter(c[m, ia], c[m, ib], c=d[m], s=6, cmap="viridis_r", vmin=0, vmax=1)
        first = next((f for f in fr if (f[3] > 0).any()), None)
        if first is not None:
            t0, _, c0, d0 = first
            m0 = d0 > 0
            a.scatter(c0[m0, ia], c0[m0, ib], s=60, facecolors="none", edgecolors="r", lw=1.2,
                      label=f"damaged at t = {t0 * 1e6:.0f} us (first frame with damage)")
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
