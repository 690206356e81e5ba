#!/usr/bin/env bash
# run_all.sh — the `make bench` entry: runs every Google Benchmark binary in
# a build directory (builds nothing), with repetitions, and writes
#   bench/results/<name>.json   Google Benchmark JSON (aggregates: mean, median, stddev, cv)
#   bench/results/<name>.csv    one row per aggregate: name, aggregate, real/cpu time, counters
#   bench/results/<name>.png    a plot, when /usr/bin/python3 has matplotlib
#
# Usage: bash bench/run_all.sh BUILD_DIR [extra benchmark flags...]
#   REPS=5 (repetitions), FILTER=regex (passed as --benchmark_filter)
# Expect: several minutes (bench_kernels meshes a 300k-tet box with Gmsh first).
set -euo pipefail
build=${1:?usage: run_all.sh BUILD_DIR [benchmark flags...]}
shift
here=$(cd "$(dirname "$0")" && pwd)
out="$here/results"
mkdir -p "$out"
reps=${REPS:-5}
filter=${FILTER:-.}

mapfile -t bins < <(find "$build/bench" -maxdepth 2 -type f -executable -name 'bench_*' | sort)
if [ ${#bins[@]} -eq 0 ]; then
  echo "run_all.sh: no bench_* executables under $build/bench (build first)" >&2
  exit 1
fi
lscpu > "$out/machine.txt" 2>/dev/null || true
status=0
for bin in "${bins[@]}"; do
  name=$(basename "$bin")
  echo "== $name"
  if ! "$bin" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
      --benchmark_filter="$filter" --benchmark_out="$out/$name.json" --benchmark_out_format=json "$@"; then
    echo "run_all.sh: $name failed" >&2
    status=1
    continue
  fi
  /usr/bin/python3 - "$out/$name.json" "$out/$name.csv" "$out/$name.png" <<'PY' || status=1
import csv, json, sys
src, csv_path, png_path = sys.argv[1:4]
runs = json.load(open(src))["benchmarks"]
fixed = {"name", "run_name", "run_type", "aggregate_name", "aggregate_unit", "family_index",
         "per_family_instance_index", "repetitions", "repetition_index", "threads", "iterations",
         "real_time", "cpu_time", "time_unit", "error_occurred", "error_message"}
counters = sorted({k for r in runs for k in r if k not in fixed})
with open(csv_path, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["run_name", "aggregate", "real_time", "cpu_time", "time_unit"] + counters)
    for r in runs:
        w.writerow([r.get("run_name", r["name"]), r.get("aggregate_name", ""), r.get("real_time"),
                    r.get("cpu_time"), r.get("time_unit")] + [r.get(k, "") for k in counters])
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("run_all.sh: no matplotlib, skipping", png_path)
    sys.exit(0)
med = [r for r in runs if r.get("aggregate_name") == "median"]
key = "Melem_per_core" if any("Melem_per_core" in r for r in med) else "items_per_second"
rows = [r for r in med if key in r]
if not rows:
    sys.exit(0)
labels = [r["run_name"].replace("BM_", "").replace("/real_time", "") for r in rows]
vals = [r[key] for r in rows]
fig, ax = plt.subplots(figsize=(9, 0.32 * len(rows) + 1.2))
bars = ax.barh(range(len(rows)), vals, color=["C1" if "threads:2" in l else "C0" for l in labels])
ax.set_yticks(range(len(rows)), labels, fontsize=7)
ax.invert_yaxis()
ax.set_xlabel(key + " (median)")
for b, r in zip(bars, rows):
    if r.get("bw_frac"):
        ax.text(b.get_width(), b.get_y() + b.get_height() / 2, f" {100 * r['bw_frac']:.0f}% bw",
                va="center", fontsize=6)
ax.set_title(src.split("/")[-1].replace(".json", ""))
fig.tight_layout()
fig.savefig(png_path, dpi=110)
print("wrote", png_path)
PY
done
exit $status
