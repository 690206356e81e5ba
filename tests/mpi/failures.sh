#!/bin/bash
# A failure on any rank ends the run on every rank with one message (issue 6,
# docs/errors.md "On several ranks"), on 2 ranks:
#   - rank 1 alone fails inside the time loop (fail_alone: it throws before
#     step 5) while rank 0 goes on into the step's collectives: exit 1, one
#     error line;
#   - rank 0 alone fails (history.csv on a full disk: /dev/full) while rank 1
#     waits in the first ledger reduction: exit 1, one error line;
#   - every rank fails together (elements inverted by a step far above the
#     stable one): exit 1, one error line, the last good state checkpointed;
#   - every rank finds the stable step collapsed (a face driven at 300 m/s
#     crushes the box): exit 1, one error line, the same as on one rank (the
#     element with the smallest step over all ranks), a checkpoint;
#   - DCR reaches its sweep cap with contact.on_sweep_cap: fail (a block
#     dropped on a plate, one sweep a step): exit 1, one error line, the same
#     as on one rank (the first pair left over all ranks, named by its nodes'
#     ids and bodies though the part holds no row of some of them);
#   - bad input on every rank: exit 2, one error line;
#   - a mesh too small for the ranks (fewer granules of 256 elements than
#     ranks): exit 2, one error line that says how many ranks it can take;
#   - a shell too small for the ranks (fewer granules of 32 control vertices
#     than ranks): exit 2, one error line that says how many ranks it can take.
# A hang is caught by `timeout` (and ctest's TIMEOUT), 100 s a run times the
# sanitized build's SHATTER_TEST_TIMEOUT_SCALE (tests/CMakeLists.txt).
# usage: failures.sh SHATTER FAIL_ALONE MPIEXEC WORKDIR
set -uo pipefail
shatter=$1 fail_alone=$2 mpiexec=$3 work=$4
limit=$((100 * ${SHATTER_TEST_TIMEOUT_SCALE:-1}))
rm -rf "$work"
mkdir -p "$work"
cat > "$work/box.yaml" <<'YAML'
name: box
time: {end: 2.0e-5}
output: {every: 0, history_every: 5}
materials:
  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}
bodies:
  - name: b
    material: steel
    mesh: {shape: box, size: [0.02, 0.01, 0.01], element_size: 0.002}
    initial_velocity: [1, 0, 0]
    angular_velocity: [0, 0, 300]
YAML
fail=0
# run NAME STATUS MESSAGE [env and arguments]: runs shatter on 2 ranks, checks
# the exit status and that exactly one line starts with "error: ", that line
# containing MESSAGE.
run() {
  local name=$1 want=$2 message=$3
  shift 3
  timeout -k 10 "$limit" env "$@" > "$work/$name.log" 2>&1
  local status=$?
  local errors
  errors=$(grep -c '^error: ' "$work/$name.log")
  if [ "$status" -ne "$want" ] || [ "$errors" -ne 1 ] || ! grep '^error: ' "$work/$name.log" | grep -qF -- "$message"; then
    echo "FAIL $name: exit $status (expected $want), $errors error lines (expected 1 with '$message'):"
    cat "$work/$name.log"
    fail=1
  else
    echo "ok $name: exit $status, one message: $(grep '^error: ' "$work/$name.log")"
  fi
}
mpi=("$mpiexec" --allow-run-as-root --oversubscribe -n 2 "$shatter" run "$work/box.yaml" --threads 1 --quiet)

run lone_rank1 1 "error: step 5: failure injected on rank 1 by the test" \
  "$mpiexec" --allow-run-as-root --oversubscribe -n 2 "$fail_alone" "$work/box.yaml" "$work/lone_rank1" 1 5
grep -q "rank 1 of 2 failed alone" "$work/lone_rank1.log" || { echo "FAIL lone_rank1: no note of the lone failure"; fail=1; }

mkdir -p "$work/full"
ln -s /dev/full "$work/full/history.csv"
run lone_rank0 1 "history.csv" "${mpi[@]}" --out "$work/full"
grep -q "rank 0 of 2 failed alone" "$work/lone_rank0.log" || { echo "FAIL lone_rank0: no note of the lone failure"; fail=1; }

run collective 1 "is inverted" "${mpi[@]}" --out "$work/collective" --set time.dt=2.0e-6 --set time.end=1.0e-3
grep -q "the last good state (step " "$work/collective.log" && [ -f "$work/collective/checkpoint.h5" ] ||
  { echo "FAIL collective: no checkpoint of the last good state"; fail=1; }

crush=(--set time.end=1.0e-4 --set "bodies[0].mesh.size=[0.01, 0.01, 0.01]" --set "bodies[0].angular_velocity=[0, 0, 0]"
  --set "boundary_conditions=[{body: b, region: {box: [[-1, -1, -1], [-0.0049, 1, 1]]}, velocity: [300, null, null]}, {body: b, region: {box: [[0.0049, -1, -1], [1, 1, 1]]}, velocity: [0, null, null]}]")
run collapse 1 "the stable step collapsed" "${mpi[@]}" --out "$work/collapse" "${crush[@]}"
timeout -k 10 "$limit" "$shatter" run "$work/box.yaml" --threads 1 --quiet --out "$work/collapse1" "${crush[@]}" > "$work/collapse1.log" 2>&1
[ "$(grep '^error: ' "$work/collapse.log")" = "$(grep '^error: ' "$work/collapse1.log")" ] && [ -f "$work/collapse/checkpoint.h5" ] ||
  { echo "FAIL collapse: not the message of one rank, or no checkpoint:"; cat "$work/collapse1.log"; fail=1; }

cat > "$work/drop.yaml" <<'YAML'
name: drop
time: {end: 2.0e-5}
output: {every: 0}
materials:
  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}
bodies:
  - {name: plate, material: steel, mesh: {shape: box, size: [0.06, 0.03, 0.01], center: [0, 0, -0.005], element_size: 0.003}}
  - {name: block, material: steel, mesh: {shape: box, size: [0.01, 0.01, 0.01], center: [0, 0, 0.005001], element_size: 0.003},
     initial_velocity: [5, 0, -5]}
boundary_conditions:
  - {body: plate, region: {box: [[-1, -1, -1], [1, 1, -0.00999]]}, velocity: [0, 0, 0]}
contact: {restitution: 0.5, max_sweeps: 1, on_sweep_cap: fail}
YAML
run sweep_cap 1 "DCR sweeps reached the cap" "$mpiexec" --allow-run-as-root --oversubscribe -n 2 "$shatter" run \
  "$work/drop.yaml" --threads 1 --quiet --out "$work/sweep_cap"
timeout -k 10 "$limit" "$shatter" run "$work/drop.yaml" --threads 1 --quiet --out "$work/sweep_cap1" > "$work/sweep_cap1.log" 2>&1
[ "$(grep '^error: ' "$work/sweep_cap.log")" = "$(grep '^error: ' "$work/sweep_cap1.log")" ] &&
  grep -q "still penetrating: [a-z-]* pair of nodes [0-9]* (.[a-z]*.) [0-9]* (.[a-z]*.) [0-9]* (.[a-z]*.) [0-9]* (.[a-z]*.) near" "$work/sweep_cap.log" ||
  { echo "FAIL sweep_cap: not the message of one rank, or no pair named:"; cat "$work/sweep_cap1.log"; fail=1; }

run bad_input 2 "time.end: expected a positive number, got 'soon'" "${mpi[@]}" --out "$work/bad" --set time.end=soon
run too_many_ranks 2 "cannot be shared by 2 MPI ranks (use at most 1)" "${mpi[@]}" --out "$work/small" \
  --set bodies[0].mesh.element_size=0.005
run too_many_ranks_shell 2 "granule of 32; they cannot be shared by 2 MPI ranks (use at most 1)" "${mpi[@]}" --out "$work/shell" \
  --set "bodies[0].shell={thickness: 0.001}" --set "bodies[0].mesh={shape: sphere, radius: 0.1, element_size: 0.1}" \
  --set "bodies[0].angular_velocity=[0, 0, 0]"
exit $fail
