#!/bin/bash
# Insertion on parts, two builds against each other (issue 15,
# docs/performance.md "Insertion on parts"): the hot field of
# bench/fracture_block.yaml on RANKS ranks of one thread, PER_RANK tets per
# rank, RUNS runs of each build interleaved (A B A B ...). Per run, from
# summary.json: steps, cohesive elements, and the largest rank's thread CPU
# time of the insertion and of the facet check, and the wall time; the
# histories of the two builds' first runs are compared (the same bits are
# expected when the change is only in speed).
#
#   bench/insertion_ratio.sh BUILD_A BUILD_B [RANKS] [PER_RANK] [RUNS]
#       defaults: 2 ranks, 20000 tets per rank, 3 runs.
# Results: bench/results/insertion_ratio.csv
set -euo pipefail
a=${1:?usage: insertion_ratio.sh BUILD_A BUILD_B [RANKS] [PER_RANK] [RUNS]} b=${2:?BUILD_B}
ranks=${3:-2} per_rank=${4:-20000} runs=${5:-3}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
side=$(python3 -c "print(f'{1.3e-3 * ($per_rank * $ranks / 10561) ** (1 / 3):.6e}')")
out="$here/results/insertion_ratio.csv"
echo "run,build,ranks,elements,steps,cohesive_elements,insert_cpu_s_max,check_cpu_s_max,wall_s,load1" > "$out"
for r in $(seq 1 "$runs"); do
  for which in A B; do
    build=$a
    [ "$which" = B ] && build=$b
    dir="$work/${which}_$r"
    mpirun --allow-run-as-root --oversubscribe --bind-to none -n "$ranks" "$build/apps/shatter" run \
      "$here/fracture_block.yaml" --out "$dir" --threads 1 --quiet \
      --set "bodies[0].mesh.size=[$side, $side, $side]" 2> /dev/null
    key() { grep -o "\"$1\": [0-9.e+-]*" "$dir/summary.json" | awk '{print $2}'; }
    echo "$r,$build,$ranks,$(key elements),$(key steps),$(key cohesive_elements),$(key fracture_insert_cpu_time_max),$(key fracture_check_cpu_time_max),$(key wall_time),$(cut -d' ' -f1 /proc/loadavg)" | tee -a "$out"
  done
done
if cmp -s "$work/A_1/history.csv" "$work/B_1/history.csv"; then
  echo "histories: the same bits" | tee -a "$out"
else
  echo "histories: differ" | tee -a "$out"
fi
