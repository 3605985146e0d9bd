#!/usr/bin/python3
"""tools/reference/near_field_fade.py — a Python prototype of the engine's near-field pair
model on axial chains (balls on the field axis, H0 along it), with its saturation treatment
replaceable, fitted to the finite-element table (near_field_fem.csv) on a training half and
checked on the other half.

    /usr/bin/python3 tools/reference/near_field_fade.py [--fem tools/reference/data/near_field_fem.csv]

The model (magnetics/PHYSICS.md, "The near field"), restricted to the axis: every moment is
along z, ball i feels
    H_i = H0 + sum_j K(d_ij) m_j,   K(d) = 2/(4 pi d^3) + C(g, h)/a^3,
with C the coupling correction: the engine's is C = S(g) phi(h) Dt(g), Dt the exact axial
correction at mu_r = 1000 (magnetics/near_field_table.inc, a natural cubic spline in ln g_e),
g_e the softplus contact gap, S the cut-off step, phi = 1/(1 + (h/0.0138)^1.2), h = H0/Ms;
m_i = V Ms tanh(3 H_i/Ms) (the engine's curve). The pair energy is
E = -mu0 sum_{i<j} m_i m_j K(d_ij), so by the envelope theorem the force on ball i is
    F_i = mu0 sum_j m_i m_j K'(d_ij) sign(z_i - z_j)
(-grad U*, the classic force), K' including dC/dg. With the engine's C it reproduces magsolve
--near-field pair to 4e-6.

Candidates (the contact saturates where the gap's flux density reaches Ms):
  A. the engine's fade with its scale at the contact's saturation field, phi =
     1/(1 + (h/(k h_s(g)))^p), h_s = 1/E(g) the applied field at which the linear gap field at
     the axis reaches Ms (E from axisym_fem.py's linear solution). Its dphi/dg term repels.
  B. the saturated contact as a wider gap: C = S(g) Dt(G), G = g_e(g) + kappa h^q. The iron
     cannot carry much more than mu0 Ms, so the part of the contact whose linear field would
     exceed Ms acts as air: a gap widened by a length that grows with the applied field.
     dG/dg > 0 and Dt falls with the gap, so C always attracts; kappa, q are fitted.
  C. B with the contact count (counted_correction): fitted on the 3-chains, checked on the
     5-chains.
The fits use a checkerboard over gap x field (training: gap index + field index even),
least squares of ln(model/FEM)."""
import argparse
import csv
import math
import os
import re
import sys

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import minimize, fsolve

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import near_field_common as nfcommon  # noqa: E402

A, MS, MU0 = 5e-3, 1.6e6, 4e-7 * math.pi
V = 4.0 / 3.0 * math.pi * A ** 3
G_M, G_S = 1.5e-3, 5e-4  # contact gap and its softplus width (near_field.hpp)


def load_table(mu_index=4):
    """The axial coupling corrections Dt a^3 at mu_r = 1000 (row 4) and the spline in ln g."""
    src = open(os.path.join(HERE, "..", "..", "magnetics", "near_field_table.inc")).read()
    gmin = float(re.search(r"kTableGapMin = ([0-9.eE+-]+)", src).group(1))
    gmax = float(re.search(r"kTableGapMax = ([0-9.eE+-]+)", src).group(1))
    body = src[src.index("kTableAxial"):src.index("kTableTransverse")]
    rows = re.findall(r"\{([^{}]*)\}", body)
    vals = np.array([float(v) for v in rows[mu_index].replace("\n", " ").split(",") if v.strip()])
    x = np.linspace(math.log(gmin), math.log(gmax), len(vals))
    return CubicSpline(x, vals, bc_type="natural")


SPLINE = load_table()


def g_eff(g):
    x = (g - G_M) / G_S
    sp = x + math.log1p(math.exp(-x)) if x > 0 else math.log1p(math.exp(x))
    d = 1.0 / (1.0 + math.exp(-x))
    return G_M + G_S * sp, d


def switch(g):
    s = g - 1.0
    if s <= 0:
        return 1.0, 0.0
    if s >= 1:
        return 0.0, 0.0
    return 1.0 - s ** 3 * (10 - 15 * s + 6 * s * s), -30.0 * s * s * (1 - s) ** 2


def coupling(g):
    """Dt a^3 and its derivative in g."""
    ge, dge = g_eff(g)
    x = math.log(ge)
    return float(SPLINE(x)), float(SPLINE(x, 1)) * dge / ge


def engine_fade(h, g):
    """phi, dphi/dg of the engine: 1/(1 + (h/0.0138)^1.2) at every gap."""
    return 1.0 / (1.0 + (h / 0.0138) ** 1.2), 0.0


def engine_correction(h, g):
    """c Dt a^3 and its derivative in g, the engine's form: S(g) phi(h) Dt(g)."""
    S, dS = switch(g)
    if S == 0.0:
        return 0.0, 0.0
    dt, ddt = coupling(g)
    phi, dphi = engine_fade(h, g)
    return S * phi * dt, (dS * phi + S * dphi) * dt + S * phi * ddt


def widened_correction(kappa, q):
    """The saturated contact as a wider gap: S(g) Dt(G), G = g_e(g) + kappa h^q (module doc).
    dG/dg = dg_e/dg > 0 and Dt falls with the gap, so the correction always attracts."""
    def corr(h, g):
        S, dS = switch(g)
        if S == 0.0:
            return 0.0, 0.0
        ge, dge = g_eff(g)
        G = ge + kappa * h ** q
        x = math.log(min(G, 2.2))
        dt = float(SPLINE(x))
        ddt = float(SPLINE(x, 1)) / G * dge if G < 2.2 else 0.0
        return S * dt, dS * dt + S * ddt
    return corr


def counted_correction(kappa, q, beta, gamma):
    """Candidate C: B seen by the neighbours. nb = the mean number of contacts (neighbours
    closer than a gap of a) of the pair's two balls: 1 for a lone pair, 1.5 for a chain's end
    contact, 2 inside it. C = nb^-beta S(g) Dt(g_e + kappa nb^gamma h^q): a ball's flux is
    shared between its contacts, and a contact inside a chain saturates earlier. Returns a
    factory: nb -> the (h, g) correction of one pair."""
    def for_pair(nb):
        inner = widened_correction(kappa * nb ** gamma, q)
        w = nb ** -beta

        def corr(h, g):
            c, dc = inner(h, g)
            return w * c, w * dc
        return corr
    for_pair.counted = True
    return for_pair


def K_and_dK(d, h, correction):
    """K(d) (1/m^3) and dK/dd (1/m^4) for balls at distance d."""
    g = d / A - 2.0
    K = 2.0 / (4 * math.pi * d ** 3)
    dK = -6.0 / (4 * math.pi * d ** 4)
    c, dc = correction(h, g)
    return K + c / A ** 3, dK + dc / A ** 4


def chain_model(n, gap, h0, correction):
    """(z forces on every ball, N; chain moment, A m^2) of n balls at gap `gap` (radii)."""
    z = (np.arange(n) - 0.5 * (n - 1)) * (2.0 + gap) * A
    Kmat = np.zeros((n, n))
    dKmat = np.zeros((n, n))
    counted = getattr(correction, "counted", False)
    contacts = [sum(1 for j in range(n) if j != i and abs(z[i] - z[j]) / A - 2.0 < 1.0) for i in range(n)]
    for i in range(n):
        for j in range(n):
            if i != j:
                corr = correction(0.5 * (contacts[i] + contacts[j])) if counted else correction
                Kmat[i, j], dKmat[i, j] = K_and_dK(abs(z[i] - z[j]), h0, corr)
    H0 = h0 * MS

    def res(M):
        H = H0 + Kmat @ (V * M * MS)
        return M - np.tanh(3.0 * H / MS)

    M = fsolve(res, np.full(n, min(1.0, 3 * h0)), xtol=1e-13)
    m = V * M * MS
    F = np.array([MU0 * sum(m[i] * m[j] * dKmat[i, j] * math.copysign(1.0, z[i] - z[j])
                            for j in range(n) if j != i) for i in range(n)])
    return F, float(np.sum(m))


def load_fem(path):
    rows = list(csv.DictReader(open(path)))
    cells = {}
    for r in rows:
        key = (int(r["N"]), float(r["gap_over_a"]), float(r["H0_over_Ms"]))
        cells.setdefault(key, {"moment": float(r["chain_moment_Am2"]), "F": {}})
        if float(r["Fz_N"]) != 0.0:
            cells[key]["F"][int(r["ball"])] = float(r["Fz_N"])
    return cells


def ratio_table(cells, correction, keys):
    out = {}
    for key in keys:
        n, g, h = key
        F, mom = chain_model(n, g, h, correction)
        c = cells[key]
        top = max(c["F"])
        out[key] = {"end": F[top] / c["F"][top], "moment": mom / c["moment"],
                    "mid": (F[top - 1] / c["F"][top - 1]) if (top - 1) in c["F"] else None}
    return out


def h_sat_of(gaps):
    """h_s(g) = 1/E(g): the applied field (in Ms) at which the gap's field at the axis reaches
    Ms in the linear pair (mu_r = 1000), from the FEM's linear solution: E = max |H| in the
    gap's air on the axis over H0."""
    sys.path.insert(0, HERE)
    import axisym_fem as af
    out = {}
    for g in gaps:
        ch = af.Chain(2, g)
        mesh = af.Mesh(ch, af.default_R(ch), 2.0)
        s = af.solve(mesh, 1.0, af.Material(1000.0, linear=True))
        cen = mesh.p[mesh.t].mean(axis=1)
        gapcells = (~mesh.iron) & (cen[:, 1] < 0.5 * g + 1e-9 + 0.0) & (cen[:, 0] < 0.5 * math.sqrt(g))
        H = np.hypot(s.grad[:, 0], s.grad[:, 1])
        E = float(np.max(H[gapcells])) if np.any(gapcells) else float(np.max(H[~mesh.iron]))
        out[g] = 1.0 / E
    return out


def print_chain_ratios(rc, chains):
    """One line per chain length: model / FEM of the end ball's force, the moment and (N > 3)
    the middle ball's force, at every field."""
    for n in sorted({c[0] for c in chains}):
        sel = [c for c in chains if c[0] == n]
        print(f"- chain of {n}, H0/Ms " + ", ".join(f"{c[2]:g}" for c in sel) + ": end ball "
              + ", ".join(f"{rc[c]['end']:.2f}" for c in sel) + "; moment "
              + ", ".join(f"{rc[c]['moment']:.2f}" for c in sel)
              + ("; middle ball " + ", ".join(f"{rc[c]['mid']:.2f}" for c in sel) if n > 3 else ""))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fem", default=os.path.join(HERE, "data", "near_field_fem.csv"))
    args = ap.parse_args(argv)
    cells = load_fem(args.fem)
    pairs = sorted(k for k in cells if k[0] == 2)
    gaps = sorted({k[1] for k in pairs}, reverse=True)
    fields = sorted({k[2] for k in pairs})
    # checkerboard: training cells have (gap index + field index) even
    train = [k for k in pairs if (gaps.index(k[1]) + fields.index(k[2])) % 2 == 0]
    check = [k for k in pairs if k not in train]
    chains = sorted(k for k in cells if k[0] > 2)

    hs = h_sat_of(gaps)
    print("h_s(g) = 1/E(g), the applied field at which the contact's gap field reaches Ms (linear, mu_r = 1000):")
    print("| g/a | " + " | ".join(f"{g:g}" for g in gaps) + " |")
    print("|---" * (len(gaps) + 1) + "|")
    print("| h_s | " + " | ".join(f"{hs[g]:.3g}" for g in gaps) + " |")
    lg = np.log(np.array(gaps))
    lh = np.log(np.array([hs[g] for g in gaps]))
    hs_fit = np.polyfit(lg, lh, 1)  # ln h_s = a1 ln g + a0: a power law through the six gaps
    print(f"\npower law: h_s = {math.exp(hs_fit[1]):.4g} g^{hs_fit[0]:.3f}")

    def gap_scaled_correction(k, p):
        """Candidate A: the engine's form with the fade's scale at the contact's saturation
        field, phi = 1/(1 + (h/(k h_s(g)))^p), h_s the power law above."""
        def corr(h, g):
            S, dS = switch(g)
            if S == 0.0:
                return 0.0, 0.0
            ge, dge = g_eff(g)
            h0 = k * math.exp(hs_fit[1]) * ge ** hs_fit[0]
            dh0 = h0 * hs_fit[0] / ge * dge
            z = (h / h0) ** p
            phi = 1.0 / (1.0 + z)
            dphi = phi * phi * p * z / h0 * dh0
            dt, ddt = coupling(g)
            return S * phi * dt, (dS * phi + S * dphi) * dt + S * phi * ddt
        return corr

    def lsq(corr, keys):
        r = ratio_table(cells, corr, keys)
        return sum(math.log(v["end"]) ** 2 if v["end"] > 0 else 100.0 for v in r.values())

    k_a = 0.0138 / (math.exp(hs_fit[1]) * 0.003 ** hs_fit[0])  # the engine's h0 at g = 0.003a
    cand_a = gap_scaled_correction(k_a, 1.2)
    best = None
    for k0 in (1.0, 3.0, 10.0, 30.0):
        for q0 in (0.7, 1.0, 1.3):
            res = minimize(lambda x: lsq(widened_correction(math.exp(x[0]), x[1]), train),
                           [math.log(k0), q0], method="Nelder-Mead",
                           options={"xatol": 1e-3, "fatol": 1e-5, "maxiter": 300})
            if best is None or res.fun < best.fun:
                best = res
    kappa, q = math.exp(best.x[0]), best.x[1]
    print(f"\ncandidate B fitted on the training half ({len(train)} cells, least squares of ln ratio): "
          f"kappa = {kappa:.4g}, q = {q:.4g}")
    cand_b = widened_correction(kappa, q)
    for name, corr in (("engine (fade 1/(1 + (h/0.0138)^1.2) at every gap)", engine_correction),
                       (f"candidate A (fade scale k h_s(g), k = {k_a:.3g}, p = 1.2)", cand_a),
                       (f"candidate B (Dt at g_e + {kappa:.4g} h^{q:.3f})", cand_b)):
        print(f"\n{name}: pair model / FEM, two balls (T = training cell, C = check cell):\n")
        r = ratio_table(cells, corr, pairs)
        print("\n".join(nfcommon.gap_field_table(
            gaps, fields, lambda g, h: nfcommon.pair_mark(r[(2, g, h)]["end"]) + (" T" if (2, g, h) in train else " C"))))
        for part in (train, check):
            vals = [r[c]["end"] for c in part]
            inside = sum(0.85 <= v <= 1.15 for v in vals)
            print(f"- {'training' if part is train else 'check'}: {inside}/{len(vals)} in 0.85-1.15, "
                  f"range {min(vals):.2f}-{max(vals):.2f}")
        rc = ratio_table(cells, corr, chains)
        print_chain_ratios(rc, chains)
    # candidate C: B with the contact count, (beta, gamma) on a grid fitted to the 3-chains
    # (least squares of ln ratio of the end ball's force and the moment), checked on the 5-chains
    c3 = [c for c in chains if c[0] == 3]
    best = None
    for beta in (0.0, 0.2, 0.4, 0.5, 0.6, 0.7, 0.8, 1.0):
        for gamma in (0.0, 0.5, 1.0, 1.5, 2.0, 3.0):
            r = ratio_table(cells, counted_correction(kappa, q, beta, gamma), c3)
            ssq = sum(math.log(max(v[k], 1e-3)) ** 2 for v in r.values() for k in ("end", "moment"))
            if best is None or ssq < best[0]:
                best = (ssq, beta, gamma)
    _, beta, gamma = best
    print(f"\ncandidate C (B with nb^-{beta:g} and kappa nb^{gamma:g}; fitted on the 3-chains, "
          f"checked on the 5-chains; pairs are B's, nb = 1):")
    rc = ratio_table(cells, counted_correction(kappa, q, beta, gamma), chains)
    print_chain_ratios(rc, chains)
    return 0


if __name__ == "__main__":
    sys.exit(main())
