#!/bin/bash
# The seeds' headline run at its size (issue 22, done-when 3;
# docs/performance.md "The headline two disks"): scenes/two_disks.yaml meshed
# at ELEMENT_SIZE (0.0111: ~5.2 M TET4, the seeds' 5.2 M), with the disks
# started GAP_X closer along x than the scene's (default 0.28: contact from
# ~0.4 ms instead of ~6 ms, so that the ~4 000 steps of time.end = 0.0035 s
# cover the first quarter of the impact; the step of this mesh is 8.7e-7 s),
# fields and checkpoints off.
#   1. `shatter partition` cuts it once for 2 ranks (Gmsh's Delaunay, one
#      process: the meshing and partition time);
#   2. 2x1: two ranks of one thread read their parts (`run --parts`);
#   3. 1x2 (unless ONLY_2X1=1): one rank of two threads meshes the scene itself.
# Per run, from summary.json: steps, loop wall time and its split (element
# loop, contact search, DCR, communication), the energy error, the peak memory
# per rank; rows in bench/results/two_disks_headline.csv. Needs ~2 GB per rank
# and ~1 GB of disk for the part files.
#
#   bench/two_disks_headline.sh BUILD [ELEMENT_SIZE] [WORK_DIR]
#   ONLY_PARTITION=1 ...: write the part files and stop; ONLY_2X1=1: skip the 1x2 run.
set -euo pipefail
build=${1:?usage: two_disks_headline.sh BUILD [ELEMENT_SIZE] [WORK_DIR]}
size=${2:-0.0111}
work=${3:-$(mktemp -d)}
gap=${GAP_X:-0.28}
here=$(cd "$(dirname "$0")" && pwd)
scene="$here/../scenes/two_disks.yaml"
shatter="$build/apps/shatter"
half=$(python3 -c "print(f'{1.1 - $gap / 2:g}')")
sets=(--set "bodies[0].mesh.element_size=$size" --set "bodies[1].mesh.element_size=$size"
      --set "bodies[0].mesh.center=[-$half, -0.3, 0.0]" --set "bodies[1].mesh.center=[$half, 0.3, 0.0]"
      --set time.end=${END:-0.0035} --set output.every=0 --set output.history_every=100)
mkdir -p "$work"
out="$here/results/two_disks_headline.csv"
[ -f "$out" ] || echo "date,commit,config,element_size,elements,steps,partition_wall_s,mesh_s,loop_wall_s,element_s,search_s,dcr_s,communication_s,energy_error,peak_rank_max_mb,load1" > "$out"
commit=$(git -C "$here" rev-parse --short HEAD)

row() {  # config, partition seconds, folder
  python3 - "$1" "$2" "$3/summary.json" "$size" "$commit" "$out" <<'EOF'
import json, os, sys, datetime
config, part_s, path, size, commit, out = sys.argv[1:]
s = json.load(open(path))
peak = max(s.get("peak_memory_bytes_per_rank", [s["peak_memory_bytes"]])) / 2**20
fields = [datetime.date.today().isoformat(), commit, config, size, s["elements"], s["steps"], part_s,
          f'{s.get("mesh_time", 0):.1f}', f'{s["wall_time"]:.1f}', f'{s["element_loop_time"]:.1f}',
          f'{s.get("contact_search_time", 0):.1f}', f'{s.get("contact_dcr_time", 0):.1f}',
          f'{s.get("communication_time", 0):.1f}', f'{s["energy_error"]:.3e}', f'{peak:.0f}',
          f'{os.getloadavg()[0]:.1f}']
open(out, "a").write(",".join(map(str, fields)) + "\n")
print(",".join(map(str, fields)))
EOF
}

# Part files already in WORK_DIR/parts (an earlier call with ONLY_PARTITION=1) are reused:
# the meshing can run on a busy machine and the loop on a quiet one.
part_s=earlier
if [ ! -d "$work/parts" ]; then
  start=$(date +%s.%N)
  # (The child's peak resident memory, by getrusage; its report goes to stderr.)
  peak=$(python3 -c "import resource, subprocess, sys; subprocess.run(sys.argv[1:], check=True, stdout=sys.stderr)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024)" \
    "$shatter" partition "$scene" --ranks 2 --out "$work/parts" "${sets[@]}")
  part_s=$(python3 -c "print(f'{$(date +%s.%N) - $start:.1f}')")
  echo "partition: $part_s s, peak $peak MB, load $(cut -d' ' -f1 /proc/loadavg)"
fi
[ "${ONLY_PARTITION:-0}" = 1 ] && exit 0
mpirun --allow-run-as-root --oversubscribe --bind-to core -n 2 "$shatter" run "$scene" --parts "$work/parts" \
  --out "$work/2x1" --threads 1 --quiet "${sets[@]}"
row 2x1 "$part_s" "$work/2x1"
rm -rf "$work/parts"
if [ "${ONLY_2X1:-0}" != 1 ]; then
  "$shatter" run "$scene" --out "$work/1x2" --threads 2 --quiet "${sets[@]}"
  row 1x2 0 "$work/1x2"
fi
