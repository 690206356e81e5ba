# interleaved.sh — sourced by the ratio scripts (simd_ratio.sh,
# facet_check_ratio.sh): runs one Google Benchmark binary of several builds,
# processes interleaved A B C A B C ... so that a change of the machine's
# load falls on every build alike, each run's /proc/loadavg recorded.
#
# interleaved RUNS BINARY BUILD...
#   runs BUILD/bench/BINARY "${BENCH_FLAGS[@]}" RUNS times per build, its
#   JSON to a temporary file, and after each run calls the caller's
#     on_run BUILD RUN LOAD1_BEFORE LOAD1_AFTER JSON_FILE
#   The benchmark's stderr (its context) is shown only if it fails.
interleaved() {
  local runs=$1 binary=$2
  shift 2
  local tmp r build load0 load1
  tmp=$(mktemp -d)
  for r in $(seq 1 "$runs"); do
    for build in "$@"; do
      load0=$(cut -d' ' -f1 /proc/loadavg)
      if ! "$build/bench/$binary" "${BENCH_FLAGS[@]}" --benchmark_out="$tmp/run.json" \
          --benchmark_out_format=json > /dev/null 2> "$tmp/stderr"; then
        cat "$tmp/stderr" >&2
        rm -rf "$tmp"
        return 1
      fi
      load1=$(cut -d' ' -f1 /proc/loadavg)
      on_run "$build" "$r" "$load0" "$load1" "$tmp/run.json"
    done
  done
  rm -rf "$tmp"
}
