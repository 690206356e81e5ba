#!/usr/bin/env bash
# contact_cost.sh — what contact costs per step next to the element update.
#
# What it shows: for a scene with contact (default scenes/two_cylinders.yaml),
# the run's wall time split into the element loop (summary.json
# element_loop_time), the contact search (contact_search_time: swept boxes,
# sparse buckets, candidate pairs) and the DCR sweeps (contact_dcr_time:
# pair coloring, narrow phase, response), as medians of REPS runs at
# --threads 1; the contact share is (search + DCR) / wall time.
# Run:     bash bench/contact_cost.sh BUILD_DIR [SCENE] [--set ...]
#          REPS=3 by default.
# Output:  bench/results/contact_cost_<scene>.csv (one row per run, then the
#          medians) and the medians on stdout.
# Expect:  a couple of minutes for two_cylinders on a quiet core.
set -euo pipefail
build=${1:?usage: contact_cost.sh BUILD_DIR [SCENE] [--set key=value ...]}
shift
here=$(cd "$(dirname "$0")" && pwd)
scene=${1:-$here/../scenes/two_cylinders.yaml}
[ $# -gt 0 ] && shift
reps=${REPS:-3}
name=$(basename "$scene" .yaml)
out="$here/results/contact_cost_$name.csv"
mkdir -p "$here/results"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "run,steps,wall_time,element_loop_time,contact_search_time,contact_dcr_time,contact_share,energy_error,contact_capped_steps" > "$out"
for r in $(seq 1 "$reps"); do
  "$build/apps/shatter" run "$scene" --out "$work/run$r" --threads 1 --quiet --set output.every=0 "$@"
  python3 - "$work/run$r/summary.json" "$r" >> "$out" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
c = s["contact_search_time"] + s["contact_dcr_time"]
print(f"{sys.argv[2]},{s['steps']},{s['wall_time']:.3f},{s['element_loop_time']:.3f},{s['contact_search_time']:.3f},"
      f"{s['contact_dcr_time']:.3f},{c / s['wall_time']:.3f},{s['energy_error']:+.4e},{s['contact_capped_steps']}")
EOF
done
python3 - "$out" <<'EOF'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
keys = ["steps", "wall_time", "element_loop_time", "contact_search_time", "contact_dcr_time", "contact_share"]
med = {k: statistics.median(float(r[k]) for r in rows) for k in keys}
with open(sys.argv[1], "a") as f:
    f.write("median," + ",".join(f"{med[k]:.3f}" for k in keys) + ",,\n")
steps = med["steps"]
print(f"medians of {len(rows)} runs, {int(steps)} steps:")
for k in keys[1:5]:
    print(f"  {k:22s} {med[k]:8.3f} s  {1e3 * med[k] / steps:7.3f} ms/step")
print(f"  contact share of the wall time {med['contact_share']:.1%}; "
      f"contact / element loop {(med['contact_search_time'] + med['contact_dcr_time']) / med['element_loop_time']:.2f}")
EOF
