#!/usr/bin/python3
"""tools/reference/two_spheres.py — exact linear magnetostatics of two identical spheres in a
uniform field: the reference that the one-dipole-per-ball model is held
against. Library and command line; numpy (Debian python3-numpy), matplotlib only for `chart`.

    /usr/bin/python3 tools/reference/two_spheres.py values
    /usr/bin/python3 tools/reference/two_spheres.py force --mu M --gap G --field axial|transverse [--L N]
    /usr/bin/python3 tools/reference/two_spheres.py chart --out DIR

Problem. Two spheres of radius a, relative permeability mu (mu = inf: the ideal sphere of
the engine's linear law M = 3H), centres at z = +d/2 (sphere 1, "upper") and z = -d/2
(sphere 2), d = 2a + g, in a uniform applied field H0: "axial" along z (the line of
centres; the spheres attract), "transverse" along x (they repel). Magnetostatics without
currents: H = -grad(phi), div(mu H) = 0, phi and mu d(phi)/dr continuous on each surface.

Units (no SI anywhere): lengths in a, fields in H0, phi in H0 a, moments in H0 a^3 (a moment
of value m is m * H0 * a^3 in A m^2 with H0 in A/m and a in m), forces in mu0 H0^2 a^2 (N).
Forces are the z component on the upper sphere: negative = attraction.

Method (multipole expansion about each centre). Azimuthal order m = 0 (axial) or m = 1
(transverse); P_n^m is the associated Legendre function WITHOUT the Condon-Shortley phase,
P_n^1(x) = sqrt(1 - x^2) dP_n/dx. Outside the spheres, near sphere i (local r, theta; the
azimuth phi_az is common),

    phi = sum_n [E^i_n (r/a)^n + B^i_n (a/r)^(n+1)] P_n^m(cos theta) cos(m phi_az),

where B^i_n is sphere i's own exterior series and E^i_n the regular part: the applied field
(axial phi0 = -z, transverse phi0 = -x = -r P_1^1 cos phi_az, so E0_n = -delta_{n1}) plus
the other sphere's exterior series re-expanded about centre i. Inside, phi = sum C_n (r/a)^n
P_n^m; continuity of phi and of mu d(phi)/dr at r = a give

    B_n = -gamma_n E_n,   gamma_n = n (mu - 1) / (mu n + n + 1)   (mu = inf: gamma_n = 1,
                                                                   the equipotential sphere).

Translation along the axis (Legendre's addition theorem for 1/|r_C + sigma d z_hat|
differentiated n - m times along z and m times along x): for a source centre S and a centre
C with C - S = sigma d z_hat (sigma = +-1), valid for r_C < d,

    (a/r_S)^(n+1) P_n^m(cos theta_S)
        = sum_{k>=m} sigma^(n-m) (-sigma)^(k-m) (n+k)! / ((n-m)! (k+m)!)
                     (a/d)^(n+k+1) (r_C/a)^k P_k^m(cos theta_C).

The factorials are taken as exp(lgamma(n+k+1) - lgamma(n-m+1) - lgamma(k+m+1)
+ (n+k+1) log(a/d)), so no factorial is ever formed. For sphere 1 the source is sphere 2,
sigma = +1. Mirror symmetry z -> -z (phi odd for the axial field, even for the transverse
one, P_n^m(-x) = (-1)^(n+m) P_n^m(x)) gives B^2_n = (-1)^(n+1) B^1_n in both cases, so with
x_n = B^1_n, n = 1..L (B_0 = 0 since gamma_0 = 0: each sphere carries no net flux),

    x_k + gamma_k sum_{n=1..L} (-1)^(n+1+k-m) (n+k)!/((n-m)!(k+m)!) (a/d)^(n+k+1) x_n
        = gamma_k delta_{k1},          k = 1..L,

one dense L x L system (numpy.linalg.solve), truncated at order L; convergence in L is
checked by doubling L.

Force on the upper sphere (vacuum Maxwell stress around it = the force mu0 int rho H_ext on
the magnetic charge that reproduces its exterior series, in the regular field E; derived
with (a/r)^(n+1) P_n = a^(n+1) (-1)^n / n! d^n/dz^n (1/r) and
(a/r)^(n+1) P_n^1 cos phi_az = a^(n+1) (-1)^n / (n-1)! d/dx d^(n-1)/dz^(n-1) (1/r)):

    axial:       Fz = -4 pi sum_k k E_k B_(k-1)
    transverse:  Fz = -2 pi sum_k (k+1) k (k-1) E_k B_(k-1)       (E, B of sphere 1).

Independent checks (all in this file, run by tests/tools/reference/two_spheres_test.py):
  * single sphere: moment 4 pi B_1 = 4 pi (mu - 1)/(mu + 2) (in H0 a^3);
  * far field: the dipole-dipole force of two such moments;
  * mu = inf, axial: the bispherical-coordinate solution (bispherical_moment): the pair's
    total moment in closed form and the force d/dd (1/2 mu0 H0 m_tot) at fixed H0;
  * the potential on a mu = inf sphere, summed directly from both exterior series and the
    applied field, is constant (surface_potential);
  * the force as the Maxwell stress integrated over the mid-plane z = 0 (midplane_force).

The dipole model (dipole_model): one point dipole per sphere at its centre, m = 4 pi
(mu - 1)/(mu + 2) a^3 H_local (mu = inf: m = 4 pi a^3 H_local, i.e. M = 3H), H_local = H0 +
the other dipole's field, solved self-consistently between the two dipoles, and the
"classic" force F = mu0 (m . grad) H on the upper one."""
import argparse
import math
import sys

import numpy as np

FIELDS = ("axial", "transverse")

# Six reference values (mu0 H0^2 a^2): (field, mu, gap/a, value)
ISSUE_VALUES = [
    ("axial", math.inf, 1.0, -1.16473),
    ("axial", math.inf, 0.1, -17.5947),
    ("axial", 1000.0, 0.01, -116.216),
    ("axial", 10.0, 0.0, -19.31581),
    ("transverse", math.inf, 0.0, +1.30939),
    ("transverse", math.inf, 0.1, +1.18820),
]


def order_of(field):
    """Azimuthal order m of a field direction: 0 axial, 1 transverse."""
    if field not in FIELDS:
        raise ValueError(f"field must be axial or transverse, not {field!r}")
    return 0 if field == "axial" else 1


def gamma(mu, n):
    """gamma_n = n (mu - 1)/(mu n + n + 1) for an array of orders n >= 0; mu = inf gives 1
    for n >= 1 (and 0 for n = 0)."""
    n = np.asarray(n, dtype=float)
    if math.isinf(mu):
        return np.where(n > 0, 1.0, 0.0)
    return n * (mu - 1.0) / (mu * n + n + 1.0)


def beta(mu):
    """(mu - 1)/(mu + 2): a lone sphere's moment is 4 pi beta a^3 H0 (mu = inf: 1)."""
    return 1.0 if math.isinf(mu) else (mu - 1.0) / (mu + 2.0)


def single_sphere_moment(mu):
    """Moment of one sphere alone in H0, in H0 a^3: 4 pi (mu - 1)/(mu + 2)."""
    return 4.0 * math.pi * beta(mu)


def translation_coefficient(n, k, m, sigma, dist):
    """Coefficient of (r_C/a)^k P_k^m(cos theta_C) in (a/r_S)^(n+1) P_n^m(cos theta_S), for
    C - S = sigma * dist * z_hat (dist in a, sigma = +-1):
        sigma^(n-m) (-sigma)^(k-m) (n+k)!/((n-m)!(k+m)!) (1/dist)^(n+k+1),
    evaluated in logarithms. n, k: integer arrays (broadcast), n, k >= m."""
    n = np.asarray(n)
    k = np.asarray(k)
    lg = np.vectorize(math.lgamma, otypes=[float])
    top = int(np.max(n + k)) + 1
    lf = lg(np.arange(top + 1) + 1.0)  # lf[j] = log(j!)
    logc = lf[n + k] - lf[n - m] - lf[k + m] - (n + k + 1) * math.log(dist)
    # sigma^(n-m) (-sigma)^(k-m) is (-1)^(k-m) for sigma = +1 and (-1)^(n-m) for sigma = -1
    odd = (k - m) % 2 if sigma > 0 else (n - m) % 2
    sign = np.where(odd == 0, 1.0, -1.0)
    return sign * np.exp(logc)


def system(mu, gap, field, L):
    """The halved linear system A x = rhs for x_n = B^1_n, n = 1..L (see the module doc), and
    T, the matrix that maps x to the regular part: E_k = -delta_{k1} + (T x)_k."""
    m = order_of(field)
    dist = 2.0 + gap
    n = np.arange(1, L + 1)
    kk, nn = np.meshgrid(n, n, indexing="ij")  # row k (equation), column n (unknown)
    # sphere 1 sees sphere 2 (sigma = +1), whose coefficients are (-1)^(n+1) x_n
    mirror = np.where((nn + 1) % 2 == 0, 1.0, -1.0)
    T = translation_coefficient(nn, kk, m, +1, dist) * mirror
    g = gamma(mu, n)
    A = g[:, None] * T
    A[np.diag_indices(L)] += 1.0
    rhs = np.zeros(L)
    rhs[0] = g[0]
    return A, rhs, T


class Solution:
    """Truncated solution at order L: B[n], E[n] (index n = 0..L, sphere 1; sphere 2 has
    B^2_n = (-1)^(n+1) B[n]), force (upper sphere, mu0 H0^2 a^2) and moment (each sphere's
    dipole 4 pi B_1, H0 a^3, along the applied field)."""

    def __init__(self, mu, gap, field, L):
        if L < 2:
            raise ValueError("L must be at least 2")
        if gap < 0:
            raise ValueError("gap must be >= 0")
        if gap == 0 and math.isinf(mu) and field == "axial":
            raise ValueError("axial, mu = inf: the force diverges at contact "
                             "(like (a/g)/ln^2(a/g)); give a gap > 0")
        self.mu, self.gap, self.field, self.L = mu, gap, field, L
        self.m = order_of(field)
        A, rhs, T = system(mu, gap, field, L)
        x = np.linalg.solve(A, rhs)
        self.B = np.concatenate(([0.0], x))
        E = np.zeros(L + 1)
        E[1] = -1.0  # the applied field
        E[1:] += T @ x  # sphere 2's series re-expanded about sphere 1
        self.E = E
        k = np.arange(2, L + 1, dtype=float)
        if self.m == 0:
            self.force = -4.0 * math.pi * float(np.sum(k * E[2:] * self.B[1:-1]))
        else:
            self.force = -2.0 * math.pi * float(np.sum((k + 1) * k * (k - 1) * E[2:] * self.B[1:-1]))
        self.moment = 4.0 * math.pi * self.B[1]


def solve(mu, gap, field, L):
    return Solution(mu, gap, field, L)


class NotConverged(RuntimeError):
    """converge() gave up at L_max; .rows holds the table so far."""

    def __init__(self, message, rows):
        super().__init__(message)
        self.rows = rows


def converge(mu, gap, field, L0=10, rtol=1e-7, L_max=3200):
    """Forces at L0, 2 L0, 4 L0, ... until two successive ones differ by less than rtol
    relative. Returns (rows, solution): rows = [(L, force, relative change from the row
    before or None)], solution at the last L. Raises NotConverged past L_max."""
    rows, prev, L = [], None, L0
    while True:
        sol = solve(mu, gap, field, L)
        change = None if prev is None else abs(sol.force - prev) / max(abs(sol.force), 1e-300)
        rows.append((L, sol.force, change))
        if change is not None and change < rtol:
            return rows, sol
        if 2 * L > L_max:
            raise NotConverged(f"not converged to {rtol:g} by L = {L} (last change "
                               f"{change if change is not None else float('nan'):.3g})", rows)
        prev, L = sol.force, 2 * L


def converged_force(mu, gap, field, rtol=1e-7, L0=10, L_max=3200):
    rows, sol = converge(mu, gap, field, L0=L0, rtol=rtol, L_max=L_max)
    return sol.force, rows


# ---------------------------------------------------------------- dipole model


def dipole_model(mu, gap, field):
    """One point dipole per sphere, m = 4 pi beta a^3 H_local (beta = (mu-1)/(mu+2)), the two
    moments solved self-consistently, and the classic force mu0 (m . grad) H on the upper one.
    Returns (moment per sphere in H0 a^3, force in mu0 H0^2 a^2).
      axial: the other dipole's field on the axis is 2 m/(4 pi d^3), so
             m = 4 pi beta/(1 - 2 beta/d^3), Fz = -3 m^2/(2 pi d^4);
      transverse: it is -m/(4 pi d^3), so m = 4 pi beta/(1 + beta/d^3), Fz = 3 m^2/(4 pi d^4)."""
    order_of(field)
    d = 2.0 + gap
    b = beta(mu)
    if field == "axial":
        mom = 4.0 * math.pi * b / (1.0 - 2.0 * b / d**3)
        return mom, -3.0 * mom**2 / (2.0 * math.pi * d**4)
    mom = 4.0 * math.pi * b / (1.0 + b / d**3)
    return mom, 3.0 * mom**2 / (4.0 * math.pi * d**4)


def dipole_dipole_force(mu, gap, field):
    """Force between two lone-sphere moments 4 pi beta a^3 H0 (no mutual induction): the far
    field of the exact force."""
    d = 2.0 + gap
    mom = single_sphere_moment(mu)
    if order_of(field) == 0:
        return -3.0 * mom**2 / (2.0 * math.pi * d**4)
    return 3.0 * mom**2 / (4.0 * math.pi * d**4)


# ---------------------------------------------------------------- bispherical check


def _bispherical_sums(gap):
    """mu = inf, axial. Bispherical coordinates (xi, eta) with foci at z = +-c: the spheres are
    xi = +-xi0, cosh xi0 = d/(2a), c = a sinh xi0. Outside both,
        phi = -z + sqrt(cosh xi - cos eta) sum_n A_n sinh((n+1/2) xi) P_n(cos eta),
    and with z = c sqrt(cosh xi - cos eta) 2 sqrt2 sum_n (n+1/2) e^(-(n+1/2) xi) P_n(cos eta)
    and 1/sqrt(cosh xi - cos eta) = sqrt2 sum_n e^(-(n+1/2) xi) P_n(cos eta) (xi > 0), the
    sphere xi0 at potential V demands
        A_n = sqrt2 w_n (c (2n+1) + V),  w_n = e^(-(n+1/2) xi0)/sinh((n+1/2) xi0)
                                             = 2/(e^((2n+1) xi0) - 1).
    Each sqrt(..) e^((n+1/2) xi) P_n term is 4 pi sqrt2 c of flux out of sphere 1 (its
    1/r tail at infinity is sqrt2 c/r), so no net flux means sum A_n = 0:
        V = -c S1/S0,  S_j = sum_n (2n+1)^j w_n.
    Its far field (1/r^2 cos theta term, from xi ~ 2c cos theta/r, sqrt(cosh xi - cos eta)
    ~ sqrt2 c/r) gives the pair's total moment
        m_tot = 4 pi sqrt2 c^2 sum_n (2n+1) A_n = 8 pi c^3 (S2 - S1^2/S0)   (H0 a^3).
    Returns xi0, c and the sums S0, S1, S2 and their xi0-derivatives."""
    if gap <= 0:
        raise ValueError("bispherical check needs gap > 0")
    xi0 = math.acosh(1.0 + gap / 2.0)
    c = math.sinh(xi0)
    N = int(40.0 / xi0) + 10  # w_n < e^(-(2n+1) xi0) / (1 - e^-...) reaches 1e-35 relative
    q = 2.0 * np.arange(N) + 1.0
    em1 = np.expm1(q * xi0)
    w = 2.0 / em1
    wp = -2.0 * q * (em1 + 1.0) / em1**2  # dw_n/dxi0
    S = [np.sum(q**j * w) for j in range(3)]
    Sp = [np.sum(q**j * wp) for j in range(3)]
    return xi0, c, S, Sp


def bispherical_moment(gap):
    """mu = inf, axial: the pair's total moment (H0 a^3) in closed form, 8 pi c^3 (S2 - S1^2/S0)."""
    xi0, c, S, _ = _bispherical_sums(gap)
    return 8.0 * math.pi * c**3 * (S[2] - S[1] ** 2 / S[0])


def bispherical_force(gap):
    """mu = inf, axial: force on the upper sphere from the energy at fixed H0,
    W = -1/2 mu0 H0 m_tot, moving both spheres apart symmetrically: Fz = d/dd (m_tot/2)
    (mu0 H0^2 a^2), with d = 2 cosh xi0, dd/dxi0 = 2 sinh xi0, differentiated analytically."""
    xi0, c, S, Sp = _bispherical_sums(gap)
    s = S[2] - S[1] ** 2 / S[0]
    sp = Sp[2] - 2.0 * S[1] * Sp[1] / S[0] + S[1] ** 2 * Sp[0] / S[0] ** 2
    dm = 8.0 * math.pi * (3.0 * c * c * math.cosh(xi0) * s + c**3 * sp)
    return 0.5 * dm / (2.0 * math.sinh(xi0))


# ---------------------------------------------------------------- direct evaluation


def legendre(nmax, m, x):
    """P_n^m(x), n = 0..nmax, m = 0 or 1, no Condon-Shortley phase; rows n, shape (nmax+1,)+x.
    Recurrence (n-m+1) P_(n+1)^m = (2n+1) x P_n^m - (n+m) P_(n-1)^m, P_m^m = 1 or sqrt(1-x^2)."""
    x = np.asarray(x, dtype=float)
    P = np.zeros((nmax + 1,) + x.shape)
    if m == 0:
        P[0] = 1.0
        if nmax >= 1:
            P[1] = x
        start = 1
    else:
        s = np.sqrt(np.maximum(0.0, 1.0 - x * x))
        if nmax >= 1:
            P[1] = s
        if nmax >= 2:
            P[2] = 3.0 * x * s
        start = 2
    for n in range(start, nmax):
        P[n + 1] = ((2 * n + 1) * x * P[n] - (n + m) * P[n - 1]) / (n - m + 1)
    return P


def potential(sol, x, y, z, applied=True):
    """phi (H0 a) at points outside both spheres (coordinates in a, origin between the
    centres): the applied field (left out with applied=False) plus both exterior series
    summed directly (no translation)."""
    x, y, z = (np.asarray(v, dtype=float) for v in (x, y, z))
    half = (2.0 + sol.gap) / 2.0
    n = np.arange(sol.L + 1)
    B2 = np.where((n + 1) % 2 == 0, 1.0, -1.0) * sol.B
    phi = 0.0 * (x + y + z)
    if applied:
        phi = phi - (z if sol.m == 0 else x)
    rho = np.hypot(x, y)
    az = 1.0 if sol.m == 0 else np.where(rho > 0, x / np.where(rho > 0, rho, 1.0), 1.0)
    for zc, coef in ((half, sol.B), (-half, B2)):
        r = np.sqrt(rho**2 + (z - zc) ** 2)
        P = legendre(sol.L, sol.m, (z - zc) / r)
        powers = (1.0 / r)[None, ...] ** (n + 1).reshape((-1,) + (1,) * r.ndim)
        phi = phi + az * np.tensordot(coef, powers * P, axes=(0, 0))
    return phi


def surface_potential(sol, count=41):
    """phi on the upper sphere's surface at `count` polar angles (azimuth 0): constant for
    mu = inf (the sphere is an equipotential)."""
    th = np.linspace(0.0, math.pi, count)
    half = (2.0 + sol.gap) / 2.0
    return potential(sol, np.sin(th), 0.0 * th, half + np.cos(th))


def midplane_force(sol, nodes=200, h=1e-4):
    """Force on the upper sphere as the vacuum Maxwell stress T = H H - 1/2 H^2 I over the
    plane z = 0 (outward normal -z of the upper half-space; the applied field's own stress
    subtracted, which closes at infinity): by the mirror symmetry H is normal to the plane
    (axial) or in it (transverse), so
        axial:       Fz = -1/2 int (H_z^2 - 1) dA,
        transverse:  Fz = +1/2 int (H_t^2 - 1) dA = 1/2 int_0^inf [pi (F'^2 + F^2/s^2) - 2 pi] s ds,
    with phi = F(s) cos phi_az on the plane. Radial integral by Gauss-Legendre in t with
    s = (d/2) tan(pi t/2); derivatives of the spheres' part f of phi (phi = applied + f) by
    4th-order central differences of step h, the applied part added exactly:
        axial:       H_z = 1 - df/dz,
        transverse:  F'^2 + F^2/s^2 - 2 = f'^2 + (f/s)^2 - 2 f' - 2 f/s   (f on azimuth 0)."""
    t, wt = np.polynomial.legendre.leggauss(nodes)
    t = 0.5 * (t + 1.0)
    wt = 0.5 * wt
    half = (2.0 + sol.gap) / 2.0
    s = half * np.tan(0.5 * math.pi * t)
    ds = half * 0.5 * math.pi / np.cos(0.5 * math.pi * t) ** 2
    zero = 0.0 * s

    def d4(f, p):
        return (-f(p + 2 * h) + 8 * f(p + h) - 8 * f(p - h) + f(p - 2 * h)) / (12 * h)

    if sol.m == 0:
        hz = -d4(lambda zz: potential(sol, s, zero, zz, applied=False), zero)
        integrand = -0.5 * (hz * hz + 2.0 * hz) * 2.0 * math.pi * s
    else:
        f = potential(sol, s, zero, zero, applied=False)
        fp = d4(lambda xx: potential(sol, xx, zero, zero, applied=False), s)
        integrand = 0.5 * math.pi * (fp * fp + (f / s) ** 2 - 2.0 * fp - 2.0 * f / s) * s
    return float(np.sum(wt * ds * integrand))


# ---------------------------------------------------------------- command line


def parse_mu(text):
    v = float(text)
    if not (v > 1.0 or math.isinf(v)):
        raise argparse.ArgumentTypeError("mu must be > 1 or inf")
    return v


def fmt_mu(mu):
    return "inf" if math.isinf(mu) else f"{mu:g}"


def print_table(rows):
    print(f"    {'L':>6}  {'force (mu0 H0^2 a^2)':>24}  {'change':>10}")
    for L, f, ch in rows:
        print(f"    {L:>6}  {f:>24.15g}  {'' if ch is None else f'{ch:10.2e}'}")


def cmd_values(args):
    worst = 0.0
    for field, mu, gap, want in ISSUE_VALUES:
        try:
            rows, sol = converge(mu, gap, field, L0=args.L0, rtol=args.rtol, L_max=args.L_max)
        except NotConverged as e:
            print(f"{field}, mu = {fmt_mu(mu)}, g = {gap:g} a: reference {want:+.8g}")
            print_table(e.rows)
            print(f"    -> {e} [OFF]\n")
            worst = math.inf
            continue
        err = abs(sol.force - want) / abs(want)
        worst = max(worst, err)
        print(f"{field}, mu = {fmt_mu(mu)}, g = {gap:g} a: reference {want:+.8g}")
        print_table(rows)
        ok = "ok" if err <= 1e-5 else "OFF"
        print(f"    -> {sol.force:+.10g} at L = {rows[-1][0]} (change below {args.rtol:g} from "
              f"L = {rows[-2][0]}); relative error against the reference {err:.2e} [{ok}]\n")
    print(f"worst relative error {worst:.2e} (tolerance 1e-5)")
    return 0 if worst <= 1e-5 else 1


def cmd_force(args):
    if args.L is not None:
        sol = solve(args.mu, args.gap, args.field, args.L)
        print(f"{args.field}, mu = {fmt_mu(args.mu)}, g = {args.gap:g} a, L = {args.L}")
    else:
        try:
            rows, sol = converge(args.mu, args.gap, args.field, L0=args.L0, rtol=args.rtol,
                                 L_max=args.L_max)
        except NotConverged as e:
            print(f"{args.field}, mu = {fmt_mu(args.mu)}, g = {args.gap:g} a")
            print_table(e.rows)
            print(f"two_spheres: {e}", file=sys.stderr)
            return 1
        print(f"{args.field}, mu = {fmt_mu(args.mu)}, g = {args.gap:g} a")
        print_table(rows)
    mom, fd = dipole_model(args.mu, args.gap, args.field)
    print(f"exact force      {sol.force:+.10g} mu0 H0^2 a^2")
    print(f"moment per sphere {sol.moment:.10g} H0 a^3 (lone sphere {single_sphere_moment(args.mu):.10g})")
    print(f"dipole model     {fd:+.10g} (moment {mom:.10g}); exact/dipole {sol.force / fd:.6g}")
    if math.isinf(args.mu) and args.field == "axial":
        fb = bispherical_force(args.gap)
        print(f"bispherical      {fb:+.10g} (relative difference {abs(fb - sol.force) / abs(fb):.2e})")
    return 0


def chart_gaps():
    """g/a from 0.003 to 3: 31 log-spaced gaps and the decades 0.01, 0.1, 1."""
    grid = np.logspace(math.log10(0.003), math.log10(3.0), 31)
    return np.unique(np.concatenate((grid, [0.01, 0.1, 1.0])))


def style_gap_axes(ax, field, ylabel, title):
    """A force-ratio chart against the gap: log gap, log ratio for the axial field, 1 marked."""
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.set_xscale("log")
    if field == "axial":
        ax.set_yscale("log")
    ax.set_xlabel("gap g / a")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()


def cmd_chart(args):
    import csv
    import os

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(args.out, exist_ok=True)
    gaps = chart_gaps()
    mus = (math.inf, 1000.0, 10.0)
    rows = []
    for field in FIELDS:
        for mu in mus:
            for g in gaps:
                f, tab = converged_force(mu, float(g), field, rtol=args.rtol)
                _, fd = dipole_model(mu, float(g), field)
                rows.append((field, fmt_mu(mu), float(g), f, fd, f / fd, tab[-1][0]))
    csv_path = os.path.join(args.out, "two_spheres_ratio.csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["field", "mu", "gap_over_a", "F_exact", "F_dipole", "ratio_exact_over_dipole", "L_final"])
        for r in rows:
            w.writerow([r[0], r[1], f"{r[2]:.6g}", f"{r[3]:.10g}", f"{r[4]:.10g}", f"{r[5]:.8g}", r[6]])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, field in zip(axes, FIELDS):
        for mu in mus:
            sel = [r for r in rows if r[0] == field and r[1] == fmt_mu(mu)]
            ax.plot([r[2] for r in sel], [r[5] for r in sel], marker=".", label=f"mu = {fmt_mu(mu)}")
        style_gap_axes(ax, field, "F exact / F dipole model",
                       f"{field} field ({'attraction' if field == 'axial' else 'repulsion'})")
    fig.suptitle("Two spheres: exact linear force / one self-consistent dipole per sphere (classic force)")
    fig.tight_layout()
    png_path = os.path.join(args.out, "two_spheres_ratio.png")
    fig.savefig(png_path, dpi=110)
    print(f"wrote {csv_path} and {png_path}")
    return 0


def main(argv=None):
    p = argparse.ArgumentParser(
        prog="two_spheres.py",
        description="Exact linear magnetostatics of two identical spheres (radius a, gap g, "
                    "relative permeability mu) in a uniform field H0; forces in mu0 H0^2 a^2 "
                    "on the upper sphere (negative = attraction), moments in H0 a^3.")
    sub = p.add_subparsers(dest="cmd", required=True)

    def conv_opts(sp):
        sp.add_argument("--rtol", type=float, default=1e-7,
                        help="stop doubling L when the force changes by less than this (default 1e-7)")
        sp.add_argument("--L0", type=int, default=10, help="first truncation order (default 10)")
        sp.add_argument("--L-max", dest="L_max", type=int, default=3200,
                        help="give up past this order (default 3200)")

    sv = sub.add_parser("values", help="the six reference values with convergence in L",
                        description="Reproduces the six reference forces, printing the force at "
                                    "L0, 2 L0, 4 L0 ... until it changes by less than --rtol; exits 1 "
                                    "if any is off its reference value by more than 1e-5 relative.")
    conv_opts(sv)
    sf = sub.add_parser("force", help="one configuration",
                        description="Force on the upper sphere of one configuration, with the dipole "
                                    "model's beside it (and the bispherical one for mu = inf axial).")
    sf.add_argument("--mu", type=parse_mu, required=True, help="relative permeability (> 1, or inf)")
    sf.add_argument("--gap", type=float, required=True, help="gap g / a (>= 0)")
    sf.add_argument("--field", choices=FIELDS, required=True)
    sf.add_argument("--L", type=int, default=None,
                    help="truncation order (default: doubled from --L0 until converged)")
    conv_opts(sf)
    sc = sub.add_parser("chart", help="ratio exact / dipole model against gap (PNG + CSV)",
                        description="Force ratio exact / dipole model for g/a from 0.003 to 3 (31 log-spaced "
                                    "gaps and 0.01, 0.1, 1), axial and transverse, mu = inf, 1000, 10: "
                                    "DIR/two_spheres_ratio.png and .csv (L_final: the last truncation "
                                    "order of the doubling, whose force changed by less than --rtol).")
    sc.add_argument("--out", required=True, help="output directory")
    sc.add_argument("--rtol", type=float, default=1e-7, help="convergence in L (default 1e-7)")
    args = p.parse_args(argv)
    try:
        if args.cmd == "values":
            return cmd_values(args)
        if args.cmd == "force":
            if args.gap < 0:
                p.error("--gap must be >= 0")
            return cmd_force(args)
        return cmd_chart(args)
    except ValueError as e:
        print(f"two_spheres: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
