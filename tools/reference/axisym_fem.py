#!/usr/bin/python3
"""tools/reference/axisym_fem.py — nonlinear axisymmetric magnetostatics of N identical iron
spheres on the field axis: the finite-element reference for the near-field model. numpy and
scipy only (Debian python3-numpy, python3-scipy); the mesher is in this file.

    /usr/bin/python3 tools/reference/axisym_fem.py --n 2 --gap 0.003 --h0 0.01 [--refine 1]

Problem. N spheres of radius a (N = 2, 3, 5, ...), centres on the z axis, neighbouring gaps
g (in a), symmetric about z = 0, in a uniform applied field H0 along z. No currents, so
H = -grad(phi) and div B = 0 with

    B = mu0 (H + M(H)),   M(H) = Ms tanh(chi0 |H| / Ms) H/|H|   in the iron,   M = 0 in air,

chi0 = mu_r - 1 the initial susceptibility (mu_r = 1000: chi0 = 999, the value of the
near-field model's `mu_r`). This is the material law of the bulk iron, not the engine's
sphere-level law f(H) = Ms tanh(3|H|/Ms) (a sphere of initial slope 3 is mu_r = inf).

Units: lengths in a, fields in Ms, phi in Ms a, forces in mu0 Ms^2 a^2 (N: times mu0 Ms^2 a^2,
80.4 N for a = 5 mm and Ms = 1.6e6 A/m), moments in Ms a^3.

Discretization.
  * Half domain. phi is odd in z (the arrangement is mirror symmetric about z = 0 and H0 is
    axial), so only z >= 0 is meshed, with phi = 0 on z = 0. The domain is the quarter disc
    rho >= 0, z >= 0, r <= R: phi = -H0 z on r = R (the applied field; the truncation leaves
    an error of order (extent/R)^3, measured by varying R), and the axis rho = 0 is a natural
    boundary of the axisymmetric weak form.
  * P1 triangles in (rho, z). The solution minimizes the convex co-energy
        W'(phi) = integral w'(|grad phi|) 2 pi rho drho dz,
        w'(H) = H^2/2 + (Ms^2/chi0) ln cosh(chi0 H/Ms) in the iron, H^2/2 in air
    (w' = integral_0^H B dH / mu0), whose stationarity is the weak form of div B = 0. With P1,
    grad phi is constant on a triangle, so each triangle's integral is exact:
    area * rho_centroid * 2 pi.
  * Newton's method on W' with an exact line search (W' is convex, so it converges from
    any start): gradient sum_e w_e b(G_e) . grad v, b = B/mu0, and Hessian with the
    tangent dB/dH / mu0 = I + (M/H)(I - h h^T) + M'(H) h h^T, h = H/|H|, M' = chi0 sech^2.
    Stopped when the Newton decrement (squared) falls below 1e-18 of W' (the force is then
    converged to round-off).
  * Mesh: a balanced quadtree of fill points, graded by a size function, plus points marched
    along every boundary (the sphere arcs, the axis, z = 0, the outer arc), Delaunay
    (scipy.spatial.Delaunay). The domain is convex, so the triangulation's hull is the domain.
    A triangle is iron if its centroid lies inside a sphere (the spheres become polygons:
    their volume error is O(h^2), like the rest). The size function
        h(x) = min(h_surf + q dist(x, spheres), max(h_gap, k dist(x, contacts))) / refine
    is finest at the contact points (the gaps' mid points on the axis), h_gap = g/2.
    `refine` halves every element size per doubling; forces converge as O(h^2).

Force on a sphere: the vacuum Maxwell stress T = mu0 (H H^T - |H|^2 I / 2) taken as a volume
integral over the air (the "eggshell" form): F_z = -integral T_zj d_j psi dV, with psi = 1 on
the sphere, 0 on the other spheres and on z = 0 (which bounds the half domain), and smooth in
the air between (psi = d_o/(d_k + d_o) times a cut-off in d_k, d the distances to the sphere and
to the rest). div T = 0 in air makes this the surface integral over any surface around the
sphere. Checked against the co-energy derivative F_z = dW'/dz_k at fixed boundary potential
(the mesh's nodes moved by psi, central differences): `--check-coenergy`.

Moment: integral M dV over the iron (both halves), in Ms a^3."""
import argparse
import json
import math
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import Delaunay, cKDTree

MU_R = 1000.0


# ---------------------------------------------------------------- geometry


class Chain:
    """N spheres of radius 1 on the z axis, gaps g, symmetric about z = 0. Only the centres
    with z >= 0 are kept (the one at z = 0, for odd N, is cut in half by the mesh)."""

    def __init__(self, n, gap):
        if n < 2:
            raise ValueError("need at least two spheres")
        self.n, self.gap = n, gap
        d = 2.0 + gap
        allc = (np.arange(n) - 0.5 * (n - 1)) * d
        self.centres = allc[allc >= -1e-12]
        # contact points (mid gap, on the axis) with z >= 0
        mids = 0.5 * (allc[1:] + allc[:-1])
        self.contacts = mids[mids >= -1e-12]
        self.top = allc[-1] + 1.0  # the chain's upper end

    def dist_spheres(self, rho, z):
        """Distance to the nearest sphere surface (>= 0 outside, 0 inside)."""
        d = np.full(np.shape(rho), np.inf)
        for c in self.centres:
            d = np.minimum(d, np.abs(np.hypot(rho, z - c) - 1.0))
        return d

    def dist_contacts(self, rho, z):
        d = np.full(np.shape(rho), np.inf)
        for c in self.contacts:
            d = np.minimum(d, np.hypot(rho, z - c))
        return d


class Sizing:
    """The element size h(x) (module doc). refine divides it."""

    def __init__(self, chain, R, refine=1.0, k=0.12, h_surf=0.07, q=0.25):
        self.chain, self.R, self.refine = chain, R, refine
        self.k, self.h_surf, self.q = k, h_surf, q
        self.h_gap = 0.5 * chain.gap

    def __call__(self, rho, z):
        rho = np.asarray(rho, dtype=float)
        z = np.asarray(z, dtype=float)
        c = self.chain
        far = self.h_surf + self.q * c.dist_spheres(rho, z)
        near = np.maximum(self.h_gap, self.k * c.dist_contacts(rho, z))
        return np.minimum(far, near) / self.refine


def march(curve, length, h, start_step=None):
    """Parameters t_i in [0, length] along a curve x(t) (arc length), spaced by h(x); the
    last step is stretched to end exactly at `length`."""
    ts = [0.0]
    while True:
        x = curve(ts[-1])
        step = float(h(x[0], x[1]))
        if ts[-1] + 1.5 * step >= length:
            break
        ts.append(ts[-1] + step)
    ts.append(length)
    return np.array(ts)


def boundary_points(chain, size):
    """Points on every boundary: the sphere arcs (marched from the poles that face a contact,
    so facing arcs get the same rho samples), the axis, z = 0 and the outer arc."""
    R = size.R
    pts = []
    for c in chain.centres:
        if c > 1e-12:
            # arc from the bottom pole (theta = pi) to the top pole (theta = 0); march from both
            # poles to the equator-ish middle, then join
            arc = lambda s, c=c: (math.sin(s), c - math.cos(s))  # noqa: E731
            top = lambda s, c=c: (math.sin(s), c + math.cos(s))  # noqa: E731
            sb = march(arc, 0.5 * math.pi, size)
            st = march(top, 0.5 * math.pi, size)
            th = np.concatenate((math.pi - sb, st[::-1][1:]))
        else:
            top = lambda s: (math.sin(s), math.cos(s))  # noqa: E731
            st = march(top, 0.5 * math.pi, size)
            th = st[::-1]
        pts.append(np.column_stack((np.sin(th), c + np.cos(th))))
    arcs = np.vstack(pts)
    # the plane z = 0 (rho from 0 to R; inside the central sphere, if any, too)
    pl = march(lambda s: (s, 0.0), R, size)
    # the axis (z from 0 to R)
    ax = march(lambda s: (0.0, s), R, size)
    # the outer arc
    outer = march(lambda s: (R * math.sin(s / R), R * math.cos(s / R)), 0.5 * math.pi * R, size)
    oth = outer / R
    out = np.column_stack((R * np.sin(oth), R * np.cos(oth)))
    bnd = np.vstack((np.column_stack((pl, 0 * pl)), np.column_stack((0 * ax, ax)), out))
    return arcs, bnd


def quadtree_points(size, R):
    """Centres of the leaves of a quadtree over [0, R]^2, each leaf no larger than h at its
    centre (vectorized level by level)."""
    cells = np.array([[0.5 * R, 0.5 * R]])
    w = R
    leaves = []
    while len(cells):
        h = size(cells[:, 0], cells[:, 1])
        split = w > 0.9 * h
        # drop cells wholly outside the quarter disc
        inside = np.hypot(np.maximum(cells[:, 0] - 0.5 * w, 0), np.maximum(cells[:, 1] - 0.5 * w, 0)) < R
        leaves.append(cells[~split & inside])
        c = cells[split & inside]
        w *= 0.5
        q = 0.5 * w
        cells = np.vstack([c + [dx, dz] for dx in (-q, q) for dz in (-q, q)]) if len(c) else c
        if w < 1e-7:
            raise RuntimeError("quadtree too deep")
    return np.vstack(leaves)


class Mesh:
    """Nodes p (n x 2: rho, z), triangles t (m x 3), iron flags, and the boundary sets."""

    def __init__(self, chain, R, refine=1.0, **sizing):
        self.chain, self.R = chain, R
        size = Sizing(chain, R, refine, **sizing)
        arcs, bnd = boundary_points(chain, size)
        fill = quadtree_points(size, R)
        # fill points: inside the domain and clear of every boundary by 0.55 h
        hf = size(fill[:, 0], fill[:, 1])
        r = np.hypot(fill[:, 0], fill[:, 1])
        keep = (fill[:, 0] > 0.55 * hf) & (fill[:, 1] > 0.55 * hf) & (r < R - 0.55 * hf)
        keep &= chain.dist_spheres(fill[:, 0], fill[:, 1]) > 0.55 * hf
        fill = fill[keep]
        # axis / plane points next to an arc point (the poles, a cut sphere's rim) give way to it
        hb = size(bnd[:, 0], bnd[:, 1])
        dist, _ = cKDTree(arcs).query(bnd)
        bnd = bnd[dist > 0.45 * hb]
        p = np.vstack((arcs, bnd, fill))
        # merge exact duplicates
        key = np.round(p / 1e-12).astype(np.int64)
        _, idx = np.unique(key, axis=0, return_index=True)
        p = p[np.sort(idx)]
        tri = Delaunay(p, qhull_options="Qbb Qc Qz Q12 Qt").simplices
        a = self._area(p, tri)
        tri = tri[np.abs(a) > 1e-13 * np.max(np.abs(a))]
        a = self._area(p, tri)
        tri[a < 0] = tri[a < 0][:, [0, 2, 1]]
        self.p, self.t = p, tri
        cen = p[tri].mean(axis=1)
        self.iron = np.zeros(len(tri), bool)
        for c in chain.centres:
            self.iron |= np.hypot(cen[:, 0], cen[:, 1] - c) < 1.0
        r = np.hypot(p[:, 0], p[:, 1])
        self.dirichlet = (p[:, 1] < 1e-12) | (r > R * (1 - 1e-9))
        self.size = size
        self.geometry()

    @staticmethod
    def _area(p, t):
        a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
        return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1]))

    def geometry(self):
        """Per triangle: the P1 gradient operator (m x 2 x 3) and the weight 2 pi rho_c area."""
        p, t = self.p, self.t
        x = p[t]  # m x 3 x 2
        A = self._area(p, t)
        # grad of barycentric coordinate i: perp of the opposite edge / (2A)
        e0 = x[:, 2] - x[:, 1]
        e1 = x[:, 0] - x[:, 2]
        e2 = x[:, 1] - x[:, 0]
        G = np.empty((len(t), 2, 3))
        for i, e in enumerate((e0, e1, e2)):
            G[:, 0, i] = -e[:, 1] / (2 * A)
            G[:, 1, i] = e[:, 0] / (2 * A)
        self.G = G
        self.area = A
        self.w = 2.0 * math.pi * x[:, :, 0].mean(axis=1) * A
        # sparse pattern: the 9 (i, j) pairs of each triangle
        self.rows = np.repeat(t, 3, axis=1).ravel()
        self.cols = np.tile(t, (1, 3)).ravel()

    @property
    def nodes(self):
        return len(self.p)


# ---------------------------------------------------------------- material


def lncosh(x):
    x = np.abs(x)
    return x + np.log1p(np.exp(-2.0 * x)) - math.log(2.0)


class Material:
    """M = Ms tanh(chi0 H / Ms) (Ms = 1 in these units); linear=True: M = chi0 H."""

    def __init__(self, mu_r=MU_R, linear=False):
        self.chi0 = mu_r - 1.0
        self.linear = linear

    def M(self, H):
        return self.chi0 * H if self.linear else np.tanh(self.chi0 * H)

    def dM(self, H):
        return np.full_like(H, self.chi0) if self.linear else self.chi0 / np.cosh(np.minimum(self.chi0 * H, 300.0)) ** 2

    def w(self, H):
        """Co-energy density beyond H^2/2: integral_0^H M dH."""
        return 0.5 * self.chi0 * H * H if self.linear else lncosh(self.chi0 * H) / self.chi0

    def M_over_H(self, H):
        if self.linear:
            return np.full_like(H, self.chi0)
        x = self.chi0 * H
        small = x < 1e-6
        return np.where(small, self.chi0 * (1 - x * x / 3), np.tanh(x) / np.where(small, 1.0, H))


# ---------------------------------------------------------------- solver


class Solution:
    pass


def solve(mesh, H0, material=None, phi0=None, tol=1e-18, max_iter=200, verbose=False):
    """Minimizes W'(phi) with phi = -H0 z on r = R and 0 on z = 0. Returns a Solution with phi,
    the element fields, W' and the iteration count. phi0: a starting guess (same mesh)."""
    mat = material or Material()
    p, G, w, iron = mesh.p, mesh.G, mesh.w, mesh.iron
    n = mesh.nodes
    D = mesh.dirichlet
    free = np.flatnonzero(~D)
    phiD = np.where(p[:, 1] < 1e-12, 0.0, -H0 * p[:, 1])
    phi = phiD.copy() if phi0 is None else np.where(D, phiD, phi0)
    if phi0 is None:
        phi[free] = -H0 * p[free, 1]
    t = mesh.t
    # the CSR pattern, built once; each iteration sums the element entries into its slots
    K0 = sp.coo_matrix((np.ones(len(mesh.rows)), (mesh.rows, mesh.cols)), shape=(n, n)).tocsr()
    K0.sum_duplicates()
    K0.sort_indices()
    lin = mesh.rows.astype(np.int64) * n + mesh.cols
    csr_lin = np.repeat(np.arange(n), np.diff(K0.indptr)).astype(np.int64) * n + K0.indices
    slot = np.searchsorted(csr_lin, lin)

    def fields(ph):
        g = np.einsum("eki,ei->ek", G, ph[t])  # grad phi per element
        return g

    def energy(ph):
        g = fields(ph)
        H = np.hypot(g[:, 0], g[:, 1])
        dens = 0.5 * H * H
        dens[iron] += mat.w(H[iron])
        return float(np.sum(w * dens))

    W = energy(phi)
    it = 0
    for it in range(1, max_iter + 1):
        g = fields(phi)
        H = np.hypot(g[:, 0], g[:, 1])
        # b = mu(H) g, tangent D = mu I + (M' - M/H) h h^T in the iron, I in air
        mu = np.ones_like(H)
        Hi = H[iron]
        MoH = mat.M_over_H(Hi)
        mu[iron] += MoH
        b = mu[:, None] * g
        res = np.zeros(n)
        np.add.at(res, t.ravel(), (w[:, None] * np.einsum("eki,ek->ei", G, b)).ravel())
        Dt = mu[:, None, None] * np.eye(2)[None]
        hh = np.zeros((len(Hi), 2))
        nz = Hi > 0
        hh[nz] = g[iron][nz] / Hi[nz, None]
        extra = np.zeros_like(Hi)
        extra[nz] = mat.dM(Hi[nz]) - MoH[nz]
        Dt[iron] += extra[:, None, None] * hh[:, :, None] * hh[:, None, :]
        Ke = w[:, None, None] * np.einsum("eki,ekl,elj->eij", G, Dt, G)
        data = np.bincount(slot, weights=Ke.ravel(), minlength=K0.nnz)
        K = sp.csr_matrix((data, K0.indices, K0.indptr), shape=(n, n))
        Kff = K[free][:, free]
        rf = res[free]
        dx = spla.spsolve(Kff.tocsc(), -rf, permc_spec="COLAMD")
        dec = float(-rf @ dx)  # the Newton decrement, squared
        if verbose:
            print(f"  newton {it}: W' {W:.15g}, decrement {dec:.3e}", flush=True)
        if dec < tol * max(abs(W), 1e-300):
            phi[free] += dx
            break
        # exact line search: W'(phi + s dx) is convex in s; its derivative
        # dW'/ds = sum_e w_e b(G_e(s)) . grad(dx)_e is solved for its root by safeguarded secant
        step_vec = np.zeros(n)
        step_vec[free] = dx
        gdx = fields(step_vec)
        g0 = fields(phi)

        def slope(s_):
            gg = g0 + s_ * gdx
            HH = np.hypot(gg[:, 0], gg[:, 1])
            mm = np.ones_like(HH)
            mm[iron] += mat.M_over_H(HH[iron])
            return float(np.sum(w * mm * np.einsum("ek,ek->e", gg, gdx)))

        lo, dlo = 0.0, -dec
        hi, dhi = 1.0, slope(1.0)
        while dhi < 0 and hi < 64:
            lo, dlo = hi, dhi
            hi *= 2.0
            dhi = slope(hi)
        s_ = hi
        for _ in range(40):
            if dhi < 0 or abs(dhi) <= 1e-6 * dec:
                break
            s_ = hi - dhi * (hi - lo) / (dhi - dlo)
            s_ = min(max(s_, lo + 0.02 * (hi - lo)), hi - 0.02 * (hi - lo))
            d = slope(s_)
            if abs(d) <= 1e-6 * dec:
                break
            if d < 0:
                lo, dlo = s_, d
            else:
                hi, dhi = s_, d
            s_ = hi if abs(dhi) < abs(dlo) else lo
        if abs(s_ - 1.0) < 1e-3:
            s_ = 1.0
        phi[free] += s_ * dx
        W = energy(phi)
    s = Solution()
    s.phi, s.W, s.iterations, s.H0 = phi, W, it, H0
    s.grad = fields(phi)
    s.material = mat
    return s


# ---------------------------------------------------------------- forces and moments


def psi_of(mesh, k):
    """psi for sphere k (index into chain.centres): 1 on it, 0 on the others and on z = 0."""
    chain = mesh.chain
    p = mesh.p
    c = chain.centres[k]
    dk = np.maximum(np.hypot(p[:, 0], p[:, 1] - c) - 1.0, 0.0)
    do = np.full(len(p), np.inf)
    for j, cj in enumerate(chain.centres):
        if j != k:
            do = np.minimum(do, np.maximum(np.hypot(p[:, 0], p[:, 1] - cj) - 1.0, 0.0))
    do = np.minimum(do, p[:, 1])  # the plane z = 0 bounds the half domain
    with np.errstate(invalid="ignore", divide="ignore"):
        psi = np.where(dk + do > 0, do / (dk + do), 0.0)
    # cut-off: psi fades to 0 by a distance of 0.5 a from the sphere
    s = np.clip(dk / 0.5, 0.0, 1.0)
    psi *= 1.0 - s * s * (3.0 - 2.0 * s)
    psi[dk == 0] = 1.0
    return psi


def force(mesh, sol, k):
    """F_z on sphere k (mu0 Ms^2 a^2), eggshell Maxwell stress over the air."""
    psi = psi_of(mesh, k)
    gpsi = np.einsum("eki,ei->ek", mesh.G, psi[mesh.t])
    air = ~mesh.iron
    H = -sol.grad[air]
    Hr, Hz = H[:, 0], H[:, 1]
    Tzr = Hz * Hr
    Tzz = Hz * Hz - 0.5 * (Hr * Hr + Hz * Hz)
    return -float(np.sum(mesh.w[air] * (Tzr * gpsi[air, 0] + Tzz * gpsi[air, 1])))


def moment(mesh, sol):
    """The whole chain's moment along z (Ms a^3): integral M_z dV over the iron, both halves."""
    H = -sol.grad[mesh.iron]
    Hn = np.hypot(H[:, 0], H[:, 1])
    Mz = sol.material.M_over_H(Hn) * H[:, 1]
    return 2.0 * float(np.sum(mesh.w[mesh.iron] * Mz))


def sphere_moments(mesh, sol):
    """Each upper-half sphere's moment (Ms a^3; the cut central one counted whole)."""
    H = -sol.grad
    Hn = np.hypot(H[:, 0], H[:, 1])
    cen = mesh.p[mesh.t].mean(axis=1)
    out = []
    for c in mesh.chain.centres:
        sel = mesh.iron & (np.hypot(cen[:, 0], cen[:, 1] - c) < 1.0)
        Mz = sol.material.M_over_H(Hn[sel]) * H[sel, 1]
        out.append((2.0 if c < 1e-12 else 1.0) * float(np.sum(mesh.w[sel] * Mz)))
    return out


def coenergy_force(mesh, H0, k, delta, material=None, phi0=None):
    """dW'/dz_k by central differences: the nodes moved by +-delta psi_k (z only)."""
    psi = psi_of(mesh, k)
    Ws = []
    for sgn in (1.0, -1.0):
        m2 = object.__new__(Mesh)
        m2.__dict__.update(mesh.__dict__)
        m2.p = mesh.p.copy()
        m2.p[:, 1] += sgn * delta * psi
        m2.geometry()
        Ws.append(solve(m2, H0, material, phi0=phi0).W)
    return (Ws[0] - Ws[1]) / (2 * delta)


# ---------------------------------------------------------------- driver


def default_R(chain):
    """The outer radius: 25 times the chain's half length (truncation error ~ 1e-4)."""
    return 25.0 * chain.top


def run_case(n, gap, fields, refine=1.0, R=None, mu_r=MU_R, linear=False, verbose=False):
    """Solves one geometry at each field (continuation: each start is the last solution scaled).
    Returns the mesh and [dict per field]."""
    chain = Chain(n, gap)
    mesh = Mesh(chain, R or default_R(chain), refine)
    mat = Material(mu_r, linear)
    rows, prev, prevH = [], None, None
    for H0 in fields:
        t0 = time.time()
        phi0 = None if prev is None else prev.phi * (H0 / prevH)
        sol = solve(mesh, H0, mat, phi0=phi0, verbose=verbose)
        F = [force(mesh, sol, k) for k in range(len(chain.centres))]
        rows.append({"H0": H0, "forces": F, "moment": moment(mesh, sol),
                     "sphere_moments": sphere_moments(mesh, sol),
                     "newton": sol.iterations, "seconds": time.time() - t0})
        prev, prevH = sol, H0
    return mesh, rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=2)
    ap.add_argument("--gap", type=float, default=0.1)
    ap.add_argument("--h0", type=float, nargs="+", default=[0.01], help="H0/Ms (one or more)")
    ap.add_argument("--refine", type=float, default=1.0)
    ap.add_argument("--R", type=float, default=None)
    ap.add_argument("--mu-r", type=float, default=MU_R)
    ap.add_argument("--linear", action="store_true", help="M = chi0 H (no saturation)")
    ap.add_argument("--check-coenergy", action="store_true")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args(argv)
    t0 = time.time()
    mesh, rows = run_case(args.n, args.gap, args.h0, args.refine, args.R, args.mu_r, args.linear, args.verbose)
    print(f"mesh: {mesh.nodes} nodes, {len(mesh.t)} triangles, R = {mesh.R:g} a", file=sys.stderr)
    for r in rows:
        print(json.dumps(r))
        if args.check_coenergy:
            chain = mesh.chain
            k = len(chain.centres) - 1
            fw = coenergy_force(mesh, r["H0"], k, 0.02 * chain.gap * 0.5, Material(args.mu_r, args.linear))
            print(json.dumps({"H0": r["H0"], "sphere": k, "maxwell": r["forces"][k], "coenergy": fw,
                              "relative": fw / r["forces"][k] - 1}))
    print(f"{time.time() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
