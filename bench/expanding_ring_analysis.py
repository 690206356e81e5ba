#!/usr/bin/env python3
"""expanding_ring_analysis.py — fragment sizes of expanding-ring runs against
Grady and Zhou-Molinari-Ramesh (ZMR): the CSV, the tables and the plots of
bench/expanding_ring.sh (unstructured tube) and
bench/expanding_ring_structured.sh (structured ring); the definitions are in
bench/expanding_ring.sh's header and docs/validation.md.

Run: expanding_ring_analysis.py RUN_DIR OUT.csv PLOT_PREFIX MAIN_SCATTER CASE...
  CASE = "name rate R a h end_time [scatter seed]"; scatter is w<m> (Weibull
  modulus m), u<s> (uniform, half-width s) or a bare number (Weibull modulus).
  MAIN_SCATTER: the scatter of the series drawn as the mesh convergence
  ("" for none); the distribution plot compares every scatter run on the mesh
  of the Weibull runs. Plots: PLOT_PREFIX.png, PLOT_PREFIX_distribution.png.
"""
import csv, json, math, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

runs, out_csv, plots, main_scatter = sys.argv[1:5]
cases = [c.split() for c in sys.argv[5:]]
E, rho, sc, Gc = 275e9, 2750.0, 300e6, 100.0
c0 = math.sqrt(E / rho)
s0 = E * Gc / sc**2
eps0 = c0 * sc**3 / (E**2 * Gc)
grady = lambda r: (24 * Gc / (rho * r**2)) ** (1 / 3)
# ZMR for a toughness G (s0 and eps0 scale with G and 1 / G)
zmr_g = lambda r, G: (E * G / sc**2) * 4.5 / (1 + 4.5 * (r / (c0 * sc**3 / (E**2 * G))) ** (2 / 3))
zmr = lambda r: zmr_g(r, Gc)


def scatter_label(s):
    if s.startswith("w"):
        return f"Weibull m = {s[1:]}"
    if s.startswith("u"):
        return f"uniform +-{float(s[1:]) * 100:g} %"
    return "no scatter"


rows, hist, lengths = [], {}, {}
for case in cases:
    name, rate, R, a, h, tend = case[:6]
    scatter, seed = (case[6], case[7]) if len(case) > 6 else ("", "")
    if scatter and scatter[0].isdigit():
        scatter = "w" + scatter
    wm = scatter[1:] if scatter.startswith("w") else ""
    spread = scatter[1:] if scatter.startswith("u") else ""
    rate, R, a, h = float(rate), float(R), float(a), float(h)
    d = f"{runs}/{name}"
    if not os.path.exists(f"{d}/summary.json"):
        print(f"{name}: not run", file=sys.stderr)
        continue
    L = 2 * math.pi * R
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
    t = [float(r["time"]) for r in hs]
    nf = [int(r["fragments"]) for r in hs]
    # plateau: time at which the fragment count last changed, and the count
    # at 70 % of the run
    t_last = next(t[i] for i in range(len(nf) - 1, -1, -1) if nf[i] != nf[-1] or i == 0)
    n70 = next(nf[i] for i in range(len(t)) if t[i] >= 0.7 * t[-1])
    # the hoop strain rate when the first facet is inserted: v / R from the
    # kinetic energy (the free ring slows down under its hoop stress)
    kin0 = float(hs[0]["kinetic"])
    i1 = next((i for i, r in enumerate(hs) if int(r["cohesive_elements"]) > 0), 0)
    rate_ins = rate * math.sqrt(float(hs[i1]["kinetic"]) / kin0)
    diss = sm["cohesive_dissipated"]
    z = zmr(rate)
    rows.append(dict(
        name=name, rate=rate, R=R, a=a, h=h, weibull_modulus=wm, uniform_spread=spread, scatter=scatter, seed=seed, elements=sm["elements"], steps=sm["steps"],
        end_time=sm["end_time"], first_insertion=t[i1], rate_at_insertion=rate_ins,
        fragments=N, fragments_big=big, single_element=single, fragments_at_70pct=n70, last_change=t_last,
        s_N=s_N, s_big=s_big, s_mass=s_m, grady=grady(rate), zmr=z, zmr_at_insertion=zmr(rate_ins),
        ratio_N_zmr=s_N / z, ratio_big_zmr=s_big / z, ratio_big_zmr_at_insertion=s_big / zmr(rate_ins),
        ratio_big_grady=s_big / grady(rate), ratio_m_zmr=s_m / z,
        zmr_over_h=z / h, cohesive_elements=sm["cohesive_elements"],
        dissipated=diss, dissipated_ratio_big=diss / (Gc * max(big, 1) * A),
        kinetic0=kin0, energy_error=sm["energy_error"], wall_time=sm["wall_time"],
        # dissipated / (Gc N_big a^2) split: through-cracks (debonded facets between
        # fragments), debonded facets inside a fragment, facets still cohesive
        split_between=sm["crack_area_between_fragments"] / (max(big, 1) * A),
        split_inside=(sm["crack_area_debonded"] - sm["crack_area_between_fragments"]) / (max(big, 1) * A),
        split_partial=(diss - sm["cohesive_dissipated_debonded"]) / (Gc * max(big, 1) * A)))
    # each through-crack debonds (between + inside) a^2 of facets, not a^2: ZMR
    # with Gc times that ratio, the toughness per crack of the ring's cross-section
    rows[-1]["debonded_per_crack"] = rows[-1]["split_between"] + rows[-1]["split_inside"]
    rows[-1]["ratio_big_zmr_debonded_gc"] = s_big / zmr_g(rate, Gc * rows[-1]["debonded_per_crack"])
    hist[name] = (t, nf)
    lengths[name] = [l for l in Li if l >= h]

keys = list(rows[0].keys())
with open(out_csv, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=keys)
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})

print(f"s0 = {s0*1e3:.4f} mm, eps0 = {eps0:.4g} /s, c = {c0:.0f} m/s")
print("| run | rate 1/s (at 1st insertion) | R mm | a mm | h um | ZMR/h | tets | N (N_big, single-tet) | L/N_big mm | mass-weighted mm | ZMR mm | L/N_big / ZMR | / ZMR at the insertion rate | L/N_big / Grady | dissipated / (Gc N_big a^2) | energy error | wall s |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['name']} | {r['rate']:.0e} ({r['rate_at_insertion']:.3g}) | {r['R']*1e3:g} | {r['a']*1e3:g} | {r['h']*1e6:.0f} | {r['zmr_over_h']:.1f} | {r['elements']} "
          f"| {r['fragments']} ({r['fragments_big']}, {r['single_element']}) | {r['s_big']*1e3:.3f} | {r['s_mass']*1e3:.3f} | {r['zmr']*1e3:.3f} "
          f"| **{r['ratio_big_zmr']:.2f}** | {r['ratio_big_zmr_at_insertion']:.2f} | {r['ratio_big_grady']:.2f} | {r['dissipated_ratio_big']:.2f} | {r['energy_error']:.1e} | {r['wall_time']:.0f} |")
print()
print("| run | dissipated / (Gc N_big a^2) | through-cracks | debonded inside fragments | still cohesive (opened partway) | L/N_big / ZMR | L/N_big / ZMR with Gc x debonded area per crack |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['name']} | {r['dissipated_ratio_big']:.2f} | {r['split_between']:.2f} | {r['split_inside']:.2f} | {r['split_partial']:.2f} "
          f"| {r['ratio_big_zmr']:.2f} | {r['ratio_big_zmr_debonded_gc']:.2f} |")
print()
for r in rows:
    print(f"{r['name']}: first facet at {r['first_insertion']*1e6:.3f} us; last change of the count at {r['last_change']*1e6:.3f} us "
          f"of {r['end_time']*1e6:.2f} us; count at 70 % of the run {r['fragments_at_70pct']}, at the end {r['fragments']}")

# one line per run: what issue 19's done-when 2 asks for
print()
print("| run | rate 1/s | h um | ZMR/h | tets | scatter, seed | N (N_big) | L/N_big / ZMR | through-crack area / a^2 | debonded area per crack / a^2 | dissipated / (Gc N_big a^2) | energy error |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['name']} | {r['rate']:.0e} | {r['h']*1e6:.0f} | {r['zmr_over_h']:.1f} | {r['elements']} | {scatter_label(r['scatter'])}{', ' + r['seed'] if r['seed'] else ''} "
          f"| {r['fragments']} ({r['fragments_big']}) | **{r['ratio_big_zmr']:.2f}** | {r['split_between']:.2f} | {r['debonded_per_crack']:.2f} "
          f"| {r['dissipated_ratio_big']:.2f} | {r['energy_error']:.1e} |")

# runs of one rate, mesh and scatter with different seeds: the seed's sample
# of strengths moves the count, so a mesh's size is the mean over its seeds
# (min and max beside it)
groups = {}
for r in rows:
    groups.setdefault((r["rate"], r["h"], r["scatter"]), []).append(r)
print()
print("| rate 1/s | h um | ZMR/h | scatter | seeds | L/N_big / ZMR, mean over seeds | min - max | through-crack area / a^2 | debonded area per crack / a^2 | dissipated / (Gc N_big a^2) |")
print("|---|---|---|---|---|---|---|---|---|---|")
for (rate, h, scat), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][2], -kv[0][1])):
    mean = lambda key: sum(r[key] for r in rs) / len(rs)
    q = [r["ratio_big_zmr"] for r in rs]
    print(f"| {rate:.0e} | {h*1e6:.0f} | {rs[0]['zmr_over_h']:.1f} | {scatter_label(scat)} | {len(rs)} | **{mean('ratio_big_zmr'):.2f}** | {min(q):.2f} - {max(q):.2f} "
          f"| {mean('split_between'):.2f} | {mean('debonded_per_crack'):.2f} | {mean('dissipated_ratio_big'):.2f} |")

# size against rate, convergence with ZMR/h, counts against time
rate_names = sorted({r["rate"] for r in rows})
fig, ax = plt.subplots(1, 3, figsize=(16, 4.8))
rr = [10 ** (2.8 + 0.05 * i) for i in range(50)]
ax[0].loglog(rr, [grady(x) * 1e3 for x in rr], "k--", label="Grady")
ax[0].loglog(rr, [zmr(x) * 1e3 for x in rr], "k-", label="Zhou-Molinari-Ramesh")
for r in rows:
    col = f"C{rate_names.index(r['rate'])}"
    main = r["scatter"] == main_scatter
    ax[0].loglog([r["rate"] * (1 + 0.02 * (r["zmr_over_h"] - 5))], [r["s_big"] * 1e3], "o" if main else "^", color=col, mfc=col if main else "none")
ax[0].plot([], [], "ko", label=f"L/N_big, {scatter_label(main_scatter)}")
ax[0].plot([], [], "k^", mfc="none", label="L/N_big, other scatter")
ax[0].set_xlabel("strain rate, 1/s"); ax[0].set_ylabel("mean fragment size, mm"); ax[0].legend(fontsize=8)
for k, rate in enumerate(rate_names):
    gs = sorted((g for key, g in groups.items() if key[0] == rate and key[2] == main_scatter), key=lambda g: g[0]["zmr_over_h"])
    x = [g[0]["zmr_over_h"] for g in gs]
    m = [sum(r["ratio_big_zmr"] for r in g) / len(g) for g in gs]
    lo = [mi - min(r["ratio_big_zmr"] for r in g) for mi, g in zip(m, gs)]
    hi = [max(r["ratio_big_zmr"] for r in g) - mi for mi, g in zip(m, gs)]
    ax[1].errorbar(x, m, yerr=[lo, hi], fmt="o-", capsize=3, color=f"C{k}", label=f"{rate:.0e} /s (mean of seeds, min-max)")
    ws = [r for r in rows if r["rate"] == rate and r["scatter"] != main_scatter]
    ax[1].plot([r["zmr_over_h"] for r in ws], [r["ratio_big_zmr"] for r in ws], "^", color=f"C{k}", mfc="none")
ax[1].axhspan(0.9, 1.1, color="0.9", label="ZMR +- 10 %")
ax[1].axhline(1.0, color="k", lw=0.8)
ax[1].set_xlabel("ZMR size / h"); ax[1].set_ylabel(f"(L/N_big) / ZMR (line: {scatter_label(main_scatter)})"); ax[1].legend(fontsize=8)
for r in rows:
    if r["scatter"] != main_scatter:
        continue
    t, nf = hist[r["name"]]
    k = rate_names.index(r["rate"])
    ax[2].plot([x / (sc / (E * r["rate"])) for x in t], nf, color=f"C{k}", lw=0.6 + 0.25 * r["zmr_over_h"] / 2, label=r["name"])
ax[2].set_xlabel("time / (sigma_c / (E rate))"); ax[2].set_ylabel("fragments"); ax[2].set_yscale("log")
ax[2].legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{plots}.png", dpi=110)

# cumulative size distributions (fragments of at least one element length),
# normalised by ZMR's mean, against the Rayleigh distribution that Zhou,
# Molinari & Ramesh (APL 2006) found for their fragment populations, with
# ZMR's mean: F(x) = 1 - exp(-pi x^2 / 4), x = s / s_ZMR
fig, ax = plt.subplots(1, len(rate_names), figsize=(5.3 * len(rate_names), 4.5), squeeze=False)
xs = [0.02 * i for i in range(201)]
for k, rate in enumerate(rate_names):
    a_ = ax[0][k]
    z = zmr(rate)
    a_.plot(xs, [1 - math.exp(-math.pi * x * x / 4) for x in xs], "k-", lw=2, label="Rayleigh, ZMR mean")
    hw = [q["h"] for q in rows if q["rate"] == rate and q["weibull_modulus"]]
    groups = sorted({r["scatter"] for r in rows if r["rate"] == rate and hw and r["h"] == hw[0]}, reverse=True)
    for j, g in enumerate(groups):
        rs = [r for r in rows if r["rate"] == rate and r["scatter"] == g and r["h"] == hw[0]]
        pool = sorted(l / z for r in rs for l in lengths[r["name"]])
        if not pool:
            continue
        lab = f"{scatter_label(g)}, seeds: {len(rs)} ({len(pool)} fragments)"
        n = len(pool)
        mean = sum(pool) / n
        std = math.sqrt(sum((x - mean) ** 2 for x in pool) / n)
        # Kolmogorov-Smirnov distance to the Rayleigh distribution of mean m
        ks = lambda m: max(max(abs((i + 1) / n - F), abs(i / n - F))
                           for i, x in enumerate(pool) for F in [1 - math.exp(-math.pi * x * x / (4 * m * m))])
        print(f"distribution {rate:.0e} /s, h = {hw[0]*1e6:.0f} um, {lab}: mean / ZMR {mean:.3f}, std / mean {std / mean:.3f} "
              f"(Rayleigh 0.523), KS distance to Rayleigh with ZMR's mean {ks(1.0):.3f}, with its own mean {ks(mean):.3f}")
        a_.step(pool, [(i + 1) / n for i in range(n)], where="post", color=f"C{j}", label=lab + f", mean {mean:.2f}")
        a_.plot(xs, [1 - math.exp(-math.pi * x * x / (4 * mean * mean)) for x in xs], "--", color=f"C{j}", lw=0.8, label="Rayleigh, that mean")
    a_.set_xlim(0, 4)
    a_.set_title(f"{rate:.0e} /s, h = {hw[0]*1e6:.0f} um, ZMR {z*1e3:.3f} mm" if hw else f"{rate:.0e} /s")
    a_.set_xlabel("fragment length / ZMR mean size"); a_.set_ylabel("cumulative fraction of fragments")
    a_.legend(fontsize=7, loc="lower right")
fig.tight_layout()
fig.savefig(f"{plots}_distribution.png", dpi=110)
