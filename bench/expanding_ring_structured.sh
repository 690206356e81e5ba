#!/usr/bin/env bash
# expanding_ring_structured.sh — the expanding ring of bench/expanding_ring.sh
# (same material, law, rates, radii and cross-sections) on structured meshes
# whose radial planes are facets (bench/ring_mesh.py), against
# Zhou-Molinari-Ramesh (issue 19, done-when 2; docs/validation.md, "The ring
# on structured meshes").
#
# Why: on the unstructured Gmsh tube each through-crack debonds 1.2-1.7 a^2 of
# zigzag facets, not the cross-section a^2 of ZMR's 1D model. Here a crack can
# cross the ring on a radial plane, a^2 exactly. This is a mesh bias (cracks
# prefer the radial planes), legitimate for checking a 1D theory whose cracks
# are all radial, and not a model of real crack paths.
# Meshes: cubic cells of edge h = a / n (n = 2, 3, 4 cells across the
# cross-section, n_t = round(2 pi R / h) around), six tets per cell.
# A perfect structured ring is degenerate: every radial plane reaches the
# strength at the same step and every plane is inserted at once (measured:
# all of them within one history interval, then 0.48-0.55 x ZMR). So
# the main series has a small strength scatter, uniform +-5 %
# (scatter: {distribution: uniform, spread: 0.05}) to break the symmetry.
# The spread's effect is measured (+-2 %, +-10 %), so is the seed's (up to
# three seeds per mesh), and Weibull m = 8 (the distribution plot; on the
# coarse mesh at 1e3 /s, the middle one at 1e4 and 1e5 /s).
# Run:     bash bench/expanding_ring_structured.sh BUILD_DIR [RUN_DIR]
#          (RUN_DIR default /tmp/expanding_ring_structured_runs; a case whose
#          RUN_DIR/name/summary.json exists is not rerun unless FORCE=1, nor
#          one whose RUN_DIR/name exists without it: another invocation runs
#          it, or it failed (see its stderr.txt); so two invocations, one
#          with REVERSE=1 (the list backwards), share the cases on 2 cores;
#          ONLY="name ..." runs only those; RUN_ONLY=1 / ANALYSE_ONLY=1;
#          SUFFIX=_x appends _x to the CSV's and the plots' names, for a
#          series run with another law or build)
# Output:  bench/results/expanding_ring_structured${SUFFIX}.csv,
#          docs/plots/expanding_ring_structured${SUFFIX}.png,
#          docs/plots/expanding_ring_structured${SUFFIX}_distribution.png, tables on stdout.
# Every run niced (nice -n 15), one thread.
set -euo pipefail
build=${1:?usage: expanding_ring_structured.sh BUILD_DIR [RUN_DIR]}
runs=${2:-/tmp/expanding_ring_structured_runs}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
mkdir -p "$here/results" "$root/docs/plots" "$runs"

# name rate R a n end_time [scatter seed]: cross-section a x a cut into n x n
# cells, h = a / n; scatter u<spread> (uniform) or w<modulus> (Weibull, with
# reference_area 0.433 h^2 as in bench/expanding_ring.sh)
cases=(
  "s1e4_n2_u5s1 1.0e4 5.0e-3 2.0e-4 2 3.0e-6 u0.05 1"
  "s1e4_n3_u5s1 1.0e4 5.0e-3 2.0e-4 3 3.0e-6 u0.05 1"
  "s1e4_n4_u5s1 1.0e4 5.0e-3 2.0e-4 4 3.0e-6 u0.05 1"
  "s1e5_n2_u5s1 1.0e5 5.0e-3 1.0e-4 2 8.0e-7 u0.05 1"
  "s1e5_n3_u5s1 1.0e5 5.0e-3 1.0e-4 3 8.0e-7 u0.05 1"
  "s1e5_n4_u5s1 1.0e5 5.0e-3 1.0e-4 4 8.0e-7 u0.05 1"
  "s1e3_n2_u5s1 1.0e3 2.5e-2 4.0e-4 2 1.2e-5 u0.05 1"
  "s1e3_n3_u5s1 1.0e3 2.5e-2 4.0e-4 3 1.2e-5 u0.05 1"
  # no scatter: the degenerate perfect ring
  "s1e4_n2 1.0e4 5.0e-3 2.0e-4 2 3.0e-6"
  "s1e4_n3 1.0e4 5.0e-3 2.0e-4 3 3.0e-6"
  # seed, spread (at 1e4 /s, on h = 100 um and 67 um) and Weibull (on the n = 2 meshes)
  "s1e4_n3_u5s2 1.0e4 5.0e-3 2.0e-4 3 3.0e-6 u0.05 2"
  "s1e4_n2_u2s1 1.0e4 5.0e-3 2.0e-4 2 3.0e-6 u0.02 1"
  "s1e4_n2_u10s1 1.0e4 5.0e-3 2.0e-4 2 3.0e-6 u0.10 1"
  "s1e4_n3_u2s1 1.0e4 5.0e-3 2.0e-4 3 3.0e-6 u0.02 1"
  "s1e4_n2_w8s1 1.0e4 5.0e-3 2.0e-4 2 3.0e-6 w8 1"
  "s1e4_n2_w8s2 1.0e4 5.0e-3 2.0e-4 2 3.0e-6 w8 2"
  "s1e5_n2_w8s1 1.0e5 5.0e-3 1.0e-4 2 8.0e-7 w8 1"
  "s1e5_n2_w8s2 1.0e5 5.0e-3 1.0e-4 2 8.0e-7 w8 2"
  "s1e3_n3_u5s2 1.0e3 2.5e-2 4.0e-4 3 1.2e-5 u0.05 2"
  "s1e3_n2_w8s1 1.0e3 2.5e-2 4.0e-4 2 1.2e-5 w8 1"
  "s1e3_n2_w8s2 1.0e3 2.5e-2 4.0e-4 2 1.2e-5 w8 2"
  # stops at 8.9 us on an inverted element (docs/validation.md), not analysed
  "s1e3_n4_u5s1 1.0e3 2.5e-2 4.0e-4 4 1.2e-5 u0.05 1"
  # more seeds of the main series: one seed's count is a sample
  "s1e4_n2_u5s2 1.0e4 5.0e-3 2.0e-4 2 3.0e-6 u0.05 2"
  "s1e4_n2_u5s3 1.0e4 5.0e-3 2.0e-4 2 3.0e-6 u0.05 3"
  "s1e4_n3_u5s3 1.0e4 5.0e-3 2.0e-4 3 3.0e-6 u0.05 3"
  "s1e5_n2_u5s2 1.0e5 5.0e-3 1.0e-4 2 8.0e-7 u0.05 2"
  "s1e5_n2_u5s3 1.0e5 5.0e-3 1.0e-4 2 8.0e-7 u0.05 3"
  "s1e4_n4_u5s2 1.0e4 5.0e-3 2.0e-4 4 3.0e-6 u0.05 2"
  "s1e5_n3_u5s3 1.0e5 5.0e-3 1.0e-4 3 8.0e-7 u0.05 3"
  "s1e3_n2_u5s2 1.0e3 2.5e-2 4.0e-4 2 1.2e-5 u0.05 2"
  "s1e3_n2_u5s3 1.0e3 2.5e-2 4.0e-4 2 1.2e-5 u0.05 3"
  "s1e4_n4_u5s3 1.0e4 5.0e-3 2.0e-4 4 3.0e-6 u0.05 3"
  "s1e5_n4_u5s2 1.0e5 5.0e-3 1.0e-4 4 8.0e-7 u0.05 2"
)
# the cases in the analysis' form: name rate R a h end_time [scatter seed]
analysis_cases=()
for c in "${cases[@]}"; do
  read -r name rate R a n tend sc seed <<<"$c"
  analysis_cases+=("$name $rate $R $a $(python3 -c "import math; print(2 * math.pi * $R / round(2 * math.pi * $R * $n / $a))") $tend ${sc:-} ${seed:-}")
done

order=("${cases[@]}")
if [ -n "${REVERSE:-}" ]; then
  order=()
  for ((i = ${#cases[@]} - 1; i >= 0; i--)); do order+=("${cases[i]}"); done
fi
for c in "${order[@]}"; do
  [ -n "${ANALYSE_ONLY:-}" ] && break
  read -r name rate R a n tend sc seed <<<"$c"
  if [ -n "${ONLY:-}" ] && [[ " $ONLY " != *" $name "* ]]; then continue; fi
  d="$runs/$name"
  if [ -z "${FORCE:-}" ]; then
    mkdir "$d" 2>/dev/null || continue  # done, failed, or taken by another invocation
  fi
  mkdir -p "$d"
  n_t=$(python3 -c "print(round(2 * 3.141592653589793 * $R * $n / $a))")
  python3 "$here/ring_mesh.py" "$R" "$a" "$n" "$n" "$n_t" "$d/ring.msh" 2> "$d/mesh_quality.txt"
  # the scene: scenes/expanding_ring.yaml with its tube replaced by the file
  python3 - "$root/scenes/expanding_ring.yaml" "$d/scene.yaml" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
text, n = re.subn(r"    mesh:\n(      .*\n)+", "    mesh:\n      file: ring.msh\n", text)
assert n == 1, "scenes/expanding_ring.yaml: no mesh block found"
open(sys.argv[2], "w").write(text)
EOF
  scatter=()
  case "${sc:-}" in
    u*) scatter=(--set materials.alu.fracture.scatter.distribution=uniform
                 --set "materials.alu.fracture.scatter.spread=${sc#u}"
                 --set "materials.alu.fracture.scatter.seed=$seed") ;;
    w*) A0=$(python3 -c "print(0.433 * ($a / $n) ** 2)")
        scatter=(--set materials.alu.fracture.scatter.distribution=weibull
                 --set "materials.alu.fracture.scatter.modulus=${sc#w}"
                 --set "materials.alu.fracture.scatter.seed=$seed"
                 --set "materials.alu.fracture.scatter.reference_area=$A0") ;;
  esac
  echo "running $name ($(cat "$d/mesh_quality.txt"))" >&2
  nice -n 15 "$build/apps/shatter" run "$d/scene.yaml" --out "$d" --threads 1 --quiet \
    --set "bodies[0].velocity_gradient=[[$rate,0,0],[0,$rate,0],[0,0,0]]" \
    --set "time.end=$tend" --set output.every=0 --set output.history_every=20 "${scatter[@]}" 2> "$d/stderr.txt"
done
[ -n "${RUN_ONLY:-}" ] && exit 0

/usr/bin/python3 "$here/expanding_ring_analysis.py" "$runs" "$here/results/expanding_ring_structured${SUFFIX:-}.csv" \
  "$root/docs/plots/expanding_ring_structured${SUFFIX:-}" u0.05 "${analysis_cases[@]}"
