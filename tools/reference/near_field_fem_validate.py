#!/usr/bin/python3
"""tools/reference/near_field_fem_validate.py — the checks of the finite-element reference
(axisym_fem.py), printed as markdown tables:

  1. linear law M = chi0 H (mu_r = 1000) against the exact two-sphere solution (two_spheres.py)
     at every gap of the table, mesh levels 1, 2, 4: force and moment;
  2. the tanh curve at g = 0.003a against the finite-element row the pair model was fitted
     to (near_field_chart.py's FEM_F), levels 1 and 2;
  3. the outer radius: R = 25 and 50 chain half lengths;
  4. the force as the co-energy derivative against the Maxwell stress;
  5. (--laws) the given row against two other knees of the same chi0 = 999, level 1: whether
     the curve's shape explains the difference;
  6. (--families) four cells of the table on two other mesh families at level 2 (the contact
     grading halved; the surface and far-field sizes halved) against the table's level 4.

    /usr/bin/python3 tools/reference/near_field_fem_validate.py [--skip-row] [--laws] [--families]"""
import argparse
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import axisym_fem as af  # noqa: E402
import near_field_chart as nfc  # noqa: E402
import two_spheres as ts  # noqa: E402

GAPS = (1.0, 0.3, 0.1, 0.03, 0.01, 0.003)


class Langevin(af.Material):
    """M = Ms L(3 chi0 H/Ms), L(x) = coth x - 1/x (initial slope chi0); co-energy beyond H^2/2:
    (Ms^2/(3 chi0)) ln(sinh x / x)."""

    def __init__(self, chi0=999.0):
        self.chi0, self.linear, self.c = chi0, False, 3.0 * chi0

    def _x(self, H):
        return np.maximum(self.c * H, 1e-8)

    def M(self, H):
        x = self._x(H)
        return np.where(x < 1e-3, x / 3, 1 / np.tanh(x) - 1 / x)

    def M_over_H(self, H):
        x = self._x(H)
        return np.where(x < 1e-3, self.c / 3 * (1 - x * x / 15), (1 / np.tanh(x) - 1 / x) / np.maximum(H, 1e-300))

    def dM(self, H):
        x = self._x(H)
        return np.where(x < 1e-3, self.c / 3 * (1 - x * x / 5), self.c * (1 / x ** 2 - 1 / np.sinh(np.minimum(x, 300.0)) ** 2))

    def w(self, H):
        x = self._x(H)
        return np.where(x < 1e-3, x * x / 6, x + np.log1p(-np.exp(-2 * x)) - math.log(2) - np.log(x)) / self.c


class FrohlichKennelly(af.Material):
    """M = chi0 H/(1 + chi0 H/Ms); co-energy beyond H^2/2: (Ms^2/chi0)(x - ln(1 + x)), x = chi0 H/Ms."""

    def __init__(self, chi0=999.0):
        self.chi0, self.linear = chi0, False

    def M(self, H):
        return self.chi0 * H / (1 + self.chi0 * H)

    def M_over_H(self, H):
        return self.chi0 / (1 + self.chi0 * H)

    def dM(self, H):
        return self.chi0 / (1 + self.chi0 * H) ** 2

    def w(self, H):
        x = self.chi0 * H
        return (x - np.log1p(x)) / self.chi0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--skip-row", action="store_true")
    ap.add_argument("--laws", action="store_true", help="also section 5 (about 1 min)")
    ap.add_argument("--families", action="store_true", help="also section 6 (about 4 min alone)")
    args = ap.parse_args(argv)
    t0 = time.time()
    lin = af.Material(1000.0, linear=True)
    print("1. Linear (M = 999 H), force on the upper ball and moment of the pair, FEM / exact - 1:\n")
    print("| g/a | exact F (mu0 H0^2 a^2) | level 1 | level 2 | level 4 | exact moment (H0 a^3) | level 1 | level 2 | level 4 |")
    print("|---|---|---|---|---|---|---|---|---|")
    for g in GAPS:
        fx, _ = ts.converged_force(1000.0, g, "axial", rtol=1e-9)
        mx = 2.0 * ts.converge(1000.0, g, "axial", rtol=1e-9)[1].moment
        ef, em = [], []
        for lev in (1.0, 2.0, 4.0):
            ch = af.Chain(2, g)
            mesh = af.Mesh(ch, af.default_R(ch), lev)
            s = af.solve(mesh, 1.0, lin)
            ef.append(af.force(mesh, s, 0) / fx - 1)
            em.append(af.moment(mesh, s) / mx - 1)
        print(f"| {g:g} | {fx:.6g} | " + " | ".join(f"{e:+.2e}" for e in ef) + f" | {mx:.6g} | "
              + " | ".join(f"{e:+.2e}" for e in em) + " |", flush=True)
    if not args.skip_row:
        print("\n2. tanh curve, g = 0.003a: F (mu0 Ms^2 a^2) against the given FEM row:\n")
        print("| H0/Ms | given | level 1 | level 2 | level 2 / given |")
        print("|---|---|---|---|---|")
        res = {}
        for lev in (1.0, 2.0):
            mesh, rows = af.run_case(2, 0.003, nfc.FEM_H, refine=lev)
            res[lev] = [r["forces"][0] for r in rows]
        for k, h in enumerate(nfc.FEM_H):
            print(f"| {h:.4g} | {nfc.FEM_F[k]:.4g} | {res[1.0][k]:.5g} | {res[2.0][k]:.5g} | "
                  f"{res[2.0][k] / nfc.FEM_F[k]:.3f} |", flush=True)
    print("\n3. Outer radius (linear, g = 0.1a, level 2): F / exact - 1\n")
    fx, _ = ts.converged_force(1000.0, 0.1, "axial", rtol=1e-9)
    for mult in (12.5, 25.0, 50.0):
        ch = af.Chain(2, 0.1)
        mesh = af.Mesh(ch, mult * ch.top, 2.0)
        s = af.solve(mesh, 1.0, lin)
        print(f"- R = {mult:g} x {ch.top:g} a: {af.force(mesh, s, 0) / fx - 1:+.2e} ({mesh.nodes} nodes)", flush=True)
    print("\n4. Co-energy derivative (nodes moved by +-0.01 g psi) against the Maxwell stress, level 2:\n")
    for n, g, h in ((2, 0.003, 0.01), (2, 0.1, 0.1), (5, 0.003, 0.03)):
        ch = af.Chain(n, g)
        mesh = af.Mesh(ch, af.default_R(ch), 2.0)
        s = af.solve(mesh, h)
        k = len(ch.centres) - 1
        fm = af.force(mesh, s, k)
        fc = af.coenergy_force(mesh, h, k, 0.01 * g, phi0=s.phi)
        print(f"- N = {n}, g = {g:g}a, H0 = {h:g} Ms, ball at z = {ch.centres[k]:.4g}a: Maxwell {fm:.8g}, "
              f"co-energy {fc:.8g}, relative {fc / fm - 1:+.2e}", flush=True)
    if args.laws:
        print("\n5. g = 0.003a, level 1: F / the given row for three knees of chi0 = 999:\n")
        print("| law | " + " | ".join(f"{h:.3g}" for h in nfc.FEM_H) + " |")
        print("|---" * (len(nfc.FEM_H) + 1) + "|")
        ch = af.Chain(2, 0.003)
        mesh = af.Mesh(ch, af.default_R(ch), 1.0)
        for name, mat in (("tanh", af.Material()), ("Langevin", Langevin()), ("Frohlich-Kennelly", FrohlichKennelly())):
            prev, out = None, []
            for h, fg in zip(nfc.FEM_H, nfc.FEM_F):
                s = af.solve(mesh, h, mat, phi0=None if prev is None else prev.phi * h / prev.H0)
                prev = s
                out.append(f"{af.force(mesh, s, 0) / fg:.3f}")
            print(f"| {name} | " + " | ".join(out) + " |", flush=True)
    if args.families:
        import csv
        path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "near_field_fem.csv")
        rows = list(csv.DictReader(open(path)))
        print("\n6. Other mesh families at level 2 against the table (level 4): F / table - 1\n")
        print("| N | g/a | H0/Ms | contact grading k = 0.06 | surface a/28, far growth 0.125 |")
        print("|---|---|---|---|---|")
        for n, g, h in ((2, 0.01, 0.03), (2, 0.003, 0.01), (2, 0.03, 0.1), (3, 0.003, 0.03)):
            ref = next(float(r["Fz_mu0Ms2a2"]) for r in rows if int(r["N"]) == n and float(r["gap_over_a"]) == g
                       and float(r["H0_over_Ms"]) == h and int(r["ball"]) == n - 1)
            ch = af.Chain(n, g)
            out = []
            for kw in ({"k": 0.06}, {"h_surf": 0.035, "q": 0.125}):
                mesh = af.Mesh(ch, af.default_R(ch), 2.0, **kw)
                prev = None
                for hh in (h / 10, h / 3, h):  # the table's continuation, shortened
                    prev = af.solve(mesh, hh, phi0=None if prev is None else prev.phi * hh / prev.H0)
                out.append(f"{af.force(mesh, prev, len(ch.centres) - 1) / ref - 1:+.1e} ({mesh.nodes} nodes)")
            print(f"| {n} | {g:g} | {h:g} | " + " | ".join(out) + " |", flush=True)
    print(f"\n({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
