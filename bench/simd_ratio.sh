#!/usr/bin/env bash
# simd_ratio.sh — bench_step of several builds (e.g. SHATTER_SIMD=baseline and
# the default width, before and after a change), one thread, runs
# interleaved A B C A B C ..., each run's /proc/loadavg recorded beside its
# figures; prints and writes the medians and their ratios to the first
# build, by wall clock and per CPU-second of the process (= per core: the
# honest figure when other processes share the cores) (docs/performance.md
# "Whole step").
#
# Usage: RUNS=3 OUT=bench/results/simd_ratio.csv bash bench/simd_ratio.sh BUILD_A BUILD_B [BUILD...]
#   FILTER (default 'threads:1/'): bench_step's cases, e.g. 'order:2/threads:1/'
#   for the TET10 block alone (no TET4 block meshed: ~10 s per process).
#   RUNS (default 3): processes per build; each meshes the blocks (~10-30 s)
#   and runs bench_step's 1-thread cases (TET4 ~250k, TET10 ~13k elements)
#   with 3 repetitions. One thread: TBB runs the loop on the benchmark's
#   thread, whose CPU time Google Benchmark reports. Run it without `nice`
#   (a timing run), on a machine as quiet as can be: the load is in the CSV.
# Expect: RUNS x builds x ~40 s.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: RUNS=3 OUT=file.csv simd_ratio.sh BUILD_A BUILD_B [BUILD...]" >&2; exit 2; }
runs=${RUNS:-3}
out=${OUT:-$(cd "$(dirname "$0")" && pwd)/results/simd_ratio.csv}
source "$(dirname "$0")/interleaved.sh"
echo "build,run,order,load1_before,load1_after,ms_per_step,cpu_ms_per_step,M_element_steps_per_s,M_element_steps_per_cpu_s,element_loop_ms" > "$out"
BENCH_FLAGS=(--benchmark_filter="${FILTER:-threads:1/}" --benchmark_repetitions=3)
on_run() {
  /usr/bin/python3 - "$5" "$1" "$2" "$3" "$4" >> "$out" <<'PY'
import json, sys
src, build, run, l0, l1 = sys.argv[1:6]
for x in json.load(open(src))["benchmarks"]:
    if x.get("run_type") != "iteration":
        continue
    order = x["name"].split("order:")[1].split("/")[0]
    per_cpu = x["elements"] / (x["cpu_time"] * 1e-3) / 1e6  # times in ms
    print(f'{build},{run},{order},{l0},{l1},{x["real_time"]:.3f},{x["cpu_time"]:.3f},'
          f'{x["items_per_second"] / 1e6:.3f},{per_cpu:.3f},{1e3 * x["element_loop_s_per_step"]:.3f}')
PY
}
interleaved "$runs" bench_step "$@"
/usr/bin/python3 - "$out" "$@" <<'PY'
import csv, statistics, sys
path, builds = sys.argv[1], sys.argv[2:]
rows = list(csv.DictReader(open(path)))
for order in sorted({r["order"] for r in rows}):
    for col in ("M_element_steps_per_s", "M_element_steps_per_cpu_s"):
        med = {}
        for build in builds:
            v = [float(r[col]) for r in rows if r["build"] == build and r["order"] == order]
            med[build] = statistics.median(v)
            print(f"order {order} {col} {build}: median {med[build]:.2f} "
                  f"(min {min(v):.2f}, max {max(v):.2f}, {len(v)} runs), "
                  f"ratio to {builds[0]} {med[build] / med[builds[0]]:.2f}")
loads = [float(r["load1_before"]) for r in rows] + [float(r["load1_after"]) for r in rows]
print(f"load average (1 min) during the runs: {min(loads):.2f} - {max(loads):.2f}")
PY
