"""Damage frames of a run's fields.h5, and cracks as connected fully open elements.

Shared by scripts/plot_cracks.py, bench/john_shah_crack.py and
bench/kalthoff_angle.py. Damage of an element = largest delta_max / delta_c
of its cohesive facets (fields.h5); an element is *fully open* when its
damage is 1 (a facet with no traction left: free crack faces).
Needs python3-h5py and python3-numpy (scripts/install-deps.sh).
"""
import glob
import sys

import h5py
import numpy as np

FULL = 1.0 - 1e-9


def field_paths(run):
    """fields.h5 of a run folder and, after a restart, those of its restart_* folders."""
    return [f"{run}/fields.h5"] + sorted(glob.glob(f"{run}/restart_*/fields.h5"))


def frames(paths):
    """(time, nodes, centroids, damage) of every frame of the files, by time, each time once.

    nodes and centroids are reference coordinates, m. Raises OSError or
    KeyError on a missing or unreadable file.
    """
    out = {}
    for p in paths:
        with h5py.File(p, "r") as f:
            for k in (k for k in f.keys() if k.startswith("step_")):
                g = f[k]
                mesh = f["mesh"][str(int(g.attrs["mesh"]))]
                X = mesh["coordinates"][()]
                T = mesh["topology"][()][:, :4]
                out[float(g.attrs["time"])] = (X, X[T].mean(axis=1), g["damage"][()])
    return [(t, X, c, d) for t, (X, c, d) in sorted(out.items())]


def run_frames(run, tool):
    """frames() of a run folder; a missing or empty file is a message naming `tool` and exit 2."""
    try:
        fr = frames(field_paths(run))
    except (OSError, KeyError) as e:
        print(f"{tool}: {run}: cannot read the damage frames: {e}", file=sys.stderr)
        sys.exit(2)
    if not fr:
        print(f"{tool}: {run}: no field frames", file=sys.stderr)
        sys.exit(2)
    return fr


def connected(pts, root, reach):
    """Points (rows of pts, in-plane x, y) joined to a `root` point through points at most `reach` apart."""
    reached = root.copy()
    if not reached.any():
        return reached
    near = np.linalg.norm(pts[:, None, :2] - pts[None, :, :2], axis=2) <= reach
    while True:
        grown = reached | near[reached].any(axis=0)
        if (grown == reached).all():
            return reached
        reached = grown
