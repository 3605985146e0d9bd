#!/usr/bin/python3
"""tests/tools/reference/axisym_fem_test.py — the nonlinear finite-element reference of iron
spheres (tools/reference/axisym_fem.py) on small meshes: the linear law against the exact
two-sphere solution (two_spheres.py), the saturated limit, the co-energy derivative against
the Maxwell stress, and the mesh's materials. numpy and scipy; a few seconds. Run by CTest
(label tools)."""
import math
import os
import sys
import unittest

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tools", "reference"))
import axisym_fem as af  # noqa: E402
import two_spheres as ts  # noqa: E402


def pair_mesh(gap, refine=1.0):
    ch = af.Chain(2, gap)
    return af.Mesh(ch, af.default_R(ch), refine)


class LinearAgainstExact(unittest.TestCase):
    # level 1 is within 0.3 % of the exact force at these gaps (level 2: 0.05 %)
    def test_force_and_moment(self):
        lin = af.Material(1000.0, linear=True)
        for gap in (0.1, 0.01):
            mesh = pair_mesh(gap)
            s = af.solve(mesh, 1.0, lin)
            fx = ts.converged_force(1000.0, gap, "axial", rtol=1e-8)[0]
            mx = 2.0 * ts.converge(1000.0, gap, "axial", rtol=1e-8)[1].moment
            self.assertLess(abs(af.force(mesh, s, 0) / fx - 1), 5e-3, gap)
            self.assertLess(abs(af.moment(mesh, s) / mx - 1), 1e-2, gap)

    def test_tanh_at_low_field_is_linear(self):
        # H0 = 1e-6 Ms: the tanh curve is its tangent; force scales as H0^2
        mesh = pair_mesh(0.1)
        s = af.solve(mesh, 1e-6)
        sl = af.solve(mesh, 1.0, af.Material(1000.0, linear=True))
        self.assertLess(abs(af.force(mesh, s, 0) / (1e-12 * af.force(mesh, sl, 0)) - 1), 1e-6)


class Nonlinear(unittest.TestCase):
    def test_saturated_spheres_are_two_dipoles(self):
        # H0 = 10 Ms: M = Ms everywhere (nearly uniform), so each moment is 4 pi/3 Ms a^3 (less
        # the polygonal sphere's volume deficit, O(h^2)) and the force that of two dipoles
        mesh = pair_mesh(0.3)
        s = af.solve(mesh, 10.0)
        vol = float(np.sum(mesh.w[mesh.iron]))  # the half domain holds one sphere
        self.assertLess(abs(vol / (4 * math.pi / 3) - 1), 1e-2)
        self.assertLess(abs(af.moment(mesh, s) / (2 * vol) - 1), 1e-3)
        m = vol
        dipoles = -3.0 * m * m / (2 * math.pi * 2.3 ** 4)
        self.assertLess(abs(af.force(mesh, s, 0) / dipoles - 1), 2e-2)

    def test_lone_sphere_on_the_knee(self):
        # a sphere in a uniform field magnetizes uniformly for any isotropic law, M = f(H0 - M/3):
        # two spheres 20a apart (their coupling is 2e-4 of H0) at the knee of the tanh curve;
        # level 1 leaves 0.7 % in the moment at every field (0.06 % at level 4)
        from scipy.optimize import brentq
        mesh = pair_mesh(20.0)
        vol = float(np.sum(mesh.w[mesh.iron]))
        for h in (0.1, 0.3, 0.33):
            s = af.solve(mesh, h)
            want = brentq(lambda M: M - math.tanh(999.0 * (h - M / 3.0)), 0.0, 1.0)
            self.assertLess(abs(af.moment(mesh, s) / (2 * vol * want) - 1), 1e-2, h)

    def test_coenergy_derivative_equals_maxwell_stress(self):
        mesh = pair_mesh(0.1)
        s = af.solve(mesh, 0.1)
        fm = af.force(mesh, s, 0)
        fc = af.coenergy_force(mesh, 0.1, 0, 1e-3, phi0=s.phi)
        self.assertLess(fm, 0.0)  # attraction
        self.assertLess(abs(fc / fm - 1), 1e-3)

    def test_chain_end_ball_is_pulled_in(self):
        ch = af.Chain(3, 0.03)
        mesh = af.Mesh(ch, af.default_R(ch), 1.0)
        s = af.solve(mesh, 0.01)
        self.assertEqual(len(ch.centres), 2)
        self.assertLess(af.force(mesh, s, 1), 0.0)
        self.assertGreater(af.moment(mesh, s), 3 * 4 * math.pi / 3 * 3 * 0.01 * 0.9)


class Mesh(unittest.TestCase):
    def test_triangles_lie_in_one_material(self):
        mesh = pair_mesh(0.003)
        x = mesh.p[mesh.t]
        mixed = 0
        for wts in ([0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6]):
            q = np.einsum("k,ekd->ed", np.array(wts), x)
            inside = np.hypot(q[:, 0], q[:, 1] - mesh.chain.centres[0]) < 1.0
            mixed += int(np.sum(inside != mesh.iron))
        self.assertLess(mixed, 0.002 * len(mesh.t))
        self.assertTrue(np.all(mesh.area > 0))


if __name__ == "__main__":
    unittest.main(verbosity=2)
