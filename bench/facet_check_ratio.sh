#!/usr/bin/env bash
# facet_check_ratio.sh — bench_fracture of one or more builds (e.g. before and
# after a change), one thread: the facet check (cold, mixed, hot stress
# fields) against the element update on the same ~73k-tet box. Processes run
# interleaved A B A B ..., each with its benchmarks in random interleaved
# order (--benchmark_enable_random_interleaving) and /proc/loadavg recorded
# beside its figures; prints the medians over all repetitions of all runs of
# a build, by CPU time of the benchmark's thread (one thread: TBB runs the
# loop there; the honest figure when other processes share the cores):
#   check / update            the ratio of the times (issue 19: hot <= 30 %)
#   ns per facet / ns per element   the check's time per facet of the mesh
#                                   against the update's time per element
# (docs/performance.md "Facet check against the element update").
#
# Usage: RUNS=3 REPS=5 OUT=bench/results/facet_check_ratio.csv bash bench/facet_check_ratio.sh BUILD_A [BUILD...]
# Expect: RUNS x builds x ~40 s (each process meshes the box first, ~10 s).
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: RUNS=3 REPS=5 OUT=file.csv facet_check_ratio.sh BUILD_A [BUILD...]" >&2; exit 2; }
runs=${RUNS:-3}
reps=${REPS:-5}
out=${OUT:-$(cd "$(dirname "$0")" && pwd)/results/facet_check_ratio.csv}
source "$(dirname "$0")/interleaved.sh"
echo "build,run,load1_before,load1_after,benchmark,field,cpu_ms,elements,facets,critical_facets" > "$out"
BENCH_FLAGS=(--benchmark_filter='threads:1/' --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true)
on_run() {
  /usr/bin/python3 - "$5" "$1" "$2" "$3" "$4" >> "$out" <<'PY'
import json, sys
build, run, l0, l1 = sys.argv[2:6]
for x in (x for x in json.load(open(sys.argv[1]))["benchmarks"] if x.get("run_type") == "iteration"):
    name = x["run_name"].split("/")[0]
    field = x["run_name"].split("cold_mixed_hot:")[1].split("/")[0] if "cold_mixed_hot" in x["run_name"] else ""
    field = {"0": "cold", "1": "mixed", "2": "hot"}.get(field, "")
    # elements per iteration (items; real time in ms: older builds have no "elements" counter)
    elements = x.get("elements") or x["items_per_second"] * x["real_time"] * 1e-3
    print(f'{build},{run},{l0},{l1},{name},{field},{x["cpu_time"]:.4f},{round(elements)},'
          f'{int(x.get("facets", 0))},{int(x.get("critical_facets", 0))}')
PY
}
interleaved "$runs" bench_fracture "$@"
/usr/bin/python3 - "$out" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
for build in dict.fromkeys(r["build"] for r in rows):
    mine = [r for r in rows if r["build"] == build]
    loads = [float(r["load1_before"]) for r in mine] + [float(r["load1_after"]) for r in mine]
    update = statistics.median(float(r["cpu_ms"]) for r in mine if r["benchmark"] == "BM_ElementUpdate")
    elements = int(mine[0]["elements"])
    print(f"{build}: element update {update:.3f} ms = {1e6 * update / elements:.1f} ns per element "
          f"(load {min(loads):.1f}-{max(loads):.1f})")
    for field in ("cold", "mixed", "hot"):
        sel = [r for r in mine if r["field"] == field]
        check = statistics.median(float(r["cpu_ms"]) for r in sel)
        facets = int(sel[0]["facets"])
        per_facet, per_element = 1e6 * check / facets, 1e6 * update / elements
        print(f"  {field:5s} check {check:.3f} ms ({sel[0]['critical_facets']} critical): check / update "
              f"{100 * check / update:.1f} %, {per_facet:.2f} ns per facet / {per_element:.1f} ns per element "
              f"= {100 * per_facet / per_element:.1f} %")
PY
