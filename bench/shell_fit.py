#!/usr/bin/env python3
"""shell_fit.py — fit cz(t) = A + B cos(w t) + C sin(w t) to a body's centre
of mass in bodies.csv (least squares; w by golden section about the first
guess from the swing's crossings of its mean). Prints w (rad/s), A (m) and
the rms residual over the amplitude. Used by bench/shell_plates.sh.
Usage: shell_fit.py DIR/bodies.csv"""
import csv, math, sys


def solve3(M, r):
    # Gaussian elimination with partial pivoting on the 3x3 normal equations
    M = [row[:] + [r[i]] for i, row in enumerate(M)]
    for c in range(3):
        p = max(range(c, 3), key=lambda i: abs(M[i][c]))
        M[c], M[p] = M[p], M[c]
        for i in range(c + 1, 3):
            f = M[i][c] / M[c][c]
            for j in range(c, 4):
                M[i][j] -= f * M[c][j]
    x = [0.0] * 3
    for i in (2, 1, 0):
        x[i] = (M[i][3] - sum(M[i][j] * x[j] for j in range(i + 1, 3))) / M[i][i]
    return x


def fit(t, z, w):
    cols = [[1.0] * len(t), [math.cos(w * s) for s in t], [math.sin(w * s) for s in t]]
    M = [[sum(a * b for a, b in zip(cols[i], cols[j])) for j in range(3)] for i in range(3)]
    r = [sum(a * b for a, b in zip(cols[i], z)) for i in range(3)]
    x = solve3(M, r)
    res = sum((zz - sum(x[k] * cols[k][i] for k in range(3))) ** 2 for i, zz in enumerate(z))
    return res, x


rows = list(csv.DictReader(open(sys.argv[1])))
t = [float(r["time"]) for r in rows]
z = [float(r["cz"]) for r in rows]
mean = sum(z) / len(z)
cross = [t[i] + (t[i + 1] - t[i]) * (mean - z[i]) / (z[i + 1] - z[i])
         for i in range(len(z) - 1) if (z[i] - mean) * (z[i + 1] - mean) < 0]
guess = math.pi * (len(cross) - 1) / (cross[-1] - cross[0])
lo, hi = 0.8 * guess, 1.2 * guess
g = (math.sqrt(5) - 1) / 2
a, b = hi - g * (hi - lo), lo + g * (hi - lo)
fa, fb = fit(t, z, a)[0], fit(t, z, b)[0]
while hi - lo > 1e-7 * guess:
    if fa < fb:
        hi, b, fb = b, a, fa
        a = hi - g * (hi - lo)
        fa = fit(t, z, a)[0]
    else:
        lo, a, fa = a, b, fb
        b = lo + g * (hi - lo)
        fb = fit(t, z, b)[0]
w = 0.5 * (lo + hi)
res, (A, B, C) = fit(t, z, w)
print(f"{w:.6g} {A:.6g} {math.sqrt(res / len(t)) / math.hypot(B, C):.3g}")
