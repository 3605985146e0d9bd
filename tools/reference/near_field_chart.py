#!/usr/bin/python3
"""tools/reference/near_field_chart.py — the physical accuracy of the near-field models: the
engine's force (magsolve, classic, --near-field dipole and pair) against our references, as
CSV and PNG charts (headless: matplotlib's Agg backend).

    /usr/bin/python3 tools/reference/near_field_chart.py --out DIR [--magsolve PATH] [--fem CSV] [--curve tanh|iron]

1. Linear (weak field, H0 = 1e-4 Ms): force / exact two-sphere force (two_spheres.py, same
   mu_r) against the gap, axial and transverse: DIR/near_field_linear.csv.
2. Nonlinear pairs (axial): force / finite-element force at every gap x field cell of the FEM
   table (near_field_fem.csv, axisym_fem.py), T or C for the training or check half of the
   checkerboard (gap index + field index even: training): DIR/near_field_cells.csv.
   1 and 2 are DIR/near_field.png (curves, and one heat map per model).
3. Chains of 3 and 5 at g = 0.003a: the end ball's force, the middle ball's (the ball next to
   the centre of the 5-chain) and the chain's moment / FEM against H0/Ms:
   DIR/near_field_chains.csv and .png.
4. One row per model, the accuracy axis: DIR/near_field_accuracy.csv (cells in their marks,
   median and worst |ratio - 1|). tools/scripts/charts.py draws it beside the cost per step
   (bench --near-field-cost) as near_field_tradeoff.png.
Balls of radius 5 mm, Ms = 1.6e6 A/m, mu_r = 1000; magsolve --method exact (the Newton
solution of the tanh curve; --curve iron: of a sphere of the reference's own iron). Forces on the upper ball; ratios of 1 are exact. Marks:
0.85-1.15 for pairs, 25 % for the chains' end ball and moment, 5 % in the linear range."""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import near_field_common as nfcommon  # noqa: E402
import near_field_compare as nfc_compare  # noqa: E402
import two_spheres as ts  # noqa: E402

A, MS, MU_R = 5e-3, 1.6e6, 1000.0
MU0 = 4e-7 * math.pi
MODELS = ("dipole", "pair")
PAIR_BAND = (0.85, 1.15)
CHAIN_MARK = 0.25
LINEAR_MARK = 0.05
ISSUE_GAPS = (0.003, 0.3)  # the pair mark's range of gaps
HERE = os.path.dirname(os.path.abspath(__file__))


def magsolve_force(magsolve, gap, H0, model, tmp, curve="tanh"):
    """z force (N) on the upper of two balls at gap g (radii) in the field H0 (A/m vector), on
    magsolve's --curve (tanh: eq. 10; iron: a sphere of the reference's bulk iron)."""
    d = (2.0 + gap) * A
    V = 4.0 / 3.0 * math.pi * A ** 3
    case = {"external_field": list(H0),
            "moments": [{"kind": "induced", "position": [0, 0, -d / 2], "volume": V, "Ms": MS},
                        {"kind": "induced", "position": [0, 0, d / 2], "volume": V, "Ms": MS}]}
    path = os.path.join(tmp, "case.json")
    with open(path, "w") as fh:
        json.dump(case, fh)
    out = subprocess.run([magsolve, path, "--method", "exact", "--force-model", "classic",
                          "--near-field", model, "--mu-r", str(MU_R), "--curve", curve],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["moments"][1]["F_model"][2]


def linear_rows(magsolve, curve="tanh"):
    """[field, g, exact force (mu0 H0^2 a^2), dipole / exact, pair / exact] at H0 = 1e-4 Ms."""
    rows = []
    H = 1e-4 * MS
    unit = MU0 * H * H * A * A
    with tempfile.TemporaryDirectory() as tmp:
        for field in ts.FIELDS:
            H0 = (0, 0, H) if field == "axial" else (H, 0, 0)
            for g in ts.chart_gaps():
                exact, _ = ts.converged_force(MU_R, float(g), field, rtol=1e-7)
                row = [field, float(g), exact]
                for model in MODELS:
                    row.append(magsolve_force(magsolve, float(g), H0, model, tmp, curve) / unit / exact)
                rows.append(row)
    return rows


def cell_rows(compared):
    """The pair cells of near_field_compare.compare's rows, with the checkerboard's half."""
    pairs = [r for r in compared if r["N"] == 2]
    gaps = sorted({r["gap_over_a"] for r in pairs}, reverse=True)
    fields = sorted({r["H0_over_Ms"] for r in pairs})
    out = []
    for r in pairs:
        half = "T" if (gaps.index(r["gap_over_a"]) + fields.index(r["H0_over_Ms"])) % 2 == 0 else "C"
        out.append({"gap_over_a": r["gap_over_a"], "H0_over_Ms": r["H0_over_Ms"], "half": half,
                    "Fz_fem_N": r["Fz_fem_N"], "fem_rel_error_est": r["Fz_rel_error_est"],
                    **{f"{m}_over_fem": r[f"F_{m}_over_fem"] for m in MODELS}})
    return out, gaps, fields


def chain_rows(compared):
    """Per chain and field: the end ball's force, the middle ball's (5-chains) and the moment,
    each model / FEM."""
    out = []
    for n in sorted({r["N"] for r in compared if r["N"] > 2}):
        for h in sorted({r["H0_over_Ms"] for r in compared if r["N"] == n}):
            rs = [r for r in compared if r["N"] == n and r["H0_over_Ms"] == h]
            end = max(rs, key=lambda r: r["ball"])
            mid = min(rs, key=lambda r: r["ball"])
            for quantity, r, key in (("end ball", end, "F"), ("middle ball", mid, "F"), ("moment", end, "moment")):
                if quantity == "middle ball" and mid is end:
                    continue  # N = 3: the middle ball is the centre one, no force by symmetry
                out.append({"N": n, "H0_over_Ms": h, "quantity": quantity,
                            **{f"{m}_over_fem": r[f"{key}_{m}_over_fem"] for m in MODELS}})
    return out


def accuracy_rows(lin, cells, chains):
    """One row per model: how many reference cases meet their marks, and the error's size."""
    out = []
    for k, m in enumerate(MODELS):
        key = f"{m}_over_fem"
        inside = [c for c in cells if PAIR_BAND[0] <= c[key] <= PAIR_BAND[1]]
        issue = [c for c in cells if ISSUE_GAPS[0] <= c["gap_over_a"] <= ISSUE_GAPS[1]]
        marked = [c for c in chains if c["quantity"] != "middle ball"]
        row = {"model": m,
               "pair_cells": len(cells),
               "pair_cells_in_band": len(inside),
               "pair_cells_g_0.003_0.3": len(issue),
               "pair_cells_g_0.003_0.3_in_band": sum(1 for c in issue if c in inside),
               "training_in_band": sum(1 for c in inside if c["half"] == "T"),
               "check_in_band": sum(1 for c in inside if c["half"] == "C"),
               "pair_min_ratio": min(c[key] for c in cells),
               "pair_max_ratio": max(c[key] for c in cells),
               "pair_median_abs_error": statistics.median(abs(c[key] - 1) for c in cells),
               "chain_marked": len(marked),
               "chain_marked_within_25pct": sum(1 for c in marked if abs(c[key] - 1) <= CHAIN_MARK),
               "chain_median_abs_error": statistics.median(abs(c[key] - 1) for c in marked),
               "chain_worst_abs_error": max(abs(c[key] - 1) for c in marked),
               "middle_ball_worst_abs_error": max((abs(c[key] - 1) for c in chains
                                                   if c["quantity"] == "middle ball"), default=float("nan"))}
        for field in ts.FIELDS:
            row[f"linear_{field}_worst_abs_error"] = max(abs(r[3 + k] - 1) for r in lin if r[0] == field)
        out.append(row)
    return out


def write_csv(path, rows):
    with open(path, "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        wr.writeheader()
        for r in rows:
            wr.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


def heat_map(ax, fig, cells, gaps, fields, model):
    """ratio model / FEM over gap x field, colour log2(ratio) in [-2, 2]; outside the band in
    bold, T/C in the corner."""
    import numpy as np
    key = f"{model}_over_fem"
    grid = np.full((len(gaps), len(fields)), np.nan)
    for c in cells:
        grid[gaps.index(c["gap_over_a"]), fields.index(c["H0_over_Ms"])] = c[key]
    im = ax.imshow(np.log2(np.clip(grid, 1e-3, None)), cmap="RdBu_r", vmin=-2, vmax=2, aspect="auto")
    for c in cells:
        i, j, v = gaps.index(c["gap_over_a"]), fields.index(c["H0_over_Ms"]), c[key]
        out = not PAIR_BAND[0] <= v <= PAIR_BAND[1]
        ax.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=8,
                fontweight="bold" if out else "normal", color="black")
        ax.text(j + 0.42, i - 0.42, c["half"], ha="right", va="top", fontsize=5, color="dimgray")
    ax.set_xticks(range(len(fields)))
    ax.set_xticklabels([f"{h:g}" for h in fields])
    ax.set_yticks(range(len(gaps)))
    ax.set_yticklabels([f"{g:g}" for g in gaps])
    ax.set_xlabel("H0 / Ms (axial)")
    ax.set_ylabel("g / a")
    n_in = sum(1 for c in cells if PAIR_BAND[0] <= c[key] <= PAIR_BAND[1])
    ax.set_title(f"{model} / FEM, two balls: {n_in}/{len(cells)} in 0.85–1.15 (bold: outside)", fontsize=9)
    cb = fig.colorbar(im, ax=ax, ticks=[-2, -1, 0, 1, 2])
    cb.ax.set_yticklabels(["0.25", "0.5", "1", "2", "4"])


def draw(out, lin, cells, gaps, fields, chains):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(14, 9))
    for ax, field in zip(axes[0], ts.FIELDS):
        sel = [r for r in lin if r[0] == field]
        for k, model in enumerate(MODELS):
            ax.plot([r[1] for r in sel], [r[3 + k] for r in sel], marker=".", label=model)
        ax.axhspan(1 - LINEAR_MARK, 1 + LINEAR_MARK, color="green", alpha=0.1, label="±5 %")
        ts.style_gap_axes(ax, field, "engine force / exact force", f"{field}, H0 = 1e-4 Ms (linear)")
    for ax, model in zip(axes[1], MODELS):
        heat_map(ax, fig, cells, gaps, fields, model)
    fig.suptitle(f"Two iron balls (a = 5 mm, mu_r = {MU_R:g}): one dipole each vs the pair model, "
                 "against the exact linear force and our finite-element force")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "near_field.png"), dpi=110)
    plt.close(fig)

    ns = sorted({c["N"] for c in chains})
    fig, axes = plt.subplots(1, len(ns), figsize=(6.5 * len(ns), 4.5), squeeze=False)
    colors = {"end ball": "tab:red", "middle ball": "tab:green", "moment": "tab:blue"}
    for ax, n in zip(axes[0], ns):
        for quantity, color in colors.items():
            sel = [c for c in chains if c["N"] == n and c["quantity"] == quantity]
            if not sel:
                continue
            for model, style in zip(MODELS, ("--", "-")):
                ax.plot([c["H0_over_Ms"] for c in sel], [abs(c[f"{model}_over_fem"]) for c in sel], style,
                        marker="o", ms=3, color=color, label=f"{quantity}, {model}")
        ax.axhline(1.0, color="grey", lw=0.8)
        ax.axhspan(1 - CHAIN_MARK, 1 + CHAIN_MARK, color="green", alpha=0.1, label="±25 %")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("H0 / Ms (along the chain)")
        ax.set_ylabel("|engine / finite element|")
        ax.set_title(f"chain of {n}, g = 0.003a (dashed: dipole, solid: pair)", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "near_field_chains.png"), dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", required=True)
    nfcommon.add_magsolve(p)
    p.add_argument("--fem", default=os.path.join(HERE, "data", "near_field_fem.csv"))
    nfcommon.add_curve(p)
    args = p.parse_args(argv)
    if nfcommon.magsolve_missing(args.magsolve, "near_field_chart.py"):
        return 2
    os.makedirs(args.out, exist_ok=True)
    lin = linear_rows(args.magsolve, args.curve)
    compared = nfc_compare.compare(args.fem, args.magsolve, args.curve)
    cells, gaps, fields = cell_rows(compared)
    chains = chain_rows(compared)
    acc = accuracy_rows(lin, cells, chains)

    with open(os.path.join(args.out, "near_field_linear.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["field", "gap_over_a", "F_exact_mu0H0^2a^2", "dipole_over_exact", "pair_over_exact"])
        for r in lin:
            w.writerow([r[0], f"{r[1]:.6g}", f"{r[2]:.10g}", f"{r[3]:.6g}", f"{r[4]:.6g}"])
    write_csv(os.path.join(args.out, "near_field_cells.csv"), cells)
    write_csv(os.path.join(args.out, "near_field_chains.csv"), chains)
    write_csv(os.path.join(args.out, "near_field_accuracy.csv"), acc)
    draw(args.out, lin, cells, gaps, fields, chains)

    for r in acc:
        print(f"{r['model']}: pair cells in 0.85-1.15: {r['pair_cells_in_band']}/{r['pair_cells']} "
              f"(g 0.003a-0.3a: {r['pair_cells_g_0.003_0.3_in_band']}/{r['pair_cells_g_0.003_0.3']}; "
              f"training {r['training_in_band']}, check {r['check_in_band']}), "
              f"ratio {r['pair_min_ratio']:.2f}-{r['pair_max_ratio']:.2f}, "
              f"median |ratio - 1| {r['pair_median_abs_error']:.3f}")
        print(f"  chains (end ball, moment): {r['chain_marked_within_25pct']}/{r['chain_marked']} within 25 %, "
              f"median |ratio - 1| {r['chain_median_abs_error']:.3f}, worst {r['chain_worst_abs_error']:.2f}; "
              f"middle ball worst {r['middle_ball_worst_abs_error']:.2f}")
        print(f"  linear (1e-4 Ms, {len(lin) // 2} gaps 0.003a-3a): worst |ratio - 1| axial "
              f"{r['linear_axial_worst_abs_error']:.3g}, transverse {r['linear_transverse_worst_abs_error']:.3g}")
    print(f"wrote near_field.png, near_field_chains.png and the CSVs in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
