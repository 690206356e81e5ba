#!/usr/bin/env bash
# rigid_skip.sh — what a rigid body's skipped element loop saves (issue 20).
#
# What it shows: bench/rigid_anvil.yaml (a ~40k-element steel anvil under a
# small rubber ball) with the anvil `rigid: free` (its elements never
# computed) and `rigid: false` (computed), runs interleaved A B A B ..., each
# run's /proc/loadavg beside it:
#   fixed:  both at the scene's fixed step (the steel's stable step): the cost
#           per step (summary.json time_per_step, element_loop_time);
#   stable: each at its own stable step (time.dt removed: the rigid anvil sets
#           none, so the rubber's governs): steps and wall time of the run.
# Run:     bash bench/rigid_skip.sh BUILD_DIR      (REPS=3 by default; one thread)
# Output:  bench/results/rigid_skip.csv (one row per run) and the medians per
#          case on stdout.
# Expect:  a few minutes on a quiet core.
set -euo pipefail
build=${1:?usage: rigid_skip.sh BUILD_DIR}
here=$(cd "$(dirname "$0")" && pwd)
scene=$here/rigid_anvil.yaml
reps=${REPS:-3}
out="$here/results/rigid_skip.csv"
mkdir -p "$here/results"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed '/^  dt:/d' "$scene" > "$work/stable.yaml"
field() { grep -o "\"$2\": [-0-9.e+]*" "$1/summary.json" | awk '{print $2}'; }
echo "case,anvil,run,load1_before,load1_after,steps,wall_time,time_per_step,element_loop_time,contact_dcr_time,energy_error" > "$out"
for r in $(seq 1 "$reps"); do
  for step in fixed stable; do
    for anvil in free false; do
      # Without time.dt the deformable anvil's stable step governs; the rigid one sets none.
      run_scene=$scene
      [ "$step" = stable ] && run_scene=$work/stable.yaml
      load0=$(cut -d' ' -f1 /proc/loadavg)
      "$build/apps/shatter" run "$run_scene" --out "$work/run" --threads 1 --quiet --set "bodies[0].rigid=$anvil"
      load1=$(cut -d' ' -f1 /proc/loadavg)
      echo "$step,$anvil,$r,$load0,$load1,$(field "$work/run" steps),$(field "$work/run" wall_time),$(field "$work/run" time_per_step),$(field "$work/run" element_loop_time),$(field "$work/run" contact_dcr_time),$(field "$work/run" energy_error)" >> "$out"
      rm -rf "$work/run"
    done
  done
done
/usr/bin/python3 - "$out" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
for case in ("fixed", "stable"):
    med = {}
    for anvil in ("free", "false"):
        sel = [r for r in rows if r["case"] == case and r["anvil"] == anvil]
        med[anvil] = {k: statistics.median(float(r[k]) for r in sel)
                      for k in ("steps", "wall_time", "time_per_step", "element_loop_time")}
        m = med[anvil]
        print(f"{case:6s} anvil {anvil:5s}: {m['steps']:.0f} steps, wall {m['wall_time']:.3f} s, "
              f"{1e3 * m['time_per_step']:.3f} ms/step, element loop {m['element_loop_time']:.3f} s")
    print(f"{case:6s} rigid/deformable: wall {med['free']['wall_time'] / med['false']['wall_time']:.3f}, "
          f"per step {med['free']['time_per_step'] / med['false']['time_per_step']:.3f}")
PY
