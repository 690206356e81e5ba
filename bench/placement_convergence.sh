#!/usr/bin/env bash
# placement_convergence.sh — how the contact placements' kinetic + strain
# energy error moves with the time step and with the mesh (issue 18,
# docs/contact.md "Kinetic + strain energy under refinement").
#
# What it shows: for each scene, `end` and `middle` (contact.placement), each
# run by bench/contact_momenta.py (--threads 1): (a) at time.safety 0.5, 0.25
# and 0.125 on the scene's own mesh; (b) at the default step with every
# element_size of the scene divided by 2 and by 4 (a copy of the scene with
# its element sizes scaled, written to a temporary folder). The rows (K + U
# error, ledger total error, contact_work, steps) go to stdout and
# bench/results/contact_momenta.csv (contact_momenta.py appends there).
#
# Usage: bash bench/placement_convergence.sh BUILD_DIR SCENE... [--no-step] [--no-mesh]
# Expect: seconds per regression scene and step; the refined full scenes take
#         minutes (the 76 cubes at 1/2 their element size: ~230 000 TET4).
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: placement_convergence.sh BUILD_DIR SCENE... [--no-step] [--no-mesh]" >&2; exit 2; }
build=$1; shift
step=1; mesh=1; scenes=()
for a in "$@"; do
  case $a in
    --no-step) step=0 ;;
    --no-mesh) mesh=0 ;;
    *) scenes+=("$a") ;;
  esac
done
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
row() {  # scene, label, --set arguments...
  local scene=$1 label=$2; shift 2
  nice -n 15 /usr/bin/python3 "$here/contact_momenta.py" "$build" "$scene" "$@" | tail -1 |
    /usr/bin/python3 -c "
import sys
d = dict(kv.split('=', 1) for kv in sys.stdin.read().split() if '=' in kv)
print('%-40s %-28s K+U %+.2f %%  total %+.3f %%  contact_work %+.2f %%  steps %s' % (
    d['scene'], '$label', 100 * float(d['mechanical_error']), 100 * float(d['energy_error']),
    100 * float(d['contact_work']), d['steps']))"
}
for scene in "${scenes[@]}"; do
  for p in end middle; do
    if [ $step = 1 ]; then
      for s in 0.5 0.25 0.125; do row "$scene" "$p safety $s" --set contact.placement=$p --set time.safety=$s; done
    fi
    if [ $mesh = 1 ]; then
      for k in 2 4; do
        refined="$tmp/$(basename "${scene%.yaml}")_h_over_$k.yaml"
        # Every "element_size: X" of the scene becomes X / k (the scene's own keys, nothing else).
        /usr/bin/python3 -c "
import re, sys
text = open(sys.argv[1]).read()
out = re.sub(r'(element_size:\s*)([0-9.eE+-]+)', lambda m: m.group(1) + repr(float(m.group(2)) / $k), text)
open(sys.argv[2], 'w').write(out)" "$scene" "$refined"
        row "$refined" "$p h/$k" --set contact.placement=$p
      done
    fi
  done
done
