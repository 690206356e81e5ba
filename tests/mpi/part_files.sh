#!/bin/bash
# Part files (docs/parallel.md "Part files", issue 15): `shatter partition SCENE
# --ranks R` writes one file per rank, and `mpirun -np R shatter run SCENE
# --parts DIR` reads on each rank its own part and meshes nothing. Checks:
#   - the outputs (history.csv, bodies.csv, fragments.csv) are byte-equal to
#     the 1-rank run's, for a scene without contact or fracture at 2 and 3
#     ranks, a contact scene, a fragmenting one and a fragmenting one with
#     contact (cracks in contact on parts) at 3, and a run stopped
#     half way and restarted from its checkpoint, both from part files;
#   - no rank holds the whole model at start-up: with parts the start-up
#     rank peaks within 1.15x of the other ranks (without parts, where it
#     meshes and cuts the whole model, it does not: checked too, so that
#     the comparison can tell the two apart);
#   - bad part folders exit 2 with a message naming the file: another rank
#     count, a changed physics key (named), a flipped byte, a truncated file.
# usage: part_files.sh SHATTER MPIEXEC SCENES_DIR WORKDIR
set -euo pipefail
shatter=$1 mpiexec=$2 scenes=$3 work=$4
rm -rf "$work"
mkdir -p "$work"
cd "$work"
status=0
fail() { echo "FAIL: $*"; status=1; }
mpi() { "$mpiexec" -n "$1" --allow-run-as-root --oversubscribe "$shatter" "${@:2}"; }
peaks() { /usr/bin/python3 -c "import json,sys; print(*json.load(open(sys.argv[1]))['peak_memory_bytes_per_rank'])" "$1"; }

same_as_one_rank() {  # scene ranks files...
  local scene=$1 ranks=$2 name
  name=$(basename "$scene" .yaml)
  shift 2
  "$shatter" partition "$scene" --ranks "$ranks" --out "parts_$name" > /dev/null
  [ -f "r1_$name/history.csv" ] || "$shatter" run "$scene" --out "r1_$name" --threads 1 --quiet
  mpi "$ranks" run "$scene" --parts "parts_$name" --out "p${ranks}_$name" --threads 1 --quiet
  for f in "$@"; do
    cmp -s "r1_$name/$f" "p${ranks}_$name/$f" || fail "$name at $ranks ranks from part files: $f differs from 1 rank's"
  done
}
same_as_one_rank "$scenes/pulled_bar.yaml" 2 history.csv bodies.csv
same_as_one_rank "$scenes/pulled_bar.yaml" 3 history.csv bodies.csv
same_as_one_rank "$scenes/five_cubes_friction.yaml" 3 history.csv bodies.csv
same_as_one_rank "$scenes/expanding_ring.yaml" 3 history.csv bodies.csv fragments.csv
same_as_one_rank "$scenes/expanding_ring_contact.yaml" 3 history.csv bodies.csv fragments.csv
# A restart from part files: stopped half way (a checkpoint at step 1000), continued.
mpi 3 run "$scenes/pulled_bar.yaml" --parts parts_pulled_bar --out restarted --threads 1 --quiet \
  --set time.end=3e-5 --set "checkpoint={every_steps: 1000}"
mpi 3 run "$scenes/pulled_bar.yaml" --parts parts_pulled_bar --restart restarted/checkpoint.h5 --threads 1 --quiet
for f in history.csv bodies.csv; do
  cmp -s r1_pulled_bar/$f restarted/$f || fail "pulled_bar restarted from part files: $f differs from 1 rank's"
done
grep -q '"contact_pairs_per_step_rank_min": [1-9]' p3_five_cubes_friction/summary.json ||
  fail "five_cubes_friction from part files: a rank of 3 resolved no contact pair (the comparison does not cover contact)"

# Memory at start-up: the pulled bar at 3 ranks, with and without parts.
mpi 3 run "$scenes/pulled_bar.yaml" --out meshed --threads 1 --quiet
ratio() { peaks "$1" | awk '{ m = $2 > $3 ? $2 : $3; printf "%.3f", $1 / m }'; }
with=$(ratio p3_pulled_bar/summary.json) without=$(ratio meshed/summary.json)
awk -v r="$with" 'BEGIN { exit !(r < 1.15) }' || fail "from part files rank 0 peaks at $with x the other ranks"
awk -v r="$without" 'BEGIN { exit !(r > 1.15) }' ||
  fail "meshing at start-up rank 0 peaks at only $without x the others: the memory check cannot tell parts apart"

# Bad part folders: exit 2, the file named.
refused() {  # expected-text command...
  local want=$1 out rc=0
  shift
  out=$("$@" 2>&1) || rc=$?
  [ $rc -eq 2 ] || fail "exit $rc, not 2: $*"
  grep -qF -- "$want" <<< "$out" || fail "no '$want' in: $out"
}
bar=$scenes/pulled_bar.yaml
refused "parts_pulled_bar/part-0-of-4.bin: no such part file (the folder holds parts for 2, 3 ranks)" \
  mpi 4 run "$bar" --parts parts_pulled_bar --out bad --quiet
refused "materials.steel.density is 7850 in the scene the parts were cut from and 7000 in" \
  mpi 2 run "$bar" --parts parts_pulled_bar --out bad --quiet --set materials.steel.density=7000
cp -r parts_pulled_bar flipped
printf '\x5a' | dd of=flipped/part-1-of-3.bin bs=1 seek=4000 conv=notrunc 2> /dev/null
refused "flipped/part-1-of-3.bin: fails its hash check" mpi 3 run "$bar" --parts flipped --out bad --quiet
cp -r parts_pulled_bar cut
truncate -s 50000 cut/part-2-of-3.bin
refused "cut/part-2-of-3.bin: fails its hash check" mpi 3 run "$bar" --parts cut --out bad --quiet
# A later format version, its hash made right (as a newer shatter would write it).
cp -r parts_pulled_bar newer
/usr/bin/python3 - newer/part-0-of-3.bin <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], 'rb').read()[:-8])
data[16:24] = struct.pack('<Q', 5)
h = 1469598103934665603
for b in data:
    h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
open(sys.argv[1], 'wb').write(bytes(data) + struct.pack('<Q', h))
PY
refused "newer/part-0-of-3.bin: is a part file of version 5; expected version 4" mpi 3 run "$bar" --parts newer --out bad --quiet
head -c 300 /dev/urandom > cut/part-0-of-3.bin
refused "cut/part-0-of-3.bin: is not a shatter part file" mpi 3 run "$bar" --parts cut --out bad --quiet
refused "part files are for runs on several ranks" "$shatter" run "$bar" --parts parts_pulled_bar --out bad --quiet
refused "shatter partition runs on one process" mpi 2 partition "$bar" --ranks 2 --out bad
[ $status -eq 0 ] && echo "part files: outputs byte-equal to 1 rank's; rank 0 peaks at $with x the others (meshing: $without x); bad folders refused"
exit $status
