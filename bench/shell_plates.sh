#!/usr/bin/env bash
# shell_plates.sh — plates in the time loop (issue 17, "Done when" 1) on
# three meshes each: the simply supported square plate's first frequency
# (scenes/shell_plate_simply_supported.yaml, against Kirchhoff's
# omega_11 = 2 pi^2 / a^2 sqrt(D / (rho t))) and the cantilever's first
# frequency and static deflection under its weight
# (scenes/shell_cantilever.yaml, nu = 0: against Euler-Bernoulli,
# 3.5160 sqrt(D / (rho t L^4)) and, for the centre of mass, q L^4 / (20 D)).
#
# What it shows: omega and the mean deflection from a least-squares fit of
# cz(t) = A + B cos(omega t) + C sin(omega t) to bodies.csv (bench/shell_fit.py).
# Run:     bash bench/shell_plates.sh BUILD_DIR
# Output:  bench/results/shell_plates.csv and a table on stdout.
# Expect:  docs/shells.md "Plates in the time loop"; about 5 min on a quiet core.
set -euo pipefail
build=${1:?usage: shell_plates.sh BUILD_DIR}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
out="$here/results/shell_plates.csv"
echo "case,element_size,cells_along,triangles,omega,omega_theory,omega_error,deflection,deflection_theory,deflection_error" > "$out"
E=210.0e9 rho=7850 t=0.01 g=9.81
run() {  # scene, element size, the case's name
  local dir="$work/$3$2"
  "$build/apps/shatter" run "$here/../scenes/$1.yaml" --threads 1 --quiet --out "$dir" \
    --set "bodies[0].mesh.element_size=$2" > /dev/null
  python3 "$here/shell_fit.py" "$dir/bodies.csv"
}
for h in 0.125 0.0625 0.03125; do
  read -r w A r <<< "$(run shell_plate_simply_supported $h ss)"
  python3 - "$h" "$w" >> "$out" <<PY
import math, sys
h, w = float(sys.argv[1]), float(sys.argv[2])
D = $E * $t ** 3 / (12 * (1 - 0.3 ** 2))
theory = 2 * math.pi ** 2 * math.sqrt(D / ($rho * $t))
n = round(1 / h)
print(f"simply_supported,{h},{n},{2 * n * n},{w:.3f},{theory:.3f},{w / theory - 1:.5f},,,")
PY
done
for h in 0.0625 0.03125 0.015625; do
  read -r w A r <<< "$(run shell_cantilever $h cl)"
  python3 - "$h" "$w" "$A" >> "$out" <<PY
import math, sys
h, w, A = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
L = 0.5
D = $E * $t ** 3 / 12
theory = 3.5160 * math.sqrt(D / ($rho * $t * L ** 4))
static = $rho * $t * $g * L ** 4 / (20 * D)
n = round(L / h)
print(f"cantilever,{h},{n},{n * n},{w:.3f},{theory:.3f},{w / theory - 1:.5f},{-A:.5e},{static:.5e},{-A / static - 1:.5f}")
PY
done
column -s, -t "$out"
