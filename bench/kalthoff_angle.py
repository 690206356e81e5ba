#!/usr/bin/python3
"""Angle of the crack from the notch tip in a Kalthoff-Winkler run.

Usage: kalthoff_angle.py RUN_DIR [--h H] [--png OUT.png] [--csv]

The half plate of scenes/kalthoff_winkler.yaml (docs/validation.md): the
notch runs along +x from the struck edge x = 0 to its tip at x = 50 mm, its
centre line at y = 25 mm, 1.5 mm wide; the symmetry plane is y = 0.

Criterion. In the last field frame (fields.h5, read with
scripts/crack_frames.py), the crack is the set of fully open elements (damage
1) connected to the notch tip through fully open elements whose centroids are
at most 1.5 H apart (H = element size, default 1 mm: the scene's); its root
is the fully open elements whose centroids lie within 1.5 H of the tip's end
face (x = 50 mm, |y - 25 mm| <= 0.75 mm). The angle is that of the line
fitted through the crack's centroids (least squares on the perpendicular
distances: the principal axis of the centroids), pointed away from the tip,
against the notch direction +x, in degrees (positive toward +y, away from
the symmetry plane). The damage field is per element (the largest of its facets), so
the centroids are those of the elements next to the opened facets, half an
element off the crack faces at most.

Prints one line: `angle_deg=... elements=... length_mm=... t_ms=...`
(length: largest distance of a crack centroid from the tip, t: the frame's
time) or with --csv the values comma-separated; with --png also draws the
crack, the fitted line and the experiment's 70-degree line over the plate
outline. Exit 0 with a crack, 3 (message on stderr) when fewer than 3 fully
open elements are connected to the tip, 2 on a missing or unreadable run.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from crack_frames import FULL, connected, run_frames  # noqa: E402

TIP = np.array([0.050, 0.025])
NOTCH_HALF_WIDTH = 0.75e-3
EXPERIMENT_DEG = 70.0


def crack_from_tip(c, d, h):
    """In-plane centroids of the fully open elements connected to the notch tip."""
    pts = c[d >= FULL][:, :2]
    root = (np.abs(pts[:, 0] - TIP[0]) <= 1.5 * h) & (np.abs(pts[:, 1] - TIP[1]) <= NOTCH_HALF_WIDTH + 1.5 * h)
    return pts[connected(pts, root, 1.5 * h)]


def fitted_direction(pts):
    """Unit direction of the principal axis of the points, pointed away from the tip."""
    mean = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - mean)
    u = vt[0]
    return -u if np.dot(mean - TIP, u) < 0 else u, mean


def draw(out, X, c, d, crack, u, mean, angle, t):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, a = plt.subplots(figsize=(6.4, 6.0))
    lo, hi = X.min(axis=0) * 1e3, X.max(axis=0) * 1e3
    a.add_patch(plt.Rectangle(lo[:2], *(hi - lo)[:2], fill=False, color="k", lw=0.8))
    a.plot([lo[0], TIP[0] * 1e3], [TIP[1] * 1e3] * 2, color="k", lw=2.5, label="notch (1.5 mm wide)")
    m = d > 0
    sc = a.scatter(c[m, 0] * 1e3, c[m, 1] * 1e3, c=d[m], s=8, cmap="viridis_r", vmin=0, vmax=1)
    a.scatter(crack[:, 0] * 1e3, crack[:, 1] * 1e3, s=30, facecolors="none", edgecolors="r", lw=0.8,
              label=f"crack from the tip: {len(crack)} fully open elements")
    reach = np.max(np.linalg.norm(crack - TIP, axis=1))
    fit = mean + np.outer(np.array([-0.65, 0.65]) * reach, u)
    a.plot(fit[:, 0] * 1e3, fit[:, 1] * 1e3, "r-", lw=1.5, label=f"fitted: {angle:.1f} deg")
    e = np.radians(EXPERIMENT_DEG)
    ln = (hi[1] - TIP[1] * 1e3) / np.sin(e)
    a.plot([TIP[0] * 1e3, TIP[0] * 1e3 + ln * np.cos(e)], [TIP[1] * 1e3, hi[1]], "k--", lw=1,
           label=f"experiment: {EXPERIMENT_DEG:.0f} deg (Kalthoff 2000)")
    a.set_xlim(lo[0] - 2, hi[0] + 2)
    a.set_ylim(lo[1] - 2, hi[1] + 2)
    a.set_aspect("equal")
    a.set_xlabel("x, mm (struck edge at x = 0)")
    a.set_ylabel("y, mm (symmetry plane at y = 0)")
    a.set_title(f"Kalthoff-Winkler half plate: damaged elements at t = {t * 1e6:.0f} us", fontsize=9)
    a.legend(loc="lower right", fontsize=7)
    fig.colorbar(sc, ax=a, label="damage", shrink=0.8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)


def main(argv):
    csv = "--csv" in argv
    argv = [a for a in argv if a != "--csv"]
    opts = {"--h": "1.0e-3", "--png": None}
    for k in opts:
        if k in argv:
            i = argv.index(k)
            opts[k] = argv[i + 1]
            del argv[i : i + 2]
    if len(argv) != 2:
        sys.exit(__doc__)
    run, h = argv[1], float(opts["--h"])
    fr = run_frames(run, "kalthoff_angle")
    t, X, c, d = fr[-1]
    crack = crack_from_tip(c, d, h)
    if len(crack) < 3:
        print(f"kalthoff_angle: {run}: NO crack from the notch tip by t = {t * 1e6:.1f} us ({len(crack)} fully "
              f"open elements connected to it, 3 needed for a line): run longer", file=sys.stderr)
        return 3
    u, mean = fitted_direction(crack)
    angle = float(np.degrees(np.arctan2(u[1], u[0])))
    length = float(np.max(np.linalg.norm(crack - TIP, axis=1)))
    vals = [f"{angle:.1f}", str(len(crack)), f"{length * 1e3:.1f}", f"{t * 1e3:.4f}"]
    keys = ["angle_deg", "elements", "length_mm", "t_ms"]
    print(",".join(vals) if csv else " ".join(f"{k}={v}" for k, v in zip(keys, vals)))
    if opts["--png"]:
        draw(opts["--png"], X, c, d, crack, u, mean, angle, t)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
