#!/usr/bin/env bash
# shell_breathing.sh — the breathing mode of a free spherical shell through
# the runtime (issue 17, "Done when" 1; scenes/shell_sphere_breathing.yaml:
# R = 1 m, t = 10 mm, steel) on three meshes.
#
# What it shows: omega from history.csv (the kinetic energy's minima, two per
# period, each by a parabola through three rows; the period from the first
# and fifth) against membrane theory omega^2 = 2 E / (rho R^2 (1 - nu)), R the
# limit surface's radius (sqrt(volume / (4 pi t)) from the summary's body
# volume), and the cost of a shell element-step (summary.json).
# Run:     bash bench/shell_breathing.sh BUILD_DIR [sizes...]  (default 0.25 0.125 0.0625 m)
# Output:  bench/results/shell_breathing.csv and a table on stdout.
# Expect:  errors -0.87 %, -0.03 %, -0.05 % against R_limit (docs/shells.md);
#          about 30 s.
set -euo pipefail
build=${1:?usage: shell_breathing.sh BUILD_DIR [sizes...]}
shift
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(0.25 0.125 0.0625)
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
out="$here/results/shell_breathing.csv"
echo "element_size,vertices,triangles,omega,omega_theory,error,ns_per_element_step" > "$out"
for h in "${sizes[@]}"; do
  dir="$work/h$h"
  "$build/apps/shatter" check "$here/../scenes/shell_sphere_breathing.yaml" --set "bodies[0].mesh.element_size=$h" \
    > "$dir.check"
  "$build/apps/shatter" run "$here/../scenes/shell_sphere_breathing.yaml" --threads 1 --quiet --out "$dir" \
    --set "bodies[0].mesh.element_size=$h" --set time.end=3.0e-3
  python3 - "$dir" "$h" "$dir.check" >> "$out" <<'PY'
import csv, json, math, sys
d, h, check = sys.argv[1], float(sys.argv[2]), sys.argv[3]
rows = list(csv.DictReader(open(d + "/history.csv")))
t = [float(r["time"]) for r in rows]
k = [float(r["kinetic"]) for r in rows]
minima = []
for i in range(1, len(k) - 1):
    if k[i] < k[i - 1] and k[i] <= k[i + 1]:
        dt = t[i] - t[i - 1]
        minima.append(t[i] + 0.5 * dt * (k[i - 1] - k[i + 1]) / (k[i - 1] - 2 * k[i] + k[i + 1]))
period = 0.5 * (minima[4] - minima[0])
omega = 2 * math.pi / period
line = [l for l in open(check) if l.startswith("ball")][0].split()
vertices, volume = int(line[2]), float(line[5])
E, nu, rho, thickness = 210.0e9, 0.3, 7850.0, 0.01
R = math.sqrt(volume / thickness / (4 * math.pi))
theory = math.sqrt(2 * E / (rho * R * R * (1 - nu)))
s = json.load(open(d + "/summary.json"))
triangles = int(line[3])
ns = 1e9 / s["element_updates_per_second"]
print(f"{h},{vertices},{triangles},{omega:.2f},{theory:.2f},{omega / theory - 1:.5f},{ns:.0f}")
PY
done
column -s, -t "$out"
