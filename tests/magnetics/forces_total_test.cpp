// Tests for ForceModel::ZeemanTotal (magnetics/forces_total.cpp): the forces and torques are
// the negative gradient of E_sys with every magnetization re-solved (finite differences),
// one moment in a fixed field gets eq. 4 exactly, and the forces sum to zero.
#include "magnetics/forces.hpp"
#include "magnetics/forces_total.hpp"
#include "magnetics/ground_truth.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

using namespace magsim::mag;

namespace {
// E_sys with the magnetization re-solved to equilibrium (Newton, 1e-13)
double energy_at_equilibrium(MomentSet s, const FieldOptions& opt) {
  REQUIRE(solve_exact(&s, Curve::Tanh, opt, 1e-13).converged);
  FieldWorkspace ws;
  return zeeman_total_energy(s, Curve::Tanh, opt, &ws);
}

struct Worst {
  double force = 0, torque = 0, eq4 = 0;
};

// worst relative error of F (every moment) and of τ (the permanent moments) against
// −∂E_sys/∂p and −∂E_sys/∂θ by central differences; `eq4`: the same for the literal eq. 4
Worst gradient_check(MomentSet s, const FieldOptions& opt) {
  REQUIRE(solve_exact(&s, Curve::Tanh, opt, 1e-13).converged);
  MagWorkspace ws;
  std::vector<Vec3> F, tau, F4;
  compute_forces(s, ForceModel::ZeemanTotal, Curve::Tanh, opt, &ws, &F, &tau, nullptr, false,
                 1e-12, 500);
  REQUIRE(ws.total.converged);
  compute_forces(s, ForceModel::Zeeman, Curve::Tanh, opt, &ws, &F4, nullptr);
  const double h = 1e-7;  // (m), (rad)
  Worst w;
  for (std::size_t j = 0; j < s.size(); ++j) {
    Vec3 Ffd, Tfd;
    for (int b = 0; b < 3; ++b) {
      MomentSet sp = s, sm = s;
      sp.position[j][b] += h;
      sm.position[j][b] -= h;
      Ffd[b] = -(energy_at_equilibrium(sp, opt) - energy_at_equilibrium(sm, opt)) / (2 * h);
      if (s.kind[j] == MomentKind::Permanent) {
        const Vec3 axis = Vec3::Unit(b);
        sp = s;
        sm = s;
        sp.m_perm[j] = Eigen::AngleAxisd(h, axis) * s.m_perm[j];
        sm.m_perm[j] = Eigen::AngleAxisd(-h, axis) * s.m_perm[j];
        Tfd[b] = -(energy_at_equilibrium(sp, opt) - energy_at_equilibrium(sm, opt)) / (2 * h);
      }
    }
    w.force = std::max(w.force, (F[j] - Ffd).norm() / Ffd.norm());
    // the torque's scale: μ0 |m| |H| at the moment (a symmetric pile has τ = 0 exactly)
    if (s.kind[j] == MomentKind::Permanent)
      w.torque = std::max(w.torque, (tau[j] - Tfd).norm() / (kMu0 * s.m_perm[j].norm() * ws.H[j].norm()));
    else
      w.eq4 = std::max(w.eq4, (F4[j] - Ffd).norm() / Ffd.norm());
  }
  return w;
}
}  // namespace

TEST_CASE("ZeemanTotal forces and torques are −∇E_sys with every magnetization re-solved",
          "[forces][fd]") {
  // 12 balls and a magnet: linear to mid-curve (3 A·m²), several balls near saturation (300)
  for (double strength : {3.0, 300.0}) {
    const Worst w = gradient_check(magsim::test::random_cloud(12, 5, strength), FieldOptions{});
    INFO("magnet " << strength << " A·m²: worst force error " << w.force << ", torque "
                   << w.torque << "; the literal eq. 4 against the same gradient " << w.eq4);
    CHECK(w.force <= 1e-5);
    CHECK(w.torque <= 1e-5);
  }
  // a touching 36-ball pile under a strong magnet, softened: the neighbours' share of the
  // gradient, which the literal eq. 4 leaves out, is large there
  FieldOptions soft;
  soft.softening = 0.001;
  const Worst w = gradient_check(magsim::test::cluster(50.0), soft);
  INFO("pile: worst force error " << w.force << ", torque " << w.torque << "; literal eq. 4 "
                                  << w.eq4);
  CHECK(w.force <= 1e-5);
  CHECK(w.torque <= 1e-5);
  CHECK(w.eq4 > 0.1);
}

TEST_CASE("ZeemanTotal is eq. 4 for one induced moment in a fixed field", "[forces]") {
  MomentSet s;
  s.add_permanent(Vec3(0, 0, 0), 1e-6, Vec3(0, 0, 5.0));
  s.add_induced(Vec3(0.003, 0.001, 0.02), magsim::test::ball_volume(), magsim::test::kIronMs);
  REQUIRE(solve_exact(&s, Curve::Tanh, FieldOptions{}).converged);
  MagWorkspace ws;
  std::vector<Vec3> F, Ft;
  compute_forces(s, ForceModel::Zeeman, Curve::Tanh, FieldOptions{}, &ws, &F, nullptr);
  compute_forces(s, ForceModel::ZeemanTotal, Curve::Tanh, FieldOptions{}, &ws, &Ft, nullptr);
  CHECK(Ft[1].isApprox(F[1], 1e-12));
  CHECK(ws.total.iterations == 0);  // no other induced moment: nothing to solve
  // action = reaction: the magnet gets the opposite force
  CHECK((Ft[0] + Ft[1]).norm() <= 1e-12 * Ft[1].norm());
}

TEST_CASE("ZeemanTotal forces sum to zero and the adjoint solve converges on a pile",
          "[forces]") {
  MomentSet s = magsim::test::cluster(500.0);
  REQUIRE(solve_exact(&s, Curve::Tanh, FieldOptions{}).converged);
  MagWorkspace ws;
  std::vector<Vec3> F;
  compute_forces(s, ForceModel::ZeemanTotal, Curve::Tanh, FieldOptions{}, &ws, &F, nullptr);
  INFO("CG iterations " << ws.total.iterations << ", residual " << ws.total.residual);
  CHECK(ws.total.converged);
  Vec3 net = Vec3::Zero();
  double largest = 0;
  for (const Vec3& f : F) {
    net += f;
    largest = std::max(largest, f.norm());
  }
  CHECK(net.norm() <= 1e-3 * largest);  // to the CG tolerance (1e-4)
  // warm start: the same state again needs no iteration
  compute_forces(s, ForceModel::ZeemanTotal, Curve::Tanh, FieldOptions{}, &ws, &F, nullptr);
  CHECK(ws.total.iterations == 0);
}
