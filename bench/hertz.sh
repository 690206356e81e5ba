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
# and the wall time of each run (--threads 1). The figures come from
# hertz_metrics in bench/speed_accuracy/speed_accuracy.py.
# Run:     bash bench/hertz.sh BUILD_DIR [V] [sizes...]   (default V = 50 m/s,
#          sizes 1.0e-3 8.0e-4 6.0e-4 m)
#          PLACEMENT=middle for contact.placement: middle (default end).
# Output:  bench/results/hertz.csv (hertz_middle.csv) and a table on stdout.
# Expect:  durations 5-12 % short of t_c and peak forces within 20 % at these
#          sizes (the contact patch, radius ~0.8 mm at 50 m/s, spans one or
#          two elements; docs/contact.md); about 2 minutes in all.
set -euo pipefail
build=${1:?usage: hertz.sh BUILD_DIR [V] [sizes...]}
shift
speed=${1:-50}
[ $# -gt 0 ] && shift
sizes=("$@")
placement=${PLACEMENT:-end}
suffix=$([ "$placement" = end ] && echo "" || echo "_$placement")
[ ${#sizes[@]} -eq 0 ] && sizes=(1.0e-3 8.0e-4 6.0e-4)
here=$(cd "$(dirname "$0")" && pwd)
out="$here/results"
mkdir -p "$out"
csv_out="$out/hertz$suffix.csv"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

half=$(python3 -c "print($speed / 2)")

echo "h,elements,steps,t_contact,t_hertz,duration_error,f_peak,f_hertz,force_error,energy_error,wall_time" > "$csv_out"
for h in "${sizes[@]}"; do
  dir="$work/h$h"
  "$build/apps/shatter" run "$here/speed_accuracy/hertz_spheres.yaml" --out "$dir" --threads 1 --quiet \
    --set "bodies[0].mesh.element_size=$h" --set "bodies[1].mesh.element_size=$h" \
    --set "bodies[0].initial_velocity=[$half,0,0]" --set "bodies[1].initial_velocity=[-$half,0,0]" \
    --set "contact.placement=$placement"
  /usr/bin/python3 - "$dir" "$h" "$speed" "$here/speed_accuracy" >> "$csv_out" <<'EOF'
import json, sys
d, h, v = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
sys.path.insert(0, sys.argv[4])
from speed_accuracy import hertz_metrics
s = json.load(open(d + "/summary.json"))
m = hertz_metrics(d, h, v)
print(f"{h},{s['elements']},{s['steps']},{m['t_contact']:.6e},{m['t_hertz']:.6e},{m['duration_error']:+.4f},"
      f"{m['f_peak']:.6e},{m['f_hertz']:.6e},{m['force_error']:+.4f},{s['energy_error']:+.3e},{s['wall_time']:.1f}")
EOF
  tail -1 "$csv_out"
done
column -s, -t "$csv_out"
