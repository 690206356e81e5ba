#!/usr/bin/env bash
# hertz.sh — DCR accuracy against Hertz: two equal elastic steel spheres
# (R = 5 mm, E = 210 GPa, nu = 0.3) meeting head-on at +-V/2, frictionless,
# e = 1, for three mesh sizes.
#
# What it shows: the contact duration (first to last step with a resolved
# contact pair) against Hertz's t_c = 2.87 (m*^2 / (R* E*^2 v))^(1/5) with
# m* = m1 m2 / (m1 + m2), R* = R1 R2 / (R1 + R2), E* = E / (2 (1 - nu^2)),
# v the approach speed; the peak contact force m dv/dt of one sphere's centre
# of mass (centred difference over 2k steps, k = 5) against
# F_max = 4/3 E* sqrt(R*) d_max^(3/2), d_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5);
# and the wall time of each run (--threads 1).
# Run:     bash bench/hertz.sh BUILD_DIR [V] [sizes...]   (default V = 50 m/s,
#          sizes 1.0e-3 8.0e-4 6.0e-4 m)
# Output:  bench/results/hertz.csv and a table on stdout.
# Expect:  durations 5-12 % short of t_c and peak forces within 20 % at these
#          sizes (the contact patch, radius ~0.8 mm at 50 m/s, spans one or
#          two elements; docs/contact.md); about 2 minutes in all.
set -euo pipefail
build=${1:?usage: hertz.sh BUILD_DIR [V] [sizes...]}
shift
speed=${1:-50}
[ $# -gt 0 ] && shift
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(1.0e-3 8.0e-4 6.0e-4)
here=$(cd "$(dirname "$0")" && pwd)
out="$here/results"
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

half=$(python3 -c "print($speed / 2)")
cat > "$work/hertz.yaml" <<EOF
name: hertz
time:
  end: 1.8e-5
output:
  every: 0
  history_every: 1
materials:
  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}
bodies:
  - name: left
    material: steel
    mesh: {shape: sphere, radius: 5.0e-3, center: [-5.01e-3, 0, 0], element_size: 1.0e-3, order: 1}
    initial_velocity: [$half, 0, 0]
  - name: right
    material: steel
    mesh: {shape: sphere, radius: 5.0e-3, center: [5.01e-3, 0, 0], element_size: 1.0e-3, order: 1}
    initial_velocity: [-$half, 0, 0]
contact: {friction: 0.0, restitution: 1.0}
EOF

echo "h,elements,steps,t_contact,t_hertz,duration_error,f_peak,f_hertz,force_error,energy_error,wall_time" > "$out/hertz.csv"
for h in "${sizes[@]}"; do
  dir="$work/h$h"
  "$build/apps/shatter" run "$work/hertz.yaml" --out "$dir" --threads 1 --quiet \
    --set "bodies[0].mesh.element_size=$h" --set "bodies[1].mesh.element_size=$h"
  python3 - "$dir" "$h" "$speed" >> "$out/hertz.csv" <<'EOF'
import csv, json, math, sys
d, h, v = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
E, nu, rho, R = 210.0e9, 0.3, 7850.0, 5.0e-3
s = json.load(open(d + "/summary.json"))
hist = list(csv.DictReader(open(d + "/history.csv")))
t_on = [float(r["time"]) for r in hist if int(r["contacts"]) > 0]
rows = [r for r in csv.DictReader(open(d + "/bodies.csv")) if r["body"] == "left"]
m = float(rows[0]["mass"])  # the meshed sphere's mass
ms, Rs, Es = m / 2, R / 2, E / (2 * (1 - nu * nu))
t_h = 2.87 * (ms * ms / (Rs * Es * Es * v)) ** 0.2
d_max = (15 * ms * v * v / (16 * Es * math.sqrt(Rs))) ** 0.4
f_h = 4.0 / 3.0 * Es * math.sqrt(Rs) * d_max ** 1.5
t = [float(r["time"]) for r in rows]
u = [float(r["vx"]) for r in rows]
k = 5
f_peak = max(abs(m * (u[i + k] - u[i - k]) / (t[i + k] - t[i - k])) for i in range(k, len(t) - k))
dur = t_on[-1] - t_on[0] if t_on else 0.0
print(f"{h},{s['elements']},{s['steps']},{dur:.6e},{t_h:.6e},{dur / t_h - 1:+.4f},{f_peak:.6e},{f_h:.6e},"
      f"{f_peak / f_h - 1:+.4f},{s['energy_error']:+.3e},{s['wall_time']:.1f}")
EOF
  tail -1 "$out/hertz.csv"
done
column -s, -t "$out/hertz.csv"
