#!/bin/bash
# MPI scaling of the decomposed time loop (issue 6, docs/performance.md "MPI"):
# two unit boxes (the seeds' cube material) meet head-on, a contact scene.
#
#   bench/mpi_scaling.sh BUILD strong [ELEMENTS] [REPEATS]
#       ranks x threads = 1x1, 1x2, 2x1 on ELEMENTS tets (default 500000),
#       REPEATS runs each (default 5), interleaved; medians of the loop wall time.
#   SCENE=FILE bench/mpi_scaling.sh BUILD strong 0 [REPEATS]
#       the same on the scene FILE as it is (e.g. scenes/cubes76.yaml).
#   [FIRST=R0] [SET=key=value] bench/mpi_scaling.sh BUILD weak [PER_RANK] [MAX_RANKS]
#       R = R0 (default 1), 2 R0, 4 R0, ... MAX_RANKS (default 64, oversubscribed) with PER_RANK
#       tets per rank (default 2000), to 2e-4 s (the boxes meet after 5e-5 s):
#       balance of elements and contact pairs and bytes per rank per step from
#       summary.json; of the times, only the contact's thread CPU times per
#       step (the largest rank's) mean something when oversubscribed. SET adds one
#       --set to every run (e.g. SET=contact.self=false), and results go to
#       mpi_scaling_weak_<key>.csv.
#   bench/mpi_scaling.sh BUILD memory [ELEMENTS] [MAX_RANKS]
#       one box of ELEMENTS tets (default 2000000) on R = 1, 2, 4, ... MAX_RANKS
#       (default 8) ranks, 20 steps: each rank's peak memory and the bytes of
#       the arrays a rank holds in the loop (summary.json), against one rank.
#   bench/mpi_scaling.sh BUILD capacity [ELEMENTS] [RANKS]
#       the two boxes with contact, ELEMENTS tets in all (default 4000000) on
#       RANKS ranks (default 16, oversubscribed), 50 steps of 2e-6 s (they meet
#       after 5e-5 s): each rank's peak memory, their sum, and the contacts.
#   [FIRST=R0 | RANKS="R ..."] [SHAPE=cube|bar] bench/mpi_scaling.sh BUILD fracture [PER_RANK] [MAX_RANKS]
#       weak scaling with fracture (issue 15): an aluminium block (the ring's
#       material) under a uniform expansion of 2e4 /s cracks everywhere (a hot
#       field; no contact, so the ranks hold parts with two ghost layers). The
#       block grows with the ranks at a fixed element size (1e-4 m), about
#       PER_RANK tets per rank (default 20000), R = R0 (default 1), 2 R0, ...
#       MAX_RANKS (default 64, oversubscribed), to 1e-7 s: per rank peak memory
#       and model bytes, ghost bytes and messages per step, and the largest
#       rank's facet check and insertion thread CPU time per step.
#       SHAPE=bar: the block grows along x only (R s x s x s), at a fixed
#       square cross-section of side s with s^3 = the volume of PER_RANK tets
#       (1.6e-3 m at 20000), so that METIS cuts it into R slabs across its
#       length: every part but the two ends shares two faces (two ghost
#       messages) at any rank count, which the cube (corners at 8 ranks,
#       interiors at 64) does not. (Slabs of s x s x s/2 were too thin: their
#       wavy cuts gave 5 messages at 8 ranks.) Results go to
#       mpi_scaling_fracture_bar.csv. RANKS="8 64" runs those counts only.
#
# Results: bench/results/mpi_scaling_<mode>.csv
set -euo pipefail
build=${1:?usage: mpi_scaling.sh BUILD strong|weak|memory ...}
mode=${2:?strong, weak, memory, capacity or fracture}
here=$(cd "$(dirname "$0")" && pwd)
shatter="$build/apps/shatter"
# Binding (strong runs): a rank of one thread is bound to a core (--bind-to core):
# left free, the single thread of a 1 x 1 run wanders between this VM's two vCPUs
# and its element loop took 10-12.7 s instead of 10.1 s (measured). A rank of
# several threads is not bound (--bind-to none), or all its threads would share
# one core (1.05x). The weak runs are oversubscribed and not bound.
mpi=(mpirun --allow-run-as-root --oversubscribe)
bind() { if [ "$1" -gt 1 ]; then echo none; else echo core; fi; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$here/results"

scene="$work/boxes.yaml"
cat > "$scene" <<'YAML'
name: mpi_boxes
time:
  end: 6.0e-4
output:
  every: 0
  history_every: 10
materials:
  seed: {model: neo_hookean, density: 0.0785, youngs_modulus: 21000, poisson_ratio: 0.3}
contact: {}
bodies:
  - name: left
    material: seed
    mesh: {shape: box, size: [1.0, 1.0, 1.0], center: [-0.501, 0.0, 0.0], element_size: 0.1}
    initial_velocity: [20.0, 0.0, 0.0]
  - name: right
    material: seed
    mesh: {shape: box, size: [1.0, 1.0, 1.0], center: [0.501, 0.1, 0.0], element_size: 0.1}
    initial_velocity: [-20.0, 0.0, 0.0]
YAML
# Element size for a target count: 9798 tets at h = 0.1, count ~ h^-2.93 (measured up to
# ~0.5 M; at 2-4 M asked, Gmsh gives about half: 4 000 000 asked -> 2 111 501 tets).
size_for() { python3 -c "print(f'{0.1 * (9798 / $1) ** (1 / 2.93):.5f}')"; }
key() { grep -o "\"$2\": [-0-9.e+]*" "$1/summary.json" | awk '{print $2}'; }
# A summary.json key of bytes, in MB.
mb() { key "$1" "$2" | awk '{printf "%.0f", $1 / 1e6}'; }
# peak_memory_bytes_per_rank of a run as MB: rank 0's, the largest other's, the sum.
peaks() {
  local p
  p=$(grep -o '"peak_memory_bytes_per_rank": \[[^]]*\]' "$1/summary.json" | sed 's/.*\[//; s/\]//' | tr ',' '\n')
  echo "$(echo "$p" | awk 'NR == 1 {printf "%.0f", $1 / 1e6}'),$(echo "$p" | awk 'NR > 1 && $1 > m {m = $1} END {printf "%.0f", m / 1e6}'),$(echo "$p" | awk '{s += $1} END {printf "%.0f", s / 1e6}')"
}

# Steps, searches, re-partitions, the largest rank's contact bytes per step and
# contact CPU ms per step (searches, DCR) of a run.
contact() {
  local steps
  steps=$(key "$1" steps)
  echo "$steps,$(key "$1" contact_searches),$(key "$1" contact_repartitions),$(key "$1" contact_state_bytes_per_step_max),$(key "$1" contact_found_bytes_per_step_max),$(key "$1" contact_search_cpu_time_max | awk -v n="$steps" '{printf "%.4f", 1e3 * $1 / n}'),$(key "$1" contact_dcr_cpu_time_max | awk -v n="$steps" '{printf "%.4f", 1e3 * $1 / n}')"
}

if [ "$mode" = strong ]; then
  elements=${3:-500000}
  repeats=${4:-5}
  sizes=()
  out="$here/results/mpi_scaling_strong.csv"
  if [ -n "${SCENE:-}" ]; then
    scene=$SCENE
    out="$here/results/mpi_scaling_strong_$(basename "$SCENE" .yaml).csv"
  else
    h=$(size_for "$elements")
    sizes=(--set "bodies[0].mesh.element_size=$h" --set "bodies[1].mesh.element_size=$h")
  fi
  echo "ranks,threads,elements,steps,wall_median,wall_min,wall_max,element_loop,contact_search,contact_dcr,communication" > "$out"
  # The runs are interleaved (1x1, 1x2, 2x1, 1x1, ...) so that a slow spell of a
  # shared machine falls on every configuration alike, not on one.
  configs=("1 1" "1 2" "2 1")
  declare -A runs  # per configuration, one "wall_time run_dir" line per run
  for k in $(seq 1 "$repeats"); do
    for rt in "${configs[@]}"; do
      set -- $rt
      dir="$work/r$1t$2_$k"
      "${mpi[@]}" --bind-to "$(bind "$2")" -n "$1" "$shatter" run "$scene" --out "$dir" --threads "$2" --quiet \
        "${sizes[@]}"
      wall=$(key "$dir" wall_time)
      runs[$1x$2]+="$wall $dir"$'\n'
      echo "run $k: ${1}x$2 $wall s (load $(cut -d' ' -f1 /proc/loadavg))" >&2
    done
  done
  for rt in "${configs[@]}"; do
    set -- $rt
    # Median, min and max wall time; the median run gives the split of its step.
    read -r median dir lo hi <<< "$(printf '%s' "${runs[$1x$2]}" | sort -g |
      awk '{w[NR] = $1; d[NR] = $2} END {m = int((NR + 1) / 2); print w[m], d[m], w[1], w[NR]}')"
    echo "$1,$2,$(key "$dir" elements),$(key "$dir" steps),$median,$lo,$hi,$(key "$dir" element_loop_time),$(key "$dir" contact_search_time),$(key "$dir" contact_dcr_time),$(key "$dir" communication_time)" | tee -a "$out"
  done
elif [ "$mode" = capacity ]; then
  elements=${3:-4000000}
  ranks=${4:-16}
  h=$(size_for $((elements / 2)))
  out="$here/results/mpi_scaling_capacity.csv"
  echo "ranks,elements,steps,max_contacts,wall_s,peak_rank0_MB,peak_others_max_MB,peak_sum_MB,model_bytes_per_rank_max_MB" > "$out"
  dir="$work/capacity"
  start=$(date +%s)
  "${mpi[@]}" --bind-to none -n "$ranks" "$shatter" run "$scene" --out "$dir" --threads 1 --quiet \
    --set "bodies[0].mesh.element_size=$h" --set "bodies[1].mesh.element_size=$h" \
    --set time.dt=2.0e-6 --set time.end=1.0e-4 --set output.history_every=1
  wall=$(( $(date +%s) - start ))
  col=$(head -1 "$dir/history.csv" | tr ',' '\n' | grep -n '^contacts$' | cut -d: -f1)
  contacts=$(tail -n +2 "$dir/history.csv" | cut -d, -f"$col" | sort -n | tail -1)
  echo "$ranks,$(key "$dir" elements),$(key "$dir" steps),$contacts,$wall,$(peaks "$dir"),$(mb "$dir" model_bytes_per_rank_max)" | tee -a "$out"
elif [ "$mode" = memory ]; then
  elements=${3:-2000000}
  max_ranks=${4:-8}
  h=$(size_for "$elements")
  out="$here/results/mpi_scaling_memory.csv"
  echo "ranks,elements,peak_rank0_MB,peak_others_max_MB,peak_sum_MB,model_bytes_per_rank_max_MB" > "$out"
  r=1
  while [ "$r" -le "$max_ranks" ]; do
    dir="$work/memory$r"
    # Twenty steps of the left box alone (the second body is dropped).
    "${mpi[@]}" --bind-to none -n "$r" "$shatter" run "$scene" --out "$dir" --threads 1 --quiet \
      --set "contact=null" --set "bodies=[{name: box, material: seed, mesh: {shape: box, size: [1.0, 1.0, 1.0], element_size: $h}, initial_velocity: [20.0, 0.0, 0.0]}]" \
      --set time.end=1.0e-9 --set time.dt=5.0e-11
    echo "$r,$(key "$dir" elements),$(peaks "$dir"),$(mb "$dir" model_bytes_per_rank_max)" | tee -a "$out"
    r=$((r * 2))
  done
elif [ "$mode" = fracture ]; then
  per_rank=${3:-20000}
  max_ranks=${4:-64}
  block="$here/fracture_block.yaml"
  shape=${SHAPE:-cube}
  case "$shape" in
    cube) out="$here/results/mpi_scaling_fracture.csv" ;;
    bar) out="$here/results/mpi_scaling_fracture_bar.csv" ;;
    *) echo "mpi_scaling.sh: SHAPE=$shape: expected cube or bar" >&2; exit 2 ;;
  esac
  echo "ranks,elements,owned_min,owned_max,local_max,ghost_bytes_max,ghost_messages_max,peak_rank0_MB,peak_others_max_MB,peak_sum_MB,model_bytes_per_rank_max_MB,steps,cohesive_elements,check_cpu_ms_per_step_max,insert_cpu_ms_per_step_max" > "$out"
  ranks=${RANKS:-$(r=${FIRST:-1}; while [ "$r" -le "$max_ranks" ]; do echo "$r"; r=$((r * 2)); done)}
  for r in $ranks; do
    # 10 561 tets for a side of 1.3e-3 m at this element size.
    size=$(python3 -c "
v = 1.3e-3 ** 3 * $per_rank / 10561  # one rank's volume
if '$shape' == 'cube':
    side = ($r * v) ** (1 / 3)
    print(f'{side:.6e}, {side:.6e}, {side:.6e}')
else:
    s = v ** (1 / 3)
    print(f'{$r * s:.6e}, {s:.6e}, {s:.6e}')")
    dir="$work/fracture$r"
    "${mpi[@]}" --bind-to none -n "$r" "$shatter" run "$block" --out "$dir" --threads 1 --quiet \
      --set "bodies[0].mesh.size=[$size]" 2> /dev/null
    steps=$(key "$dir" steps)
    per_step() { key "$dir" "$1" | awk -v n="$steps" '{printf "%.3f", 1e3 * $1 / n}'; }
    echo "$r,$(key "$dir" elements),$(key "$dir" owned_elements_min),$(key "$dir" owned_elements_max),$(key "$dir" local_elements_max),$(key "$dir" ghost_bytes_per_step_max),$(key "$dir" ghost_messages_per_step_max),$(peaks "$dir"),$(mb "$dir" model_bytes_per_rank_max),$steps,$(key "$dir" cohesive_elements),$(per_step fracture_check_cpu_time_max),$(per_step fracture_insert_cpu_time_max)" | tee -a "$out"
  done
else
  per_rank=${3:-2000}
  max_ranks=${4:-64}
  out="$here/results/mpi_scaling_weak${SET:+_${SET%%=*}}.csv"
  extra=(); [ -n "${SET:-}" ] && extra=(--set "$SET")
  echo "ranks,elements,owned_min,owned_max,local_max,ghost_bytes_max,ghost_messages_max,shared_surface_bytes,reduction_bytes,contact_pairs_min,contact_pairs_max,contact_gather_bytes,peak_rank0_MB,peak_others_max_MB,peak_sum_MB,model_bytes_per_rank_max_MB,steps,contact_searches,contact_repartitions,contact_state_bytes_max,contact_found_bytes_max,contact_search_cpu_ms_per_step_max,contact_dcr_cpu_ms_per_step_max,contact_whole_surface_kB,contact_patch_vertices_max,contact_surface_triangles" > "$out"
  r=${FIRST:-1}
  while [ "$r" -le "$max_ranks" ]; do
    h=$(size_for $((per_rank * r)))
    dir="$work/weak$r"
    "${mpi[@]}" --bind-to none -n "$r" "$shatter" run "$scene" --out "$dir" --threads 1 --quiet --set time.end=2.0e-4 \
      --set "bodies[0].mesh.element_size=$h" --set "bodies[1].mesh.element_size=$h" "${extra[@]}"
    echo "$r,$(key "$dir" elements),$(key "$dir" owned_elements_min),$(key "$dir" owned_elements_max),$(key "$dir" local_elements_max),$(key "$dir" ghost_bytes_per_step_max),$(key "$dir" ghost_messages_per_step_max),$(key "$dir" shared_surface_bytes_per_step),$(key "$dir" reduction_bytes_per_step),$(key "$dir" contact_pairs_per_step_rank_min),$(key "$dir" contact_pairs_per_step_rank_max),$(key "$dir" contact_exchange_bytes_per_step),$(peaks "$dir"),$(mb "$dir" model_bytes_per_rank_max),$(contact "$dir"),$(key "$dir" contact_whole_surface_bytes_max | awk '{printf "%.0f", $1 / 1e3}'),$(key "$dir" contact_patch_vertices_max),$(key "$dir" contact_surface_triangles)" | tee -a "$out"
    r=$((r * 2))
  done
fi
