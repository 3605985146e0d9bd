#!/usr/bin/python3
"""tools/reference/near_field_flux_fit.py — the fit of the engine's near-field pair model with
the contact's saturation driven by the balls' own flux (magnetics/near_field.hpp), on axial
chains, against the finite-element tables: kappa and q on the pair training half, beta on
the 3- and 4-chains, and the check on the rest (pair check half, 5- and 7-chains at
g = 0.003a, 3- and 5-chains at 0.01a and 0.03a).

    /usr/bin/python3 tools/reference/near_field_flux_fit.py [--fem tools/reference/data/near_field_fem.csv]
        [--chains tools/reference/data/near_field_fem_chains.csv] [--no-fit] [--curve tanh|sphere]
        [--widen sum|blend [--fit-p]]

The model, on the axis (every moment along z; M in Ms, moments m = V Ms M):
    U(M; z)/mu0 = sum V Ms^2 Psi(M_i) - sum m_i H0 - sum_{i<j} m_i m_j K_ij(z, M),
    K_ij = 2/(4 pi d^3) + nu^-beta S(g) Dt(G)/a^3,   G = g_e(g) + kappa h^q,
    h = zbar / (3 sqrt(1 - zbar^2)),   zbar = (M_i + M_j)/2,
Psi' = atanh(M)/3 (the engine's curve tanh(3H/Ms)), nu the contact count of
near_field_widen_trials.py (1 for a lone pair, 1.5 at a chain's end, 2 inside). M solves
dU/dM = 0 (not M = f(H0 + K m): K depends on M; solved for atanh M, the interaction's
M-derivative by central differences), and the forces are -dU/dz at fixed M (the envelope
theorem, by central differences). `--no-fit` evaluates the engine's
constants only. `--curve sphere` swaps the engine's curve for the law of a sphere of the
reference's own bulk iron, M = Ms tanh(999 (H - M/3)/Ms) (Psi' = atanh(M)/999 + M/3); its U
is not convex in M near Ms, so M is the least-U stationary point from four starts. `--widen
blend` swaps G = g_e + kappa h^q for the blend G = (1 - lambda) g_e + ((lambda g_e)^p +
(kappa h^q)^p)^(1/p), p = 4, and fits lambda with kappa and q (the engine's iron balls;
`--fit-p` fits p too). Candidate C (the model before: h = H0/Ms, G = g_e + kappa nu^gamma h^q) is
evaluated beside it on the same chains."""
import argparse
import math
import os
import sys
import warnings

import numpy as np
from scipy.optimize import brentq, fsolve, minimize

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import near_field_common as nfcommon  # noqa: E402
import near_field_fade as nf  # noqa: E402
import near_field_widen_trials as wt  # noqa: E402

A, MS, MU0, V = nf.A, nf.MS, nf.MU0, nf.V
ENGINE = (0.3425, 1.277, 0.4)  # kappa, q, beta (magnetics/near_field.hpp)
CANDIDATE_C = (0.553, 1.22, 0.4, 1.0)  # kappa, q, beta, gamma with h = H0/Ms
G_TAIL = 2.2
DT_TAIL = float(nf.SPLINE(math.log(G_TAIL)))
LAMBDA = float(nf.SPLINE(math.log(G_TAIL), 1)) / DT_TAIL
CHI = 999.0  # the reference's iron: mu_r,initial 1000
CURVE = "tanh"  # the balls' curve: tanh = the engine's eq. 10; sphere = the reference's iron


def widen_sum(ge, w0):
    """eq. 10's widened gap: G = g_e + w0, w0 = kappa h^q."""
    return ge + w0


def widen_blend(lam, p=4.0):
    """The iron's widened gap (magnetics/near_field.hpp, PairWidening):
    G = (1 - lam) g_e + ((lam g_e)^p + w0^p)^(1/p), p = 4 in the engine; dG/dg_e >= 1 - lam > 0."""
    def widen(ge, w0):
        a = lam * ge
        big, small = max(a, w0), min(a, w0)
        return (1.0 - lam) * ge + big * (1.0 + (small / big) ** p) ** (1.0 / p)
    return widen


WIDEN = widen_sum
ENGINE_BLEND = (0.4274, 1.470, 0.4, 0.3876, 4.0)  # kappa, q, beta, lambda, p: Curve::Iron


def psi(M):
    """The curve's stored energy over Ms^2 (the integral of f^-1(M)/Ms): eq. 10's tanh(3H/Ms),
    or a sphere of the reference's bulk iron, M = Ms tanh(chi (H - M/3)/Ms), whose
    f^-1(M)/Ms = atanh(M)/chi + M/3."""
    lg = M * np.arctanh(M) + 0.5 * np.log1p(-M * M)
    return lg / 3.0 if CURVE == "tanh" else lg / CHI + M * M / 6.0


def psi_prime_of_u(u):
    """f^-1(M)/Ms at M = tanh u."""
    return u / 3.0 if CURVE == "tanh" else u / CHI + np.tanh(u) / 3.0


def dt_of(G):
    """Dt a^3 at the widened gap, the engine's power tail beyond the table's last node."""
    return float(nf.SPLINE(math.log(G))) if G <= G_TAIL else DT_TAIL * (G / G_TAIL) ** LAMBDA


def flux_field(zeta):
    z = min(max(zeta, 0.0), 1.0 - 1e-9)
    return z / (3.0 * math.sqrt(1.0 - z * z))


def kmat(z, M, par, h0=None):
    """K (1/m^3). par = (kappa, q, beta) with h from M, or (kappa, q, beta, gamma) with h = h0."""
    n = len(z)
    gg = np.abs(z[:, None] - z[None, :]) / A - 2.0
    sc = np.array([[wt.step(gg[i, j], 0.5, 1.0) if i != j else 0.0 for j in range(n)] for i in range(n)])
    cnt = sc.sum(1)
    K = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1, n):
            k = 2.0 / (4 * math.pi * abs(z[i] - z[j]) ** 3)
            S, _ = nf.switch(gg[i, j])
            if S > 0:
                nu = max(1.0, 1.0 + 0.5 * (cnt[i] + cnt[j]) - sc[i, j])
                ge, _ = nf.g_eff(gg[i, j])
                if h0 is None:
                    kappa, q, beta = par
                    G = WIDEN(ge, kappa * flux_field(0.5 * (abs(M[i]) + abs(M[j]))) ** q)
                else:
                    kappa, q, beta, gamma = par
                    G = ge + kappa * nu ** gamma * h0 ** q
                k += nu ** -beta * S * dt_of(G) / A ** 3
            K[i, j] = K[j, i] = k
    return K


def energy(z, M, h0, par, applied, stored=True):
    """U/mu0 (A^2 m); without the curve's stored energy (constant in z at fixed M) if not stored."""
    m = V * MS * M
    K = kmat(z, M, par, h0 if applied else None)
    return (V * MS * MS * np.sum(psi(M)) if stored else 0.0) - np.sum(m) * h0 * MS - 0.5 * m @ K @ m


def chain(n, gap, h0, par, applied=False):
    """(z forces on every ball, N; the chain's moment, A m^2)."""
    z = (np.arange(n) - 0.5 * (n - 1)) * (2.0 + gap) * A
    start = par if applied else (par[0], par[1], par[2], 0.0)  # h = H0/Ms: the starting point
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        M = fsolve(lambda M: M - np.tanh(3.0 * (h0 * MS + kmat(z, M, start, h0) @ (V * M * MS)) / MS),
                   np.full(n, min(0.9, 3 * h0)), xtol=1e-13)
        if not applied:
            # dU/dM_i/(V Ms^2) = atanh(M_i)/3 - h0 - d(1/2 m K m)/dM_i/(V Ms^2) = 0, solved for
            # u = atanh(M) (well scaled up to saturation); the interaction's derivative by central
            # differences in M
            def residual(u):
                M = np.tanh(u)
                out = psi_prime_of_u(u) - h0
                for i in range(n):
                    e = 1e-7
                    Mp, Mm = M.copy(), M.copy()
                    Mp[i] += e
                    Mm[i] -= e
                    mp, mm = V * MS * Mp, V * MS * Mm
                    dE = 0.5 * (mp @ kmat(z, Mp, par) @ mp - mm @ kmat(z, Mm, par) @ mm) / (2 * e)
                    out[i] -= dE / (V * MS * MS)
                return out
            starts = [np.arctanh(np.clip(M, 1e-12, 1 - 1e-12))]
            if CURVE == "sphere":
                # U is not convex in M on the sphere curve near Ms (its f^-1 is stiff only as
                # 1/chi in u): start from lone spheres at H0 and at a few raised fields, and keep
                # the stationary point of least U
                starts = [np.full(n, brentq(lambda w: psi_prime_of_u(w) - hh, 0.0, CHI * (hh + 1.0)))
                          for hh in (h0, 1.1 * h0, 1.3 * h0, 2.0 * h0)]
            found = []
            for u0 in starts:
                u, _, ier, msg = fsolve(residual, u0, xtol=1e-13, full_output=True)
                if ier == 1 or np.max(np.abs(residual(u))) <= 1e-9:
                    found.append((energy(z, np.tanh(u), h0, par, False), tuple(u)))
            if not found:
                raise RuntimeError(f"no stationary magnetization for N {n}, g {gap}, H0 {h0}: {msg}")
            M = np.tanh(np.array(min(found)[1]))
    F = -MU0 * np.array(nfcommon.central_z(z, lambda zz: energy(zz, M, h0, par, applied, False), 1e-7 * A))
    return F, float(np.sum(V * MS * M))


def ratios(cells, keys, par, applied=False):
    out = {}
    for key in keys:
        F, mom = chain(*key, par, applied)
        c = cells[key]
        top = max(c["F"])
        out[key] = {"end": F[top] / c["F"][top], "moment": mom / c["moment"],
                    "mid": F[top - 1] / c["F"][top - 1] if (top - 1) in c["F"] else None}
    return out


def fit_beta(cells, chain_train, kappa, q):
    """beta from 0, 0.1, ..., 1 by the 3- and 4-chains' end balls and moments; a beta at which a
    chain has no stationary magnetization is skipped."""
    def chain_loss(b):
        try:
            return wt.ssq(ratios(cells, chain_train, (kappa, q, b)), ("end", "moment"))
        except RuntimeError:
            return math.inf
    return min((chain_loss(b), b) for b in np.arange(0.0, 1.01, 0.1))[1]


def fit_blend(cells, train, chain_train, p_fixed=None):
    """kappa, q, lambda (and p unless p_fixed) on the pair training half (three Nelder-Mead
    starts; lambda in (0, 1) and p > 1 through their logistic and exp), then beta on the 3- and
    4-chains: ((kappa, q, beta), (lambda, p))."""
    global WIDEN

    def unpack(x):
        p = p_fixed if p_fixed is not None else 1.0 + math.exp(x[3])
        return math.exp(x[0]), x[1], 1.0 / (1.0 + math.exp(-x[2])), p

    def loss(x):
        global WIDEN
        kappa, q, lam, p = unpack(x)
        if not 0.3 < q < 3:
            return 1e9
        WIDEN = widen_blend(lam, p)
        try:
            return wt.ssq(ratios(cells, train, (kappa, q, 0.4)))
        except RuntimeError:  # no stationary magnetization found at this trial point
            return 1e9
    starts = ([math.log(0.59), 1.3, 0.0, 0.0], [math.log(0.74), 1.5, 1.0, 1.0], [math.log(0.4), 1.2, -1.0, -1.0])
    if p_fixed is not None:
        starts = tuple(x0[:3] for x0 in starts)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        best = min((minimize(loss, x0, method="Nelder-Mead", options={"xatol": 1e-3, "fatol": 1e-5, "maxiter": 400})
                    for x0 in starts), key=lambda res: res.fun)
    kappa, q, lam, p = unpack(best.x)
    WIDEN = widen_blend(lam, p)
    beta = fit_beta(cells, chain_train, kappa, q)
    print(f"fitted: kappa {kappa:.4g}, q {q:.4g}, lambda {lam:.4g}, p {p:.4g} (pair training half), beta {beta:.1f} "
          f"(3- and 4-chains at 0.003a); the engine's iron has {ENGINE_BLEND}")
    return (kappa, q, beta), (lam, p)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fem", default=os.path.join(HERE, "data", "near_field_fem.csv"))
    ap.add_argument("--chains", default=os.path.join(HERE, "data", "near_field_fem_chains.csv"))
    ap.add_argument("--no-fit", action="store_true", help="the engine's constants only")
    ap.add_argument("--curve", choices=("tanh", "sphere"), default="tanh",
                    help="the balls' curve: tanh (the engine's eq. 10) or sphere (the reference's bulk iron)")
    ap.add_argument("--widen", choices=("sum", "blend"), default="sum",
                    help="the widened gap: sum (g_e + kappa h^q, eq. 10's balls) or blend (lambda fitted "
                         "too, p = 4 as in the engine; the engine's iron balls)")
    ap.add_argument("--fit-p", action="store_true", help="with --widen blend: fit the exponent p too")
    args = ap.parse_args(argv)
    global CURVE, WIDEN
    CURVE = args.curve
    cells = nf.load_fem(args.fem)
    cells.update(nf.load_fem(args.chains))
    pairs = sorted(k for k in cells if k[0] == 2)
    gaps = sorted({k[1] for k in pairs}, reverse=True)
    fields = sorted({k[2] for k in pairs})
    train = [k for k in pairs if (gaps.index(k[1]) + fields.index(k[2])) % 2 == 0]
    chains = sorted(k for k in cells if k[0] > 2)
    chain_train = [c for c in chains if c[1] == 0.003 and c[0] in (3, 4)]
    par, blend_name = ENGINE, ""
    if args.widen == "blend":
        par, lam_p = ENGINE_BLEND[:3], ENGINE_BLEND[3:]
        WIDEN = widen_blend(*lam_p)
        if not args.no_fit:
            par, lam_p = fit_blend(cells, train, chain_train, None if args.fit_p else 4.0)
        blend_name = f", lambda {lam_p[0]:.4g}, p {lam_p[1]:.4g}"
    elif not args.no_fit:
        def loss(x):  # beta does not enter a lone pair (nu = 1)
            return 1e9 if not 0.3 < x[1] < 3 else wt.ssq(ratios(cells, train, (math.exp(x[0]), x[1], 0.4)))
        best = min((minimize(loss, x0, method="Nelder-Mead", options={"xatol": 1e-3, "fatol": 1e-5, "maxiter": 200})
                    for x0 in ([math.log(0.553), 1.22], [math.log(0.3), 1.0])), key=lambda res: res.fun)
        kappa, q = math.exp(best.x[0]), best.x[1]
        par = (kappa, q, fit_beta(cells, chain_train, kappa, q))
        print(f"fitted: kappa {par[0]:.4g}, q {par[1]:.4g} (pair training half), beta {par[2]:.1f} "
              f"(3- and 4-chains at 0.003a); the engine has {ENGINE}")
    name = f"flux (kappa {par[0]:.4g}, q {par[1]:.4g}, beta {par[2]:.1f}{blend_name})"
    wt.print_pairs(name, ratios(cells, pairs, par), gaps, fields, train)
    wt.print_chains(name + "; training: N = 3, 4 at 0.003a", ratios(cells, chains, par), chains)
    wt.print_chains("candidate C (h = H0/Ms)", ratios(cells, chains, CANDIDATE_C, applied=True), chains)
    return 0


if __name__ == "__main__":
    sys.exit(main())
