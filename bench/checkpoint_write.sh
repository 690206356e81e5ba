#!/bin/bash
# Checkpoint write and restart read on several ranks (issue 15, docs/performance.md
# "Checkpoints on ranks"): bench/block_step.yaml's TET4 block (element size
# H, default 0.0027: 247 601 tets) for STEPS steps (default 25) with a checkpoint
# every STEPS/2 steps (time.end assumes dt = 1.3e-7 s x H / 0.0027), on each rank count of RANKS (default "2 4"); then a restart
# from that checkpoint to one step past it. Prints, per rank count: every rank's
# peak memory (summary.json), checkpoint_time, and the restart's peak memory per
# rank and wall time (mesh, partition, read and one step).
#   bench/checkpoint_write.sh BUILD [H] [STEPS] [RANKS]
set -euo pipefail
build=${1:?usage: checkpoint_write.sh BUILD [H] [STEPS] [RANKS]}
h=${2:-0.0027} steps=${3:-25} ranks=${4:-2 4}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
shatter=$build/apps/shatter
mpi=(mpirun --allow-run-as-root --oversubscribe)
key() { grep -o "\"$1\": [^,}]*" "$2" | head -1 | sed 's/.*: //'; }
for r in $ranks; do
  out=$work/r$r
  "${mpi[@]}" -n "$r" "$shatter" run "$here/block_step.yaml" --out "$out" --threads 1 --quiet \
    --set "bodies[0].mesh.element_size=$h" --set "checkpoint.every_steps=$((steps / 2))" \
    --set "time.end=$(/usr/bin/python3 -c "print($steps * 1.3e-7 * $h / 0.0027)")"
  t=$(/usr/bin/python3 -c "import h5py; print(h5py.File('$out/checkpoint.h5', 'r').attrs['time'])")
  end=$(/usr/bin/python3 -c "print($t * 1.0000001 + 1e-10)")
  t0=$(date +%s.%N)
  "${mpi[@]}" -n "$r" "$shatter" run "$here/block_step.yaml" --restart "$out/checkpoint.h5" --threads 1 --quiet \
    --set "bodies[0].mesh.element_size=$h" --set "time.end=$end" --out "$out.restart" 2>/dev/null || true
  t1=$(date +%s.%N)
  echo "ranks $r: steps $(key steps "$out/summary.json"), checkpoint at t = $t s"
  grep -o '"peak_memory_bytes_per_rank": \[[^]]*\]' "$out/summary.json"
  echo "  checkpoint_time $(key checkpoint_time "$out/summary.json") s, wall_time $(key wall_time "$out/summary.json") s"
  grep -o '"peak_memory_bytes_per_rank": \[[^]]*\]' "$out.restart/summary.json" 2>/dev/null | sed 's/^/  restart: /' || true
  echo "  restart wall $(/usr/bin/python3 -c "print(round($t1 - $t0, 2))") s"
done
rm -rf "$work"
