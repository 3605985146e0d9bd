#!/usr/bin/python3
"""tools/reference/near_field_transverse.py — two iron balls with the field perpendicular to
their line of centres: the engine's force (magsolve --near-field dipole and pair) against the
exact linear two-sphere force (two_spheres.py, mu_r = 1000), and how far into the field the
linear solution stays a valid reference.

    /usr/bin/python3 tools/reference/near_field_transverse.py [--magsolve build/release/tools/magsolve]
        [--out tools/reference/data/near_field_transverse.csv] [--curve tanh|iron]

Each case: a = 5 mm, Ms = 1.6e6 A/m, balls at z = -+d/2, d = (2 + g) a, H0 = h Ms along x;
magsolve --method exact --force-model classic --mu-r 1000 (the Newton solution of the
engine's tanh curve and its classic force -grad U*). The exact force scales as H0^2, so the
ratio model / exact is the engine's departure from linear magnetostatics. The mark (the
pair model's transverse criterion) is 5 % at g = 0.3a, 0.1a and 0.01a in a weak field
(h = 1e-4 and 1e-3).

Validity of the linear reference at h: the iron's bulk law is M = Ms tanh(999 H/Ms), so the
linear solution is right where 999 |H_in| h stays small inside both balls. The largest
interior field |H_in|/H0 of the linear solution is found on a grid of the upper ball's
surface (just inside it) from its interior series phi_in = sum C_n (r/a)^n P_n^1 cos(az),
C_n = E_n + B_n (continuity of phi at r = a); h_lin is the field at which the bulk law's
M falls 1 % below linear there (1 - tanh x / x = 0.01, x = 0.1737). The same for the axial
field shows the contrast: there the gap concentrates the flux."""
import argparse
import csv
import math
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import near_field_chart as nfc  # noqa: E402
import near_field_common as nfcommon  # noqa: E402
import two_spheres as ts  # noqa: E402

A, MS, MU_R = 5e-3, 1.6e6, 1000.0
MU0 = 4e-7 * math.pi
GAPS = (0.3, 0.1, 0.03, 0.01, 0.003)
MARKED_GAPS = (0.3, 0.1, 0.01)
FIELDS = (1e-4, 1e-3, 1e-2, 3e-2, 0.1)
WEAK = (1e-4, 1e-3)
MARK = 0.05
X_ONE_PERCENT = 0.1737  # 1 - tanh(x)/x = 0.01


def interior_field_max(sol, n_theta=721, depth=1e-3, h=1e-6):
    """max |H_in| / H0 over the upper ball, sampled at r = (1 - depth) a, polar angles on
    [0, pi] and azimuths 0 and pi/2 (the field's plane and the one across it), by central
    differences of the interior series. Coordinates local to the upper ball's centre."""
    n = np.arange(sol.L + 1)
    C = sol.E + sol.B
    m = sol.m

    def phi(x, y, z):
        r = np.sqrt(x * x + y * y + z * z)
        rho = np.hypot(x, y)
        az = 1.0 if m == 0 else np.where(rho > 0, x / np.where(rho > 0, rho, 1.0), 1.0)
        P = ts.legendre(sol.L, m, z / r)
        powers = r[None, ...] ** n.reshape((-1,) + (1,) * r.ndim)
        return az * np.tensordot(C, powers * P, axes=(0, 0))

    best = 0.0
    th = np.linspace(1e-4, math.pi - 1e-4, n_theta)
    r = 1.0 - depth
    for az in (0.0, 0.5 * math.pi):
        x, y, z = r * np.sin(th) * math.cos(az), r * np.sin(th) * math.sin(az), r * np.cos(th)
        g = [(phi(x + h * e[0], y + h * e[1], z + h * e[2]) - phi(x - h * e[0], y - h * e[1], z - h * e[2]))
             / (2 * h) for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
        best = max(best, float(np.max(np.sqrt(g[0] ** 2 + g[1] ** 2 + g[2] ** 2))))
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    nfcommon.add_magsolve(ap)
    ap.add_argument("--out", default=os.path.join(here, "data", "near_field_transverse.csv"))
    nfcommon.add_curve(ap)
    args = ap.parse_args(argv)
    if nfcommon.magsolve_missing(args.magsolve, "near_field_transverse.py"):
        return 2
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for g in GAPS:
            exact, conv = ts.converged_force(MU_R, g, "transverse", rtol=1e-7)
            sol = ts.solve(MU_R, g, "transverse", conv[-1][0])
            hin = interior_field_max(sol)
            ax = ts.solve(MU_R, g, "axial", ts.converge(MU_R, g, "axial", rtol=1e-7)[0][-1][0])
            hin_ax = interior_field_max(ax)
            for h in FIELDS:
                H = h * MS
                unit = MU0 * H * H * A * A
                r = {"gap_over_a": g, "H0_over_Ms": h, "F_exact_mu0H0^2a^2": exact, "L_exact": conv[-1][0],
                     "Hin_max_over_H0": hin, "h_lin_1pct": X_ONE_PERCENT / ((MU_R - 1) * hin),
                     "Hin_max_over_H0_axial": hin_ax, "h_lin_1pct_axial": X_ONE_PERCENT / ((MU_R - 1) * hin_ax)}
                for model in nfc.MODELS:
                    f = nfc.magsolve_force(args.magsolve, g, (H, 0.0, 0.0), model, tmp, args.curve) / unit
                    r[f"F_{model}_mu0H0^2a^2"] = f
                    r[f"{model}_over_exact"] = f / exact
                rows.append(r)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        wr.writeheader()
        for r in rows:
            wr.writerow({k: (f"{v:.7g}" if isinstance(v, float) else v) for k, v in r.items()})

    print(f"transverse, model / exact linear force (upper ball; pair | dipole), mu_r = 1000, curve {args.curve}:\n")
    print("| g/a | exact (mu0 H0^2 a^2) | " + " | ".join(f"{h:g} Ms" for h in FIELDS) + " |")
    print("|---" * (len(FIELDS) + 2) + "|")
    worst = 0.0
    for g in GAPS:
        cells = []
        for h in FIELDS:
            r = next(r for r in rows if r["gap_over_a"] == g and r["H0_over_Ms"] == h)
            p, d = r["pair_over_exact"], r["dipole_over_exact"]
            marked = g in MARKED_GAPS and h in WEAK
            if marked:
                worst = max(worst, abs(p - 1))
            cell = f"{p:.4f} \\| {d:.3f}"
            cells.append(f"**{cell}**" if marked and abs(p - 1) > MARK else cell)
        ex = next(r for r in rows if r["gap_over_a"] == g)["F_exact_mu0H0^2a^2"]
        print(f"| {g:g} | {ex:+.5f} | " + " | ".join(cells) + " |")
    print("\nvalidity of the linear reference (largest interior field, upper ball):\n")
    print("| g/a | transverse max abs(H_in)/H0 | h_lin (1 %) | axial max abs(H_in)/H0 | h_lin (1 %), axial |")
    print("|---|---|---|---|---|")
    for g in GAPS:
        r = next(r for r in rows if r["gap_over_a"] == g)
        print(f"| {g:g} | {r['Hin_max_over_H0']:.4g} | {r['h_lin_1pct']:.3g} | "
              f"{r['Hin_max_over_H0_axial']:.4g} | {r['h_lin_1pct_axial']:.3g} |")
    ok = worst <= MARK
    print(f"\npair, weak field (h = {', '.join(f'{h:g}' for h in WEAK)}) at g/a = "
          f"{', '.join(f'{g:g}' for g in MARKED_GAPS)}: worst |ratio - 1| = {worst:.4f} "
          f"(mark {MARK:g}) [{'ok' if ok else 'MISSED'}]")
    print(f"wrote {args.out}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
