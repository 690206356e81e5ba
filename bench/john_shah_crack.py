#!/usr/bin/python3
"""Which crack runs in a John & Shah beam run: the notch crack or the mid-span crack.

Usage: john_shah_crack.py RUN_DIR GAMMA [--h H] [--csv]

The beam of scenes/john_shah_beam_g05.yaml (docs/validation.md): depth
D = 76.2 mm, span S = 203.2 mm, a notch of depth a = D / 4 = 19.05 mm whose
centre line is at x_n = GAMMA * S / 2, the load at x = 0 on the top face.

Criterion. Damage of an element = largest delta_max / delta_c of its cohesive
facets (fields.h5); an element is *fully open* when its damage is 1 (a facet
with no traction left: free crack faces). For each field frame and each of
the two regions of docs/validation.md (notch: centroids within 20 mm of the
notch line and below y = 50 mm; mid-span: within 30 mm of x = 0 and below
y = 30 mm), the crack of the region is the set of fully open elements
connected to its root through fully open elements whose centroids are at most
1.5 H apart (H = element size): the root of the notch crack is at the notch
tip (centroids within H of the tip line y = a, |x - x_n| <= 1.5 mm + H), the
root of the mid-span crack at the bottom face (centroids below y = H). Its
height is the largest centroid y of that set minus the root's y (a for the
notch, 0 for mid-span). A crack *runs* when its height reaches a = 19.05 mm
(a quarter of the depth: the mid-span crack has grown as high as the notch,
the notch crack one notch depth into the ligament). The crack that runs
first (earliest frame) is the one that runs; the frame interval is the time
resolution. Isolated fully open elements (support and load-line shear, a
facet popping alone) are not connected to a root and do not count.

Prints one line: `crack=notch|midspan t_run_ms=... notch_first_full_ms=...
midspan_first_full_ms=... notch_height_mm=... midspan_height_mm=...`
(heights at the last frame; first_full = first frame with any fully open
element in the region, "-" if none), or with --csv the same values
comma-separated. Exit 0 when a crack runs; exit 3 with a message on stderr
when neither crack runs by the last frame (run longer); exit 4 when both
reach the height in the same frame (undecided at this output interval);
exit 2 on a missing or unreadable run. Reads RUN_DIR/fields.h5 and, after a
restart, the frames of RUN_DIR/restart_*/fields.h5.
Needs python3-h5py and python3-numpy (scripts/install-deps.sh); reads the
frames with scripts/crack_frames.py.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from crack_frames import FULL, connected, run_frames  # noqa: E402

DEPTH = 0.0762
HALF_SPAN = 0.1016
NOTCH_DEPTH = DEPTH / 4
NOTCH_HALF_WIDTH = 0.0015


def crack_height(c, d, region, root, base, h):
    """Height above `base` of the fully open elements of `region` connected to `root`."""
    open_ = region & (d >= FULL)
    pts = c[open_]
    if len(pts) == 0:
        return 0.0, False
    reached = connected(pts, root[open_], 1.5 * h)
    if not reached.any():
        return 0.0, True
    return max(0.0, pts[reached, 1].max() - base), True


def main(argv):
    csv = "--csv" in argv
    argv = [a for a in argv if a != "--csv"]
    h = 8.0e-3
    if "--h" in argv:
        i = argv.index("--h")
        h = float(argv[i + 1])
        del argv[i : i + 2]
    if len(argv) != 3:
        sys.exit(__doc__)
    run, gamma = argv[1], float(argv[2])
    fr = run_frames(run, "john_shah_crack")
    xn = gamma * HALF_SPAN
    t_run = {}
    first_full = {}
    height = {}
    for t, _, c, d in fr:
        x, y = c[:, 0], c[:, 1]
        regions = {
            "notch": ((np.abs(x - xn) <= 0.020) & (y <= 0.050),
                      (np.abs(x - xn) <= NOTCH_HALF_WIDTH + h) & (np.abs(y - NOTCH_DEPTH) <= h), NOTCH_DEPTH),
            "midspan": ((np.abs(x) <= 0.030) & (y <= 0.030), y <= h, 0.0),
        }
        for name, (region, root, base) in regions.items():
            hgt, any_open = crack_height(c, d, region, root, base, h)
            height[name] = hgt
            if any_open:
                first_full.setdefault(name, t)
            if hgt >= NOTCH_DEPTH:
                t_run.setdefault(name, t)
    fmt = lambda k, dct: f"{dct[k] * 1e3:.4f}" if k in dct else "-"
    if not t_run:
        winner = "none"
    else:
        tmin = min(t_run.values())
        first = [k for k, v in t_run.items() if v == tmin]
        winner = first[0] if len(first) == 1 else "both"
    vals = [winner, fmt(winner, t_run) if winner in t_run else "-", fmt("notch", first_full),
            fmt("midspan", first_full), f"{height['notch'] * 1e3:.1f}", f"{height['midspan'] * 1e3:.1f}"]
    keys = ["crack", "t_run_ms", "notch_first_full_ms", "midspan_first_full_ms", "notch_height_mm",
            "midspan_height_mm"]
    print(",".join(vals) if csv else " ".join(f"{k}={v}" for k, v in zip(keys, vals)))
    t_last = fr[-1][0]
    if winner == "none":
        print(f"john_shah_crack: {run}: NEITHER crack runs by t = {t_last * 1e3:.3f} ms (no fully open crack "
              f"{NOTCH_DEPTH * 1e3:.2f} mm high at the notch tip or at mid-span bottom): run longer",
              file=sys.stderr)
        return 3
    if winner == "both":
        print(f"john_shah_crack: {run}: BOTH cracks reach {NOTCH_DEPTH * 1e3:.2f} mm in the frame at "
              f"{min(t_run.values()) * 1e3:.3f} ms: undecided at this output interval", file=sys.stderr)
        return 4
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
