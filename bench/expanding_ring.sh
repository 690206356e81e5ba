#!/usr/bin/env bash
# expanding_ring.sh — fragmentation of an expanding ring against Grady and
# Zhou-Molinari-Ramesh (issue 5's validation, docs/validation.md).
#
# A thin ring (mean radius R = 5 mm, square cross-section a x a) of
# E = 275 GPa, nu = 0.3, rho = 2750 kg/m^3, sigma_c = 300 MPa, Gc = 100 J/m^2,
# beta = 1, starts with v = rate (x, y, 0) (velocity_gradient rate diag(1,1,0))
# at rates 1e4 and 1e5 /s, two element sizes each. Fragment sizes:
#   s_N   = 2 pi R / N                (N: all fragments of fragments.csv)
#   s_big = 2 pi R / N_big            (N_big: fragments of mass >= rho a^2 h,
#                                      i.e. at least one element length)
#   s_m   = sum L_i^2 / sum L_i        (mass-weighted mean length,
#                                      L_i = m_i / (rho a^2))
# Fragments shorter than h are chips off the surface (often one tet), not
# pieces of the ring between two through-cracks; s_big is the size to compare.
# against Grady s_G = (24 Gc / (rho rate^2))^(1/3) and ZMR
# s = s0 4.5 / (1 + 4.5 (rate/eps0)^(2/3)), s0 = E Gc / sigma_c^2,
# eps0 = c sigma_c^3 / (E^2 Gc), c = sqrt(E/rho). Also: the energy ledger
# error, cohesive_dissipated against Gc x N a^2 (N through-cracks of area a^2)
# and its split (summary.json's crack areas: through-cracks, debonded facets
# inside fragments, facets opened partway), fragment counts over time
# (plateau), single-element fragments.
# Run:     bash bench/expanding_ring.sh BUILD_DIR [RUN_DIR]
#          (RUN_DIR keeps every run's outputs; default /tmp/expanding_ring_runs)
# Output:  bench/results/expanding_ring.csv, docs/plots/expanding_ring.png,
#          a table on stdout.
# Expect:  L/N_big 1.2-1.5 x ZMR, 0.3-0.5 x Grady; about 30 minutes of wall
#          time with --threads 1 on a loaded 2-core machine (the two fine
#          rings, 54k and 109k elements, take ~12 minutes each).
set -euo pipefail
build=${1:?usage: expanding_ring.sh BUILD_DIR [RUN_DIR]}
runs=${2:-/tmp/expanding_ring_runs}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
mkdir -p "$here/results" "$root/docs/plots" "$runs"
csv="$here/results/expanding_ring.csv"

# name rate a h end_time
cases=(
  "r1e4_h100 1.0e4 2.0e-4 1.0e-4 3.0e-6"
  "r1e4_h50 1.0e4 2.0e-4 5.0e-5 3.0e-6"
  "r1e5_h50 1.0e5 1.0e-4 5.0e-5 6.0e-7"
  "r1e5_h25 1.0e5 1.0e-4 2.5e-5 8.0e-7"
  # other Gmsh meshes of nearly the same size: the spread of the counts
  "r1e4_h100_9.7e-5 1.0e4 2.0e-4 9.7e-5 3.0e-6"
  "r1e4_h100_1.03e-4 1.0e4 2.0e-4 1.03e-4 3.0e-6"
  "r1e5_h50_4.85e-5 1.0e5 1.0e-4 4.85e-5 6.0e-7"
)
R=5.0e-3
for c in "${cases[@]}"; do
  read -r name rate a h tend <<<"$c"
  [ -f "$runs/$name/summary.json" ] && [ -z "${FORCE:-}" ] && continue
  ri=$(python3 -c "print($R - $a / 2)")
  ro=$(python3 -c "print($R + $a / 2)")
  echo "running $name" >&2
  "$build/apps/shatter" run "$root/scenes/expanding_ring.yaml" --out "$runs/$name" --threads 1 --quiet \
    --set "bodies[0].mesh.inner_radius=$ri" --set "bodies[0].mesh.outer_radius=$ro" \
    --set "bodies[0].mesh.length=$a" --set "bodies[0].mesh.element_size=$h" \
    --set "bodies[0].velocity_gradient=[[$rate,0,0],[0,$rate,0],[0,0,0]]" \
    --set "time.end=$tend" --set output.every=0 --set output.history_every=20
done

/usr/bin/python3 - "$runs" "$csv" "$root/docs/plots/expanding_ring.png" "$R" "${cases[@]}" <<'EOF'
import csv, json, math, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

runs, out_csv, png, R = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
cases = [c.split() for c in sys.argv[5:]]
E, rho, sc, Gc = 275e9, 2750.0, 300e6, 100.0
c0 = math.sqrt(E / rho)
s0 = E * Gc / sc**2
eps0 = c0 * sc**3 / (E**2 * Gc)
grady = lambda r: (24 * Gc / (rho * r**2)) ** (1 / 3)
zmr = lambda r: s0 * 4.5 / (1 + 4.5 * (r / eps0) ** (2 / 3))
L = 2 * math.pi * R

rows, hist, masses = [], {}, {}
for name, rate, a, h, tend in cases:
    rate, a, h = float(rate), float(a), float(h)
    d = f"{runs}/{name}"
    sm = json.load(open(f"{d}/summary.json"))
    fr = list(csv.DictReader(open(f"{d}/fragments.csv")))
    hs = list(csv.DictReader(open(f"{d}/history.csv")))
    A = a * a
    m = [float(f["mass"]) for f in fr]
    Li = [mi / (rho * A) for mi in m]
    N = len(fr)
    big = sum(1 for mi in m if mi >= rho * A * h)
    single = sum(1 for f in fr if int(f["elements"]) == 1)
    s_N, s_big = L / N, L / max(big, 1)
    s_m = sum(l * l for l in Li) / sum(Li)
    # plateau: time at which the fragment count last changed, and the count
    # over the last 30 % of the run
    t = [float(r["time"]) for r in hs]
    nf = [int(r["fragments"]) for r in hs]
    t_last = next(t[i] for i in range(len(nf) - 1, -1, -1) if nf[i] != nf[-1] or i == 0)
    n70 = next(nf[i] for i in range(len(t)) if t[i] >= 0.7 * t[-1])
    kin0 = float(hs[0]["kinetic"])
    diss = sm["cohesive_dissipated"]
    rows.append(dict(
        name=name, rate=rate, a=a, h=h, elements=sm["elements"], steps=sm["steps"], end_time=sm["end_time"],
        fragments=N, fragments_big=big, single_element=single, fragments_at_70pct=n70, last_change=t_last,
        s_N=s_N, s_big=s_big, s_mass=s_m, grady=grady(rate), zmr=zmr(rate),
        ratio_N_zmr=s_N / zmr(rate), ratio_big_zmr=s_big / zmr(rate), ratio_big_grady=s_big / grady(rate), ratio_N_grady=s_N / grady(rate), ratio_m_zmr=s_m / zmr(rate),
        zmr_over_h=zmr(rate) / h, cohesive_elements=sm["cohesive_elements"],
        dissipated=diss, gc_crack_area=Gc * N * A, dissipated_ratio=diss / (Gc * N * A), dissipated_ratio_big=diss / (Gc * max(big, 1) * A),
        kinetic0=kin0, energy_error=sm["energy_error"], wall_time=sm["wall_time"],
        # dissipated / (Gc N_big a^2) split: through-cracks (debonded facets between
        # fragments), debonded facets inside a fragment, facets still cohesive
        split_between=Gc * sm["crack_area_between_fragments"] / (Gc * max(big, 1) * A),
        split_inside=Gc * (sm["crack_area_debonded"] - sm["crack_area_between_fragments"]) / (Gc * max(big, 1) * A),
        split_partial=(diss - sm["cohesive_dissipated_debonded"]) / (Gc * max(big, 1) * A)))
    hist[name] = (t, nf, [float(r["cohesive_dissipated"]) for r in hs])
    masses[name] = (sorted(Li), h)

keys = list(rows[0].keys())
with open(out_csv, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=keys)
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})

print(f"s0 = {s0*1e3:.4f} mm, eps0 = {eps0:.4g} /s, c = {c0:.0f} m/s")
print("| run | rate 1/s | h um | ZMR/h | elements | fragments N (N_big, single-tet) | L/N mm | L/N_big mm | mass-weighted mm | Grady mm | ZMR mm | L/N_big / ZMR | L/N_big / Grady | dissipated / (Gc N_big a^2) | energy error | wall s |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['name']} | {r['rate']:.0e} | {r['h']*1e6:.1f} | {r['zmr_over_h']:.1f} | {r['elements']} | {r['fragments']} ({r['fragments_big']}, {r['single_element']}) "
          f"| {r['s_N']*1e3:.3f} | {r['s_big']*1e3:.3f} | {r['s_mass']*1e3:.3f} | {r['grady']*1e3:.3f} | {r['zmr']*1e3:.3f} | {r['ratio_big_zmr']:.2f} "
          f"| {r['ratio_big_grady']:.2f} | {r['dissipated_ratio_big']:.2f} | {r['energy_error']:.1e} | {r['wall_time']:.0f} |")
print("| run | dissipated / (Gc N_big a^2) | through-cracks | debonded inside fragments | still cohesive (opened partway) |")
print("|---|---|---|---|---|")
for r in rows:
    print(f"| {r['name']} | {r['dissipated_ratio_big']:.2f} | {r['split_between']:.2f} | {r['split_inside']:.2f} | {r['split_partial']:.2f} |")
for r in rows:
    print(f"{r['name']}: last change of the fragment count at {r['last_change']*1e6:.3f} us of {r['end_time']*1e6:.2f} us; "
          f"count at 70 % of the run {r['fragments_at_70pct']}, at the end {r['fragments']}")

fig, ax = plt.subplots(1, 3, figsize=(15, 4.5))
rr = [10 ** (3 + 0.05 * i) for i in range(61)]
ax[0].loglog(rr, [grady(x) * 1e3 for x in rr], "k--", label="Grady")
ax[0].loglog(rr, [zmr(x) * 1e3 for x in rr], "k-", label="Zhou-Molinari-Ramesh")
for i, r in enumerate(rows):
    mk, col = "osD^v<>p"[i % 8], f"C{i % 10}"
    ax[0].loglog([r["rate"] * (1 + 0.04 * i)], [r["s_big"] * 1e3], mk, color=col, label=f"{r['name']}: L/N_big")
    ax[0].loglog([r["rate"] * (1 + 0.04 * i)], [r["s_mass"] * 1e3], mk, color=col, mfc="none", label=f"{r['name']}: mass-weighted")
ax[0].set_xlabel("strain rate, 1/s"); ax[0].set_ylabel("mean fragment size, mm"); ax[0].legend(fontsize=6)
for name, (Ls, h) in masses.items():
    n = len(Ls)
    ax[1].semilogx([l * 1e3 for l in Ls], [(i + 1) / n for i in range(n)], label=name)
ax[1].set_xlabel("fragment length L_i = m_i / (rho a^2), mm"); ax[1].set_ylabel("cumulative fraction of fragments")
ax[1].legend(fontsize=8)
for name, (t, nf, dis) in hist.items():
    ax[2].plot([x * 1e6 for x in t], nf, label=name)
ax[2].set_xlabel("time, us"); ax[2].set_ylabel("fragments"); ax[2].set_yscale("log"); ax[2].legend(fontsize=8)
fig.tight_layout()
fig.savefig(png, dpi=110)
EOF
