#!/usr/bin/python3
"""tools/scripts/charts.py — draws the report's charts from the CSV/JSON the experiment programs
write (Debian's python3-matplotlib; no other dependency).

    /usr/bin/python3 tools/scripts/charts.py OUT_DIR    reads OUT_DIR/*.csv|json, writes OUT_DIR/*.png
    /usr/bin/python3 tools/scripts/charts.py energy SUMMARY.json OUT.png
                                                the energy audit of one magsim-scene run

Every chart is skipped (with a note) when its data file is missing, so a partial run still
draws what it has."""
import csv
import json
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

COLORS = {"ours": "tab:blue", "ours-realigned": "tab:green", "kim2018": "tab:red",
          "damping-llg": "tab:orange", "anderson": "tab:purple", "exact": "black"}


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def have(out, name):
    p = os.path.join(out, name)
    if not os.path.exists(p):
        print(f"charts: {name} missing, chart skipped")
        return None
    return p


def fig8(out):
    p = have(out, "fig8.csv")
    if not p:
        return
    data = defaultdict(lambda: ([], []))
    for r in rows(p):
        k = (r["magnet"], r["method"])
        data[k][0].append(int(r["iteration"]))
        data[k][1].append(max(float(r["e_M"]), 1e-16))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for ax, magnet in zip(axes, ["weak", "strong"]):
        for (mg, method), (x, y) in sorted(data.items()):
            if mg == magnet:
                ax.semilogy(x, y, label=method, color=COLORS.get(method))
        ax.set_title(f"crystal_balls, {magnet} bar magnet (paper Fig. 8)")
        ax.set_xlabel("iteration")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("e_M (eq. 12)")
    axes[1].legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig8.png"), dpi=110)
    plt.close(fig)


def fig9(out):
    order = list(COLORS)
    files = sorted((f for f in os.listdir(out) if f.startswith("fig9_") and f.endswith(".csv")
                    and "shard" not in f),
                   key=lambda f: order.index(f[5:-4]) if f[5:-4] in order else len(order))
    if not files:
        print("charts: fig9_*.csv missing, chart skipped")
        return
    fig, axes = plt.subplots(1, len(files), figsize=(4.2 * len(files), 4.5), squeeze=False)
    for ax, f in zip(axes[0], files):
        method = f[len("fig9_"):-4]
        rs = rows(os.path.join(out, f))
        dts = sorted({float(r["dt_mult"]) for r in rs})
        hs = sorted({float(r["h_mult"]) for r in rs})
        grid = [[math.nan] * len(dts) for _ in hs]
        for r in rs:
            grid[hs.index(float(r["h_mult"]))][dts.index(float(r["dt_mult"]))] = \
                float(r["mean_iterations"])
        im = ax.imshow(grid, origin="lower", aspect="auto", cmap="rainbow",
                       norm=LogNorm(vmin=1, vmax=999),
                       extent=[dts[0], dts[-1], hs[0], hs[-1]])
        ax.set_title(method)
        ax.set_xlabel("Δt / 100 ns")
        ax.set_ylabel("|H| / |M|")
    fig.colorbar(im, ax=axes[0].tolist(), label="mean iterations (red: ≥ 999 / failure)")
    fig.suptitle("Stability map (paper Fig. 9)")
    fig.savefig(os.path.join(out, "fig9.png"), dpi=110)
    plt.close(fig)


def fig10(out):
    p = have(out, "fig10.csv")
    if not p:
        return
    rs = rows(p)
    xs = sorted({float(r["x"]) for r in rs})
    zs = sorted({float(r["z"]) for r in rs})
    grids = {}
    for key in ("F_kim", "F_ours"):
        g = [[math.nan] * len(xs) for _ in zs]
        for r in rs:
            g[zs.index(float(r["z"]))][xs.index(float(r["x"]))] = float(r[key])
        grids[key] = g
    vals = [v for g in grids.values() for row in g for v in row if not math.isnan(v) and v > 0]
    norm = LogNorm(vmin=min(vals), vmax=max(vals))
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
    for ax, key, title in zip(axes, ("F_kim", "F_ours"),
                              ("Kim 2018: classic force, eq. 7 curve", "ours: Zeeman force (eq. 4)")):
        im = ax.imshow(grids[key], origin="lower", cmap="rainbow", norm=norm,
                       extent=[xs[0] * 100, xs[-1] * 100, zs[0] * 100, zs[-1] * 100])
        ax.set_title(title)
        ax.set_xlabel("x (cm)")
        ax.set_ylabel("z (cm)")
    fig.colorbar(im, ax=axes.tolist(), label="|F| on a 2 mm iron ball (N), one scale")
    fig.suptitle("Force near a uniformly magnetized sphere (paper Fig. 10)")
    fig.savefig(os.path.join(out, "fig10.png"), dpi=110)
    plt.close(fig)


def em_time_curves(path):
    """(magnet, method) -> ([wall ms], [e_M]) from a speed CSV (speed_accuracy.csv layout)."""
    data = defaultdict(lambda: ([], []))
    for r in rows(path):
        k = (r["magnet"], r["method"])
        data[k][0].append(float(r["wall_ms"]))
        data[k][1].append(max(float(r["e_M"]), 1e-16))
    return data


def em_time_panel(ax, data, magnet, title):
    """e_M against wall time, one line per method (Newton as points; '+bh' runs dashed)."""
    for (mg, method), (x, y) in sorted(data.items()):
        if mg != magnet:
            continue
        base = method.split("+")[0]
        if method == "exact":
            ax.loglog(x, y, "o-", label="Newton (exact)", color=COLORS["exact"])
        elif "+bh" in method:
            th = float(method.split("+bh")[1])
            ax.loglog(x, y, "--", label=f"{base}, Barnes–Hut θ={th:g}", color=COLORS.get(base),
                      alpha=0.35 + 0.65 * (1 - th))
        else:
            ax.loglog(x, y, "-", label=method, color=COLORS.get(method))
    ax.set_title(title)
    ax.set_xlabel("wall time (ms)")
    ax.grid(True, which="both", alpha=0.3)


def speed(out):
    p = have(out, "speed_accuracy.csv")
    if p:
        data = em_time_curves(p)
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
        for ax, magnet in zip(axes, ["weak", "strong"]):
            em_time_panel(ax, data, magnet, f"speed against accuracy, crystal_balls {magnet}")
        axes[0].set_ylabel("e_M")
        axes[1].legend()
        fig.tight_layout()
        fig.savefig(os.path.join(out, "speed_accuracy.png"), dpi=110)
        plt.close(fig)
    p = have(out, "dt_iterations.csv")
    if p:
        data = defaultdict(lambda: ([], []))
        for r in rows(p):
            it = int(r["iterations_to_1e-4"])
            data[(r["magnet"], r["method"])][0].append(float(r["dt_ns"]))
            data[(r["magnet"], r["method"])][1].append(it if it > 0 else float("nan"))
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
        for ax, magnet in zip(axes, ["weak", "strong"]):
            for (mg, method), (x, y) in sorted(data.items()):
                if mg == magnet:
                    ax.plot(x, y, "o-", label=method, color=COLORS.get(method))
            ax.set_title(f"Δt_m against iterations to e_M ≤ 1e-4 ({magnet}); gaps: never")
            ax.set_xlabel("Δt_m (ns)")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
        axes[0].set_ylabel("iterations")
        axes[1].legend()
        fig.tight_layout()
        fig.savefig(os.path.join(out, "dt_iterations.png"), dpi=110)
        plt.close(fig)


def snapshot_speed(out):
    """speed_sakura.png: e_M against wall time on the sakura_tree snapshot from M = 0 and from
    the engine's warm start, and the Barnes–Hut field's error against its time."""
    p = have(out, "speed_sakura.csv")
    if not p:
        return
    data = em_time_curves(p)
    info = {}
    j = os.path.join(out, "snapshot_speed.json")
    if os.path.exists(j):
        with open(j) as f:
            info = json.load(f).get("snapshot", {})
    where = (f"sakura_tree, {info['balls']} balls, t = {info['seconds']:.2f} s"
             if info else "sakura_tree snapshot")
    fig, axes = plt.subplots(1, 3, figsize=(18, 5.2))
    em_time_panel(axes[0], data, "cold", f"{where}: from M = 0")
    em_time_panel(axes[1], data, "warm", f"{where}: from the engine's warm start")
    lo = min(min(y) for y in (v[1] for v in data.values()))
    for ax in axes[:2]:
        ax.set_ylim(max(lo / 2, 1e-13), 2)
        ax.set_ylabel("e_M against Newton (eq. 12)")
    axes[0].legend(fontsize=7, loc="lower left")
    ax = axes[2]
    b = os.path.join(out, "sakura_bh.csv")
    if os.path.exists(b):
        rs = rows(b)
        bh = [r for r in rs if r["solver"] == "barnes-hut"]
        direct = [float(r["ms_per_eval"]) for r in rs if r["solver"] == "direct"]
        t = [float(r["ms_per_eval"]) for r in bh]
        ax.loglog(t, [max(float(r["rms_rel_err"]), 1e-16) for r in bh], "o-", color="tab:purple",
                  label="RMS relative error")
        ax.loglog(t, [max(float(r["max_rel_err"]), 1e-16) for r in bh], "s--", color="tab:purple",
                  label="max relative error")
        for r in bh:
            ax.annotate(f"θ={float(r['theta']):g}", (float(r["ms_per_eval"]), float(r["max_rel_err"])),
                        textcoords="offset points", xytext=(4, 4), fontsize=8)
        if direct:
            ax.axvline(direct[0], color="black", ls=":", label=f"direct sum ({direct[0]:.2f} ms, exact)")
        ax.set_xlabel("ms per field evaluation (H at every moment)")
        ax.set_ylabel("field error against the direct sum")
        ax.set_title("Barnes–Hut field on the snapshot")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    else:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "speed_sakura.png"), dpi=110)
    plt.close(fig)


def tolerance(out):
    """tolerance.png: relative force error against the tolerance per method (warm start and
    M = 0) and the time it took, with balls_up's T_i per step."""
    p = have(out, "tolerance_snapshot.csv")
    if not p:
        return
    data = defaultdict(list)
    for r in rows(p):
        data[(r["start"], r["method"])].append(r)
    fig, axes = plt.subplots(1, 3, figsize=(18, 5.2))
    for ax, start, title in ((axes[0], "warm", "from the engine's warm start"),
                             (axes[1], "cold", "from M = 0")):
        for (st, method), rs in sorted(data.items()):
            if st != start:
                continue
            rs = sorted(rs, key=lambda r: float(r["tol"]))
            tol = [float(r["tol"]) for r in rs]
            c = COLORS.get(method)
            ax.loglog(tol, [max(float(r["force_err_max"]), 1e-16) for r in rs], "o-", color=c,
                      label=f"{method} max")
            ax.loglog(tol, [max(float(r["force_err_rms"]), 1e-16) for r in rs], "--", color=c,
                      label=f"{method} RMS")
            capped = [(t, float(r["force_err_max"])) for t, r in zip(tol, rs) if r["converged"] != "1"]
            if capped:
                ax.loglog(*zip(*capped), "x", color="black", ms=9)
        ax.set_title(f"sakura_tree snapshot, {title}")
        ax.set_xlabel("tolerance (max_j |M_j − f(H_j)| / Ms)")
        ax.set_ylabel("|F − F_gt| / max |F_gt|")
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
    if not any(st == "cold" for st, _ in data):
        axes[1].set_visible(False)
    axes[0].legend(fontsize=7, ncol=2, title="x: iteration cap hit", title_fontsize=7)
    ax = axes[2]
    for (st, method), rs in sorted(data.items()):
        rs = sorted(rs, key=lambda r: float(r["tol"]))
        ax.loglog([float(r["tol"]) for r in rs], [float(r["wall_ms"]) for r in rs],
                  "o-" if st == "warm" else "o:", color=COLORS.get(method),
                  label=f"{method} ({st})", ms=4)
    o = os.path.join(out, "tolerance_outcome.csv")
    if os.path.exists(o):
        rs = sorted(rows(o), key=lambda r: float(r["tol"]))
        if rs:
            ax.loglog([float(r["tol"]) for r in rs], [float(r["T_i_median_ms"]) for r in rs], "s-",
                      color="black", lw=2, label=f"{rs[0]['scene']} T_i per step, median")
    ax.set_title("time to the tolerance")
    ax.set_xlabel("tolerance")
    ax.set_ylabel("ms (snapshot: one solve; balls_up: per 1 ms step)")
    ax.invert_xaxis()
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "tolerance.png"), dpi=110)
    plt.close(fig)


def stacked_timing(ax, x, timing, width, color, label=None):
    """One bar at x of a bench run's median T_i (plain), T_f (//) and T_r (..) stacked, labelled
    "LABEL T_i" etc. when label is given; returns the bar's top."""
    bottom = 0
    for key, hatch in (("T_i", ""), ("T_f", "//"), ("T_r", "..")):
        v = timing[key]["median"]
        ax.bar(x, v, width, bottom=bottom, color=color, hatch=hatch, edgecolor="black", linewidth=0.3,
               label=f"{label} {key}" if label else None)
        bottom += v
    return bottom


def bench(out):
    p = have(out, "bench.json")
    if not p:
        return
    with open(p) as f:
        b = json.load(f)
    runs = b.get("runs", [])
    scenes = sorted({r["scene"] for r in runs})
    methods = sorted({r["method"] for r in runs})
    if not runs:
        return
    fig, ax = plt.subplots(figsize=(10, 4.5))
    width = 0.8 / max(1, len(methods))
    for mi, m in enumerate(methods):
        for si, s in enumerate(scenes):
            r = next((r for r in runs if r["scene"] == s and r["method"] == m), None)
            if not r:
                continue
            stacked_timing(ax, si + mi * width, r["timing_ms"], width, COLORS.get(m), m if si == 0 else None)
    ax.set_xticks([i + 0.4 - width / 2 for i in range(len(scenes))])
    ax.set_xticklabels(scenes)
    ax.set_ylabel("ms per 1 ms step (median)")
    ax.set_yscale("log")
    ax.set_title("Table 1: T_i (plain), T_f (//), T_r (..) per step")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "table1.png"), dpi=110)
    plt.close(fig)
    sc = b.get("scaling", [])
    if sc:
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for m in sorted({r["method"] for r in sc}):
            pts = sorted((r["balls"], r["total_ms"]) for r in sc if r["method"] == m)
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=m, color=COLORS.get(m))
        ax.set_xlabel("balls")
        ax.set_ylabel("ms per step (median, T_i + T_f + T_r)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        ax.set_title("Scaling (sakura_tree with N balls)")
        fig.tight_layout()
        fig.savefig(os.path.join(out, "scaling.png"), dpi=110)
        plt.close(fig)


def near_field_cost(out):
    """bench --near-field-cost: T_i, T_f, T_r per step of each scene with one dipole per ball
    and with the pair model, measured in the same run; the ratio pair/dipole over each pair of bars."""
    p = have(out, "near_field_cost.json")
    if not p:
        return
    with open(p) as f:
        b = json.load(f)
    runs = [r for r in b.get("runs", []) if "near_field" in r]
    if not runs:
        return
    scenes = list(dict.fromkeys(r["scene"] for r in runs))
    models = ("dipole", "pair")
    fig, ax = plt.subplots(figsize=(8, 4.5))
    width = 0.38
    ymax = 0
    for si, s in enumerate(scenes):
        stacked = 0
        for mi, m in enumerate(models):
            r = next((r for r in runs if r["scene"] == s and r["near_field"] == m), None)
            if not r:
                continue
            top = stacked_timing(ax, si + mi * width, r["timing_ms"], width,
                                 "tab:blue" if m == "dipole" else "tab:red", m if si == 0 else None)
            stacked = max(stacked, top)
        ymax = max(ymax, stacked)
        for meth, q in b.get("near_field_cost", {}).get(s, {}).items():
            ax.text(si + width / 2, stacked * 1.02, f"pair/dipole ×{q['pair_over_dipole']:.2f}",
                    ha="center", fontsize=8)
    ax.set_ylim(0, ymax * 1.15)
    ax.set_xticks([i + width / 2 for i in range(len(scenes))])
    ax.set_xticklabels(scenes)
    ax.set_ylabel("ms per 1 ms step (median)")
    ax.set_title("near field: cost per step, dipole against pair (same run); T_i plain, T_f //, T_r ..",
                 fontsize=9)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "near_field_cost.png"), dpi=110)
    plt.close(fig)



def near_field_tradeoff(out):
    """The near-field models' cost per step (bench --near-field-cost, one point per scene and
    model) against their physical error (tools/reference/near_field_chart.py's
    near_field_accuracy.csv: the share of reference cases outside their marks)."""
    p = have(out, "near_field_cost.json")
    q = have(out, "near_field_accuracy.csv")
    if not p or not q:
        return
    with open(p) as f:
        b = json.load(f)
    acc = {r["model"]: r for r in rows(q)}
    runs = [r for r in b.get("runs", []) if r.get("near_field") in acc]
    if not runs:
        return
    measures = (("pair cells outside 0.85–1.15 (two balls, axial, 6 gaps × 8 fields)",
                 lambda a: 1 - int(a["pair_cells_in_band"]) / int(a["pair_cells"])),
                ("chains: end ball and moment beyond 25 % (3 and 5 balls, 8 fields)",
                 lambda a: 1 - int(a["chain_marked_within_25pct"]) / int(a["chain_marked"])))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    scenes = list(dict.fromkeys(r["scene"] for r in runs))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (title, err) in zip(axes, measures):
        for si, s in enumerate(scenes):
            pts = []
            for m, marker in (("dipole", "o"), ("pair", "s")):
                r = next((r for r in runs if r["scene"] == s and r["near_field"] == m), None)
                if not r:
                    continue
                x, y = err(acc[m]), r["timing_ms"]["total"]["median"]
                pts.append((x, y))
                ax.plot(x, y, marker, color=colors[si % len(colors)], ms=8,
                        label=f"{s}, {m}" if ax is axes[0] else None)
                ax.annotate(m, (x, y), textcoords="offset points", xytext=(6, 4), fontsize=8)
            if len(pts) == 2:
                ax.plot([p_[0] for p_ in pts], [p_[1] for p_ in pts], "-", color=colors[si % len(colors)], lw=0.8)
        ax.set_xlim(-0.05, 1.05)
        ax.set_xlabel("share of reference cases outside the mark")
        ax.set_title(title, fontsize=9)
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("ms per 1 ms step (median, T_i + T_f + T_r)")
    axes[0].legend(fontsize=7)
    fig.suptitle("near field: cost per step against physical error", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "near_field_tradeoff.png"), dpi=110)
    plt.close(fig)

ENERGY_SERIES = (("energy_kinetic", "kinetic K", "tab:blue"),
                 ("energy_gravitational", "gravitational U_g − U_g(0)", "tab:brown"),
                 ("energy_magnetic_work", "magnetic work W_mag", "tab:red"),
                 ("energy_contact_work", "contact work W_c", "tab:green"),
                 ("energy_eddy_work", "eddy-current loss W_e", "tab:orange"),
                 ("energy_magnetic", "co-energy U* − U*(first)", "tab:purple"),
                 ("energy_total", "E = K + U_g + U*, − E(first)", "black"),
                 ("energy_created", "created: Σ max(0, ΔE)", "tab:pink"),
                 ("energy_dissipated", "dissipated: Σ max(0, −ΔE)", "tab:gray"))


def energy(summary_path, png_path):
    """The energy audit of one run (magsim-scene's summary.json, engine/energy.hpp): K, U_g,
    the cumulative magnetic and contact work (and the eddy-current loss's, where a run has one),
    the co-energy U*, the total E = K + U_g + U* and what the steps created and dissipated of it
    over time (offsets removed so that every curve starts at 0 except K), and below,
    the power of the magnetic forces and of the contacts between frames (J/s): where the
    energy of scattered bodies comes from."""
    with open(summary_path) as f:
        s = json.load(f)
    ser = s.get("series", {})
    if "energy_kinetic" not in ser:
        print(f"charts: {summary_path} has no energy series (older magsim-scene?)", file=sys.stderr)
        sys.exit(1)
    t = ser["time"]
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(9, 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 2]})
    for key, label, color in ENERGY_SERIES:
        if key not in ser or (key == "energy_eddy_work" and not any(ser.get(key, []))):
            continue  # no eddy loss in this run (or a summary from before the series existed)
        tt, y = t, ser[key]
        if key in ("energy_magnetic", "energy_total"):
            # U* is known from the first step on (the frame at t = 0 holds 0)
            tt, y = t[1:], y[1:]
        if key in ("energy_gravitational", "energy_magnetic", "energy_total") and y:
            y = [v - y[0] for v in y]
        ax.plot(tt, y, label=label, color=color)
    ax.axhline(0, color="black", linewidth=0.5)
    ax.set_ylabel("J")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    e = s.get("energy", {})
    ax.set_title(f"{s.get('scene')} {s.get('method')} ({s.get('force_model', '?')} force): energy audit "
                 f"(final W_mag {e.get('magnetic_work', float('nan')):.3g} J, "
                 f"W_c {e.get('contact_work', float('nan')):.3g} J, K {e.get('kinetic', float('nan')):.3g} J; "
                 f"created {e.get('created', float('nan')):.3g} J, dissipated {e.get('dissipated', float('nan')):.3g} J)",
                 fontsize=9)
    for key, label, color in (("energy_magnetic_work", "magnetic", "tab:red"),
                              ("energy_contact_work", "contacts", "tab:green"),
                              ("energy_eddy_work", "eddy-current loss", "tab:orange")):
        if key == "energy_eddy_work" and not any(ser.get(key, [])):
            continue
        y = ser[key]
        p = [(y[i] - y[i - 1]) / (t[i] - t[i - 1]) for i in range(1, len(t)) if t[i] > t[i - 1]]
        tm = [0.5 * (t[i] + t[i - 1]) for i in range(1, len(t)) if t[i] > t[i - 1]]
        ax2.plot(tm, p, label=f"power of the {label}", color=color)
    ax2.axhline(0, color="black", linewidth=0.5)
    ax2.set_yscale("symlog", linthresh=1e-3)
    ax2.set_xlabel("simulated time (s)")
    ax2.set_ylabel("W (J/s), between frames")
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
    print(f"charts: written {png_path}")


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "energy":
        if len(sys.argv) != 4:
            print("usage: charts.py energy SUMMARY.json OUT.png", file=sys.stderr)
            sys.exit(2)
        if not os.path.isfile(sys.argv[2]):
            print(f"charts: {sys.argv[2]} is not a file", file=sys.stderr)
            sys.exit(2)
        energy(sys.argv[2], sys.argv[3])
        return
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) == 2 else 2)
    out = sys.argv[1]
    if not os.path.isdir(out):
        print(f"charts: {out} is not a directory", file=sys.stderr)
        sys.exit(2)
    for f in (fig8, fig9, fig10, speed, snapshot_speed, tolerance, bench, near_field_cost,
              near_field_tradeoff):
        f(out)
    print(f"charts: written to {out}")


if __name__ == "__main__":
    main()
