#!/usr/bin/env python3
"""ring_mesh.py — a structured ring of TET4 whose radial planes are facets.

The expanding ring checks a 1D theory (Zhou-Molinari-Ramesh) in which every
crack crosses the bar at right angles, with area a^2. On an unstructured tet
mesh the cracks zigzag along inclined facets and debond 1.2-1.7 a^2 each
(docs/validation.md). This mesh puts a plane of facets at every
theta = 2 pi k / n_t, so a crack can cross the ring on exactly a^2.

The ring (mean radius R, square cross-section a x a, axis z, z in [-a/2, a/2])
is cut into n_r x n_z x n_t cells (radial, axial, around); each cell, a hex in
(r, z, theta), is split into six tets along its (0,0,0)-(1,1,1) diagonal (the
Kuhn split), which is conforming between cells because every cell is split
the same way. Faces of constant theta are therefore pairs of facets; the
inside of a cell has inclined facets too, so cracks are biased toward, not
forced onto, the radial planes. Straight edges between nodes: the ring is a
polygon of n_t sides (chord error R (1 - cos(pi / n_t)), < 2e-5 R here).

Writes a Gmsh 2.2 ASCII .msh (physical volume 1, "ring") and prints the mesh
quality to stderr: tets, the shortest and longest edges, the smallest
altitude (what sets the stable step), and the worst radius ratio
3 r_in / r_out (1 for a regular tet).
Run: python3 bench/ring_mesh.py R a n_r n_z n_t OUT.msh
"""
import itertools
import math
import sys


def ring_nodes(R, a, n_r, n_z, n_t):
    """Node coordinates and a function (i, j, k) -> node index (k periodic)."""
    xs = []
    for k in range(n_t):
        t = 2 * math.pi * k / n_t
        for j in range(n_z + 1):
            z = -a / 2 + a * j / n_z
            for i in range(n_r + 1):
                r = R - a / 2 + a * i / n_r
                xs.append((r * math.cos(t), r * math.sin(t), z))
    index = lambda i, j, k: (k % n_t) * (n_z + 1) * (n_r + 1) + j * (n_r + 1) + i
    return xs, index


def signed_volume(p):
    d = [[p[m][c] - p[0][c] for c in range(3)] for m in (1, 2, 3)]
    return (d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1])
            - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
            + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0])) / 6


def ring_tets(xs, index, n_r, n_z, n_t):
    """Six positively oriented tets per cell, split along the cell's main diagonal."""
    tets = []
    for k in range(n_t):
        for j in range(n_z):
            for i in range(n_r):
                for perm in itertools.permutations(range(3)):
                    corner = [0, 0, 0]
                    tet = [index(i, j, k)]
                    for axis in perm:
                        corner[axis] = 1
                        tet.append(index(i + corner[0], j + corner[1], k + corner[2]))
                    if signed_volume([xs[n] for n in tet]) < 0:
                        tet[2], tet[3] = tet[3], tet[2]
                    tets.append(tet)
    return tets


def quality(xs, tets):
    """Shortest and longest edge, smallest altitude, worst radius ratio."""
    def sub(u, v):
        return [u[c] - v[c] for c in range(3)]

    def cross(u, v):
        return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]

    norm = lambda u: math.sqrt(sum(c * c for c in u))
    emin, emax, hmin, qmin = math.inf, 0.0, math.inf, math.inf
    for tet in tets:
        p = [xs[n] for n in tet]
        V = signed_volume(p)
        edges = [norm(sub(p[m], p[n])) for m, n in itertools.combinations(range(4), 2)]
        faces = [norm(cross(sub(p[b], p[a]), sub(p[c], p[a]))) / 2 for a, b, c in itertools.combinations(range(4), 3)]
        emin, emax = min(emin, *edges), max(emax, *edges)
        hmin = min(hmin, 3 * V / max(faces))
        r_in = 3 * V / sum(faces)
        # circumradius from the edge lengths (a b c products of opposite edges)
        l01, l02, l03, l12, l13, l23 = edges
        s = [l01 * l23, l02 * l13, l03 * l12]
        prod = (s[0] + s[1] + s[2]) * (-s[0] + s[1] + s[2]) * (s[0] - s[1] + s[2]) * (s[0] + s[1] - s[2])
        r_out = math.sqrt(max(prod, 0.0)) / (24 * V)
        qmin = min(qmin, 3 * r_in / r_out)
    return emin, emax, hmin, qmin


def write_msh(path, xs, tets):
    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
        f.write('$PhysicalNames\n1\n3 1 "ring"\n$EndPhysicalNames\n')
        f.write(f"$Nodes\n{len(xs)}\n")
        for n, x in enumerate(xs):
            f.write(f"{n + 1} {x[0]:.17g} {x[1]:.17g} {x[2]:.17g}\n")
        f.write(f"$EndNodes\n$Elements\n{len(tets)}\n")
        for e, t in enumerate(tets):
            f.write(f"{e + 1} 4 2 1 1 {t[0] + 1} {t[1] + 1} {t[2] + 1} {t[3] + 1}\n")
        f.write("$EndElements\n")


def main():
    if len(sys.argv) != 7:
        sys.exit("usage: ring_mesh.py R a n_r n_z n_t OUT.msh")
    R, a = float(sys.argv[1]), float(sys.argv[2])
    n_r, n_z, n_t = (int(v) for v in sys.argv[3:6])
    xs, index = ring_nodes(R, a, n_r, n_z, n_t)
    tets = ring_tets(xs, index, n_r, n_z, n_t)
    write_msh(sys.argv[6], xs, tets)
    emin, emax, hmin, qmin = quality(xs, tets)
    print(f"{len(tets)} tets, {len(xs)} nodes; edges {emin:.4g} to {emax:.4g} m, smallest altitude {hmin:.4g} m, "
          f"worst radius ratio {qmin:.3f}", file=sys.stderr)


if __name__ == "__main__":
    main()
