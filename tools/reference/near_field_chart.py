#!/usr/bin/python3
"""tools/reference/near_field_chart.py — two iron balls: the engine's force (magsolve, classic,
--near-field dipole and pair) against exact magnetostatics, as CSV and PNG charts.

    /usr/bin/python3 tools/reference/near_field_chart.py --out DIR [--magsolve PATH]

1. Linear (weak field, H0 = 1e-4 Ms): force / exact two-sphere force (two_spheres.py, same
   mu_r) against the gap, axial and transverse: near_field_linear.{csv,png}.
2. Nonlinear (axial, g = 0.003a): force / the finite-element force against H0/Ms:
   near_field_saturation.{csv,png}.
Balls of radius 5 mm, Ms = 1.6e6 A/m, mu_r = 1000; magsolve --method exact (the Newton
solution of the tanh curve). Forces on the upper ball; ratios of 1 are exact."""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import two_spheres as ts  # noqa: E402

A, MS, MU_R = 5e-3, 1.6e6, 1000.0
MU0 = 4e-7 * math.pi
# nonlinear axisymmetric finite-element forces, g = 0.003a, initial mu_r = 1000, tanh curve,
# in mu0 Ms^2 a^2 (the near-field issue's table)
FEM_H = (1e-4, 1e-3, 0.01, 0.03, 0.1, 0.2, 1 / 3, 0.5, 1, 3, 10)
FEM_F = (-2.936e-6, -2.818e-4, -0.01306, -0.05479, -0.2057, -0.3647, -0.4797, -0.5387, -0.5595, -0.5380, -0.5262)
MODELS = ("dipole", "pair")


def magsolve_force(magsolve, gap, H0, model, tmp):
    """z force (N) on the upper of two balls at gap g (radii) in the field H0 (A/m vector)."""
    d = (2.0 + gap) * A
    V = 4.0 / 3.0 * math.pi * A ** 3
    case = {"external_field": list(H0),
            "moments": [{"kind": "induced", "position": [0, 0, -d / 2], "volume": V, "Ms": MS},
                        {"kind": "induced", "position": [0, 0, d / 2], "volume": V, "Ms": MS}]}
    path = os.path.join(tmp, "case.json")
    with open(path, "w") as fh:
        json.dump(case, fh)
    out = subprocess.run([magsolve, path, "--method", "exact", "--force-model", "classic",
                          "--near-field", model, "--mu-r", str(MU_R)],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["moments"][1]["F_model"][2]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", required=True)
    p.add_argument("--magsolve", default="build/release/tools/magsolve")
    args = p.parse_args(argv)
    if not os.access(args.magsolve, os.X_OK):
        print(f"near_field_chart.py: {args.magsolve} is not an executable (build first)", file=sys.stderr)
        return 2
    os.makedirs(args.out, exist_ok=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows_lin, rows_sat = [], []
    with tempfile.TemporaryDirectory() as tmp:
        H = 1e-4 * MS
        unit = MU0 * H * H * A * A
        for field in ts.FIELDS:
            H0 = (0, 0, H) if field == "axial" else (H, 0, 0)
            for g in ts.chart_gaps():
                exact, _ = ts.converged_force(MU_R, float(g), field, rtol=1e-7)
                row = [field, float(g), exact]
                for model in MODELS:
                    row.append(magsolve_force(args.magsolve, float(g), H0, model, tmp) / unit / exact)
                rows_lin.append(row)
        unit = MU0 * MS * MS * A * A
        for h, fem in zip(FEM_H, FEM_F):
            row = [h, fem]
            for model in MODELS:
                row.append(magsolve_force(args.magsolve, 0.003, (0, 0, h * MS), model, tmp) / unit / fem)
            rows_sat.append(row)

    with open(os.path.join(args.out, "near_field_linear.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["field", "gap_over_a", "F_exact_mu0H0^2a^2", "dipole_over_exact", "pair_over_exact"])
        for r in rows_lin:
            w.writerow([r[0], f"{r[1]:.6g}", f"{r[2]:.10g}", f"{r[3]:.6g}", f"{r[4]:.6g}"])
    with open(os.path.join(args.out, "near_field_saturation.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["H0_over_Ms", "F_fem_mu0Ms^2a^2", "dipole_over_fem", "pair_over_fem"])
        for r in rows_sat:
            w.writerow([f"{r[0]:.6g}", f"{r[1]:.6g}", f"{r[2]:.6g}", f"{r[3]:.6g}"])

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for ax, field in zip(axes[:2], ts.FIELDS):
        sel = [r for r in rows_lin if r[0] == field]
        for k, model in enumerate(MODELS):
            ax.plot([r[1] for r in sel], [r[3 + k] for r in sel], marker=".", label=model)
        ts.style_gap_axes(ax, field, "engine force / exact force", f"{field}, H0 = 1e-4 Ms (linear)")
    ax = axes[2]
    for k, model in enumerate(MODELS):
        ax.plot([r[0] for r in rows_sat], [r[2 + k] for r in rows_sat], marker="o", label=model)
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.axhspan(0.85, 1.15, color="green", alpha=0.1, label="±15 %")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("H0 / Ms")
    ax.set_ylabel("engine force / finite-element force")
    ax.set_title("axial, g = 0.003a (nonlinear)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.suptitle(f"Two iron balls (a = 5 mm, mu_r = {MU_R:g}): one dipole each vs the pair model")
    fig.tight_layout()
    png = os.path.join(args.out, "near_field.png")
    fig.savefig(png, dpi=110)
    worst_lin = {m: max(abs(r[3 + k] - 1) for r in rows_lin) for k, m in enumerate(MODELS)}
    worst_sat = {m: max(abs(r[2 + k] - 1) for r in rows_sat) for k, m in enumerate(MODELS)}
    print(f"linear, worst |ratio - 1| over {len(rows_lin)} cases: " +
          ", ".join(f"{m} {worst_lin[m]:.3g}" for m in MODELS))
    print(f"nonlinear (g = 0.003a), worst |ratio - 1| over {len(rows_sat)} fields: " +
          ", ".join(f"{m} {worst_sat[m]:.3g}" for m in MODELS))
    print(f"wrote {png} and the CSVs in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
