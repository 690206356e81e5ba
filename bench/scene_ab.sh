#!/bin/bash
# scene_ab.sh — one scene on two builds, runs interleaved A B A B ... so that a
# change of the machine's load falls on both alike; prints per run the wall,
# contact search and DCR times, the search's thread CPU, the model bytes per
# rank and the load, and whether the two builds' history.csv are byte-equal.
#
# usage: [RANKS=2] [ROUNDS=3] [KEYS="..."] bench/scene_ab.sh SCENE BUILD_A BUILD_B [--set k=v ...]
#   RANKS ranks of one thread each (mpirun --oversubscribe --bind-to none);
#   KEYS: the summary.json keys to print (default below). Outputs in
#   ${OUT:-/tmp/scene_ab}/<a|b>_<round>.
set -euo pipefail
scene=$1 a=$2 b=$3
shift 3
ranks=${RANKS:-2} rounds=${ROUNDS:-3} out=${OUT:-/tmp/scene_ab}
keys=${KEYS:-"wall_time contact_search_time contact_dcr_time contact_search_cpu_time_max model_bytes_per_rank_max"}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out"
for round in $(seq 1 "$rounds"); do
  for side in a b; do
    build=$a; [ "$side" = b ] && build=$b
    dir="$out/${side}_$round"
    rm -rf "$dir"
    load=$(cut -d' ' -f1 /proc/loadavg)
    mpirun --oversubscribe --bind-to none -n "$ranks" "$build/apps/shatter" run "$scene" --threads 1 --quiet \
      --out "$dir" "$@" > /dev/null
    line="$side round $round:"
    for k in $keys; do line="$line $k $(grep -o "\"$k\": [-0-9.e+]*" "$dir/summary.json" | awk '{print $2}')"; done
    echo "$line load $load"
  done
  if cmp -s "$out/a_$round/history.csv" "$out/b_$round/history.csv"; then echo "round $round: history.csv equal"
  else echo "round $round: history.csv differs"; fi
done
