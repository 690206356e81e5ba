#!/bin/bash
# The same scene on 1x1, 2x1, 1x2, 3x1 and 4x1 ranks x threads must give the same
# history.csv and bodies.csv (and fragments.csv, and fields.h5's datasets when
# the scene writes frames), byte for byte (issue 6:
# "bitwise with --deterministic"; the decomposed loop is bitwise for any
# decomposition, so the flag changes nothing). Also checks that summary.json
# names the ranks, that `shatter check` says the same on 1 and 3 ranks, and
# that the comparison covers what the scene is for:
#   contact:  the run had contacts, and at 3 ranks every rank resolved pairs and
#             some pairs waited for a pair on another rank sharing a node;
#   fracture: cohesive elements were inserted between elements of different
#             ranks at 3 ranks (cracks crossing subdomain boundaries), and
#             each rank held only its part (two ghost layers; with contact
#             too, the cracks' faces in the patches): model_bytes_per_rank_max
#             below 0.85x that of 1 rank;
#   local_fracture: as fracture, but the cracks stay on one rank: at 3 ranks a
#             rank owns no cohesive element and another owns them all;
#   volume:   (no contact, no fracture) at 3 ranks each rank held only its
#             part of the model: model_bytes_per_rank_max below 0.6x that of 1 rank;
#   shell:    (shells without contact) the scene has shell elements.
# With shell bodies (any kind), at 3 ranks each rank computed fewer than all
# shell elements, each owned some, and the ghost update sent bytes.
# usage: same_history.sh SHATTER MPIEXEC SCENE WORKDIR contact|fracture|local_fracture|volume|shell [--set key=value ...]
set -euo pipefail
shatter=$1 mpiexec=$2 scene=$3 work=$4 kind=$5
shift 5
extra=("$@")
rm -rf "$work"
mkdir -p "$work"
run() {
  "$mpiexec" -n "$1" --allow-run-as-root --oversubscribe "$shatter" run "$scene" --out "$work/r$1t$2" \
    --threads "$2" --quiet --deterministic "${extra[@]}"
}
run 1 1
run 2 1
run 1 2
run 3 1
run 4 1
bytes() { grep -o '"model_bytes_per_rank_max": [0-9]*' "$work/$1/summary.json" | grep -o '[0-9]*$'; }
status=0
for d in r2t1 r1t2 r3t1 r4t1; do
  for f in history.csv bodies.csv $([ "$kind" != contact ] && [ "$kind" != volume ] && [ "$kind" != shell ] && echo fragments.csv); do
    if ! cmp -s "$work/r1t1/$f" "$work/$d/$f"; then
      echo "FAIL: $d/$f differs from r1t1/$f:"
      diff "$work/r1t1/$f" "$work/$d/$f" | head -4
      status=1
    fi
  done
  # Field frames (when the scene writes them): every dataset the same bits.
  if [ -f "$work/r1t1/fields.h5" ]; then
    /usr/bin/python3 "$(dirname "$0")/same_h5.py" "$work/r1t1/fields.h5" "$work/$d/fields.h5" > /dev/null ||
      { echo "FAIL: $d/fields.h5 differs from r1t1/fields.h5"; status=1; }
    cmp -s "$work/r1t1/fields.xdmf" "$work/$d/fields.xdmf" || { echo "FAIL: $d/fields.xdmf differs"; status=1; }
  fi
done
# `shatter check` prints the whole model's summary once on any rank count
# (the memory line is the largest rank's).
check() { "$mpiexec" -n "$1" --allow-run-as-root --oversubscribe "$shatter" check "$scene" "${extra[@]}" | grep -v '^memory:'; }
[ "$(check 1)" = "$(check 3)" ] || { echo "FAIL: shatter check on 3 ranks differs from 1 rank:"; check 3; status=1; }
grep -q '"ranks": 3' "$work/r3t1/summary.json" || { echo "FAIL: r3t1/summary.json does not say 3 ranks"; status=1; }
# The contact surface's size at the end (crack faces included) is the whole model's on any
# rank count (on parts, each triangle counted by its one owner).
tri() { grep -o '"contact_surface_triangles": [0-9]*' "$work/$1/summary.json" | grep -o '[0-9]*$'; }
[ "$(tri r1t1)" = "$(tri r3t1)" ] ||
  { echo "FAIL: contact_surface_triangles $(tri r3t1) at 3 ranks, $(tri r1t1) at 1"; status=1; }
if [ "$kind" = contact ]; then
  col=$(head -1 "$work/r1t1/history.csv" | tr ',' '\n' | grep -n '^contacts$' | cut -d: -f1)
  n=$(tail -n +2 "$work/r1t1/history.csv" | cut -d, -f"$col" | sort -n | tail -1)
  what="max contacts $n"
  # The partitioned contact stage (docs/parallel.md) must have given pairs to every rank.
  least=$(grep -o '"contact_pairs_per_step_rank_min": [-0-9.e+]*' "$work/r3t1/summary.json" | awk '{print $2}')
  awk -v m="${least:-0}" 'BEGIN { exit !(m > 0) }' || { echo "FAIL: a rank of 3 resolved no contact pairs"; status=1; }
  what="$what, at 3 ranks at least $least pairs per step per rank"
  # Pairs on different ranks shared nodes, so states passed between them (PatchRanks).
  passed=$(grep -o '"contact_states_passed": [0-9]*' "$work/r3t1/summary.json" | awk '{print $2}')
  awk -v m="${passed:-0}" 'BEGIN { exit !(m > 0) }' || { echo "FAIL: at 3 ranks no pair waited for one on another rank"; status=1; }
  what="$what, $passed states passed between ranks"
elif [ "$kind" = shell ]; then
  n=$(grep -o '"shell_elements": [0-9]*' "$work/r1t1/summary.json" | grep -o '[0-9]*$')
  what="$n shell elements"
elif [ "$kind" = volume ]; then
  one=$(bytes r1t1) three=$(bytes r3t1)
  awk -v a="$three" -v b="$one" 'BEGIN { exit !(a < 0.6 * b) }' && n=1 || n=0
  what="model bytes per rank $three at 3 ranks, $one at 1"
else
  key() { grep -o "\"$1\": [0-9]*" "$work/r3t1/summary.json" | grep -o '[0-9]*$'; }
  if [ "$kind" = local_fracture ]; then
    least=$(key cohesive_elements_per_rank_min) n=$(key cohesive_elements_per_rank_max)
    [ "${least:-1}" -eq 0 ] && [ "$n" -eq "$(key cohesive_elements)" ] ||
      { echo "FAIL: at 3 ranks the ranks own $least to $n of $(key cohesive_elements) cohesive elements: the cracks are not on one rank"; status=1; }
    what="at 3 ranks one rank owns all $n cohesive elements, another none"
  else
    n=$(key cohesive_elements_across_ranks)
    what="$n cohesive elements across ranks at 3 ranks"
  fi
  # A fracture scene runs on parts (two ghost layers), with contact too.
  one=$(bytes r1t1) three=$(bytes r3t1)
  awk -v a="$three" -v b="$one" 'BEGIN { exit !(a < 0.85 * b) }' ||
    { echo "FAIL: model bytes per rank $three at 3 ranks, $one at 1: the ranks do not hold parts"; status=1; }
  what="$what, model bytes per rank $three at 3 ranks, $one at 1"
fi
if grep -q '^ *shell:' "$scene"; then
  # Shells on ranks (docs/parallel.md "Shells on ranks"): at 3 ranks each rank
  # computes only its patches and their ghost layer, whose positions travel.
  key3() { grep -o "\"$1\": [0-9]*" "$work/r3t1/summary.json" | grep -o '[0-9]*$'; }
  total=$(key3 shell_elements) local=$(key3 shell_local_elements_max) owned=$(key3 shell_owned_elements_min)
  ghost=$(key3 ghost_bytes_per_step_max)
  [ "${local:-0}" -lt "${total:-0}" ] && [ "${owned:-0}" -gt 0 ] && [ "${ghost:-0}" -gt 0 ] ||
    { echo "FAIL: at 3 ranks a rank computes $local of $total shell elements, owns at least $owned, sends $ghost ghost bytes per step: the shells are not shared"; status=1; }
  what="$what, at 3 ranks at most $local of $total shell elements computed per rank, at least $owned owned, $ghost ghost bytes per step"
fi
[ "${n:-0}" -gt 0 ] || { echo "FAIL: $what: the comparison does not cover $kind"; status=1; }
[ $status -eq 0 ] && echo "same outputs at 1x1, 2x1, 1x2, 3x1, 4x1 ($what)"
exit $status
