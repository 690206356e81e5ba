#!/bin/bash
# Checkpoints written collectively (issue 15: each rank writes its own rows,
# runtime/checkpoint.hpp): the same run's checkpoint on 1, 2, 3 and 4 ranks is
# the same file content, every dataset bit for bit and every attribute (the
# datasets' hashes, summed from the ranks' rows, included). Then one number of
# DATASET (a row that one rank of 3 reads and hashes, the others not) changed in
# the 4-rank file: a restart on 3 ranks refuses it, exit 2, naming the dataset.
# usage: same_checkpoint.sh SHATTER MPIEXEC SCENE WORKDIR EVERY_STEPS DATASET
set -uo pipefail
shatter=$1 mpiexec=$2 scene=$3 work=$4 every=$5 spoil=$6
here=$(dirname "$0")
mpi=("$mpiexec" --allow-run-as-root --oversubscribe)
rm -rf "$work"
mkdir -p "$work"
for n in 1 2 3 4; do
  "${mpi[@]}" -n $n "$shatter" run "$scene" --out "$work/r$n" --threads 1 --quiet \
    --set checkpoint.every_steps="$every" || { echo "FAIL: the run on $n ranks"; exit 1; }
  [ -f "$work/r$n/checkpoint.h5" ] || { echo "FAIL: no checkpoint on $n ranks"; exit 1; }
done
# The comparison covers a state worth comparing: version 7, steps taken, and
# with fracture, cohesive elements in it.
/usr/bin/python3 - "$work/r1/checkpoint.h5" <<'PY' || exit 1
import sys, h5py
f = h5py.File(sys.argv[1], "r")
assert f.attrs["version"] == 7, f.attrs["version"]
assert f.attrs["step"] > 0
if "fracture" in f:
    assert f["fracture"].attrs["cohesive_elements"] > 0, "no crack at the checkpoint"
print(f"checkpoint at step {f.attrs['step']}")
PY
for n in 2 3 4; do
  /usr/bin/python3 "$here/same_h5.py" "$work/r1/checkpoint.h5" "$work/r$n/checkpoint.h5" ||
    { echo "FAIL: the checkpoint of $n ranks differs from that of 1 rank"; exit 1; }
done
cp "$work/r4/checkpoint.h5" "$work/spoiled.h5"
/usr/bin/python3 -c "import h5py; f = h5py.File('$work/spoiled.h5', 'r+'); d = f['$spoil']; d[d.shape[0] - 1, 0] += 1; f.close()"
"${mpi[@]}" -n 3 "$shatter" run "$scene" --restart "$work/spoiled.h5" --out "$work/spoiled" --threads 1 --quiet \
  2> "$work/spoiled.log"
status=$?
name=${spoil##*/}
[ $status -eq 2 ] && grep -q "dataset $name fails its hash check" "$work/spoiled.log" ||
  { echo "FAIL: a changed $spoil was not refused (exit $status):"; cat "$work/spoiled.log"; exit 1; }
echo "checkpoints of 1, 2, 3 and 4 ranks equal; a changed $spoil refused on 3 ranks"
