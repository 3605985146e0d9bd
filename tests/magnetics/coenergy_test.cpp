// Tests for magnetics/coenergy.cpp: with converged magnetizations the classic forces and
// torques (forces.hpp) are −∇U* — checked by central differences of U*, every magnetization
// re-solved exactly at each displaced pose — for both curves, permanent moments and their
// torques, bodies of several moments, softening and bounded pairs; the classic force does no
// work around a closed loop; eq. 4 does, and is not −∇U*.
#include "magnetics/coenergy.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "magnetics/near_field.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>

using namespace magsim::mag;
using magsim::test::ball_volume;
using magsim::test::kBallRadius;
using magsim::test::kIronMs;

namespace {

// U* of s with the induced magnetizations re-solved exactly at s's poses (J)
double coenergy_solved(MomentSet s, Curve c, const FieldOptions& f) {
  const ExactStats st = solve_exact(&s, c, f, 1e-14, 100);
  REQUIRE(st.residual < 1e-11);
  FieldWorkspace ws;
  std::vector<Vec3> H;
  compute_fields(s, f, &H, nullptr, &ws);
  return magnetic_coenergy(s, s, c, H, f.near_field, &ws.near);
}

// forces and torques of `model` at the exact solution of s
void forces_solved(MomentSet* s, Curve c, const FieldOptions& f, ForceModel model,
                   std::vector<Vec3>* F, std::vector<Vec3>* tau) {
  REQUIRE(solve_exact(s, c, f, 1e-14, 100).residual < 1e-11);
  MagWorkspace ws;
  compute_forces(*s, model, c, f, &ws, F, tau);
}

// −∂U*/∂x by central differences, where move(s, ±h) displaces the coordinate x by ±h
double fd(const MomentSet& s, Curve c, const FieldOptions& f, double h,
          const std::function<void(MomentSet*, double)>& move) {
  MomentSet p = s, m = s;
  move(&p, h);
  move(&m, -h);
  return -(coenergy_solved(p, c, f) - coenergy_solved(m, c, f)) / (2 * h);
}

// Rotates the moments of group g about c by angle t about axis e (positions, and the
// permanent moments with their body; induced M is re-solved by coenergy_solved).
void rotate_group(MomentSet* s, int g, const Vec3& c, const Vec3& e, double t) {
  const Mat3 R = Eigen::AngleAxisd(t, e).toRotationMatrix();
  for (std::size_t j = 0; j < s->size(); ++j) {
    if (s->group[j] != g) continue;
    s->position[j] = c + R * (s->position[j] - c);
    if (s->kind[j] == MomentKind::Permanent) {
      s->m_perm[j] = R * s->m_perm[j];
      s->M[j] = s->m_perm[j] / s->volume[j];
    }
  }
}

// The largest |(−∇U*) − F| over every group's net force and torque (rigid bodies: the
// groups, and each ungrouped moment on its own) against the largest |F|, |τ|·(1 cm).
struct Check {
  double worst_force = 0, worst_torque = 0;  // relative errors
};
Check check_gradient(const MomentSet& s0, Curve c, const FieldOptions& f, ForceModel model,
                     double h = 1e-7) {
  MomentSet s = s0;
  std::vector<Vec3> F, tau;
  forces_solved(&s, c, f, model, &F, &tau);
  double Fmax = 0, Tmax = 0;
  for (std::size_t j = 0; j < s.size(); ++j) Fmax = std::max(Fmax, F[j].norm());
  // bodies: every group id ≥ 0, and singletons (group −1) as bodies of their own
  std::vector<std::vector<int>> bodies;
  std::vector<int> ids;
  for (std::size_t j = 0; j < s.size(); ++j) {
    if (s.group[j] < 0) {
      bodies.push_back({static_cast<int>(j)});
      continue;
    }
    if (std::find(ids.begin(), ids.end(), s.group[j]) == ids.end()) {
      ids.push_back(s.group[j]);
      bodies.push_back({static_cast<int>(j)});
      continue;
    }
    for (auto& b : bodies)
      if (s.group[b[0]] == s.group[j]) {
        b.push_back(static_cast<int>(j));
        break;
      }
  }
  const double ht = 1e-5;  // rad; h in m
  Check r;
  std::vector<Vec3> Fb(bodies.size()), Tb(bodies.size());
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    Vec3 cen = Vec3::Zero();
    for (int j : bodies[b]) cen += s.position[j];
    cen /= static_cast<double>(bodies[b].size());
    Fb[b].setZero();
    Tb[b].setZero();
    for (int j : bodies[b]) {
      Fb[b] += F[j];
      Tb[b] += (s.position[j] - cen).cross(F[j]) + tau[j];
    }
    Tmax = std::max(Tmax, Tb[b].norm() / 0.01);
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    Vec3 cen = Vec3::Zero();
    for (int j : bodies[b]) cen += s.position[j];
    cen /= static_cast<double>(bodies[b].size());
    // a body of one moment with group −1: give it a group of its own for the rotation
    MomentSet base = s;
    const int g = base.group[bodies[b][0]] >= 0 ? base.group[bodies[b][0]] : 1000000 + static_cast<int>(b);
    for (int j : bodies[b]) base.group[j] = g;
    for (int a = 0; a < 3; ++a) {
      const Vec3 e = Vec3::Unit(a);
      const double Ffd = fd(base, c, f, h, [&](MomentSet* t, double d) {
        for (int j : bodies[b]) t->position[j] += d * e;
      });
      r.worst_force = std::max(r.worst_force, std::abs(Ffd - Fb[b][a]) / Fmax);
      const double Tfd = fd(base, c, f, ht, [&](MomentSet* t, double d) { rotate_group(t, g, cen, e, d); });
      r.worst_torque = std::max(r.worst_torque, std::abs(Tfd - Tb[b][a]) / (0.01 * Tmax));
    }
  }
  return r;
}

// n iron balls at random (≥ min_gap radii apart) in a 4 cm box, one permanent magnet and H0
MomentSet random_set(int n, unsigned seed, double strength, double min_gap = 2.2) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  MomentSet s;
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Vec3 p(u(rng), u(rng), u(rng));
    bool ok = p.norm() > 0.011;
    for (const Vec3& q : pts) ok = ok && (p - q).norm() > min_gap * kBallRadius;
    if (ok) pts.push_back(p);
  }
  for (const Vec3& p : pts) s.add_induced(p, ball_volume(), kIronMs);
  s.add_permanent(Vec3(0, 0, 0), 1e-6, Vec3(0.3, -0.2, 1.0).normalized() * strength);
  s.H0 = Vec3(2e3, -1e3, 5e2);
  return s;
}

}  // namespace

TEST_CASE("curve energy density: Psi' = |f^-1|, Psi ~ |M|^2/6 at small M", "[coenergy]") {
  const double Ms = kIronMs;
  for (double x : {1e-5, 1e-3, 0.1, 0.5, 0.9, 0.999}) {
    const double M = x * Ms, d = 1e-6 * Ms;
    const double dPsi = (curve_energy_density(Curve::Tanh, M + d, Ms) -
                         curve_energy_density(Curve::Tanh, M - d, Ms)) / (2 * d);
    CHECK(dPsi == Approx(tanh_inverse_norm(M, Ms)).epsilon(1e-6));
    CHECK(curve_energy_density(Curve::Kim, M, Ms) == Approx(M * M / 6.0).epsilon(1e-15));
  }
  CHECK(curve_energy_density(Curve::Tanh, 1e-4 * Ms, Ms) == Approx(1e-8 * Ms * Ms / 6.0).epsilon(1e-8));
  // the iron sphere: Ψ' = |f⁻¹(M)| = Ms(atanh(x)/χ + x/3), read from |H| where f(H) = M
  for (double h : {1e-4, 0.05, 0.2, 0.3, 0.33}) {
    const double M = curve_M(Curve::Iron, Vec3(0, 0, h * Ms), Ms).z(), d = 1e-7 * Ms;
    const double dPsi = (curve_energy_density(Curve::Iron, M + d, Ms) -
                         curve_energy_density(Curve::Iron, M - d, Ms)) / (2 * d);
    INFO("|H|/Ms " << h << ", |M|/Ms " << M / Ms);
    CHECK(dPsi == Approx(h * Ms).epsilon(1e-6));
  }
  // at saturation Ψ = (Ms²/3) ln 2, finite
  CHECK(curve_energy_density(Curve::Tanh, Ms, Ms) == Approx(Ms * Ms * std::log(2.0) / 3.0).epsilon(1e-14));
}

TEST_CASE("classic force and torques are -grad U*: tanh curve, permanent moment, H0", "[coenergy]") {
  for (double strength : {0.3, 30.0}) {  // weak: linear range; strong: saturated near the magnet
    const Check r = check_gradient(random_set(11, 7, strength), Curve::Tanh, FieldOptions{}, ForceModel::Classic);
    INFO("strength " << strength << " force " << r.worst_force << " torque " << r.worst_torque);
    CHECK(r.worst_force < 1e-6);
    CHECK(r.worst_torque < 1e-6);
  }
}

TEST_CASE("classic force is -grad U* with eq. 7's curve", "[coenergy]") {
  const Check r = check_gradient(random_set(9, 3, 10.0), Curve::Kim, FieldOptions{}, ForceModel::Classic);
  INFO("force " << r.worst_force << " torque " << r.worst_torque);
  CHECK(r.worst_force < 1e-6);
  CHECK(r.worst_torque < 1e-6);
}

TEST_CASE("classic torques are -grad U* for bodies of several moments", "[coenergy]") {
  // three "letters" of three induced moments in an L shape, and a body of two permanent
  // moments; the letters feel the shape torque −μ0 m × H^same
  MomentSet s;
  const double a = kBallRadius, V = ball_volume();
  const Vec3 at[3] = {Vec3(0.02, 0.0, 0.004), Vec3(-0.015, 0.018, -0.006), Vec3(0.003, -0.022, 0.012)};
  for (int g = 0; g < 3; ++g) {
    s.add_induced(at[g], V, kIronMs, g);
    s.add_induced(at[g] + Vec3(2.1 * a, 0.3 * a, 0), V, kIronMs, g);
    s.add_induced(at[g] + Vec3(0, 2.1 * a, 0.4 * a), V, kIronMs, g);
  }
  s.add_permanent(Vec3(0, 0, -0.004), 1e-6, Vec3(0.2, 0.1, 3.0), 5);
  s.add_permanent(Vec3(0, 0, 0.004), 1e-6, Vec3(-0.1, 0.3, 3.0), 5);
  s.H0 = Vec3(1e3, 2e3, -5e2);
  const Check r = check_gradient(s, Curve::Tanh, FieldOptions{}, ForceModel::Classic);
  INFO("force " << r.worst_force << " torque " << r.worst_torque);
  CHECK(r.worst_force < 1e-6);
  CHECK(r.worst_torque < 1e-6);
}

TEST_CASE("classic force is -grad U* with softening and with bounded pairs", "[coenergy]") {
  SECTION("softening 3 mm, balls closer than a diameter") {
    FieldOptions f;
    f.softening = 0.003;
    const Check r = check_gradient(random_set(10, 11, 20.0, 1.6), Curve::Tanh, f, ForceModel::Classic);
    INFO("force " << r.worst_force << " torque " << r.worst_torque);
    CHECK(r.worst_force < 1e-6);
    CHECK(r.worst_torque < 1e-6);
  }
  SECTION("bounded pairs, some pairs inside their bound") {
    FieldOptions f;
    f.bounded_pairs = true;
    MomentSet s = random_set(10, 5, 20.0);
    // two pairs inside their bound (1.7 and 1.85 radii apart, the bound is 2)
    s.position[1] = s.position[0] + 1.7 * kBallRadius * Vec3(0.6, -0.48, 0.64);
    s.position[3] = s.position[2] + 1.85 * kBallRadius * Vec3(0, 0.8, -0.6);
    int inside = 0;
    for (std::size_t j = 0; j < s.size(); ++j)
      s.radius[j] = s.kind[j] == MomentKind::Induced ? kBallRadius : 0.0;
    for (std::size_t i = 0; i < s.size(); ++i)
      for (std::size_t j = i + 1; j < s.size(); ++j)
        inside += (s.position[i] - s.position[j]).norm() < s.radius[i] + s.radius[j];
    REQUIRE(inside >= 2);
    const Check r = check_gradient(s, Curve::Tanh, f, ForceModel::Classic);
    INFO(inside << " pairs inside; force " << r.worst_force << " torque " << r.worst_torque);
    CHECK(r.worst_force < 1e-6);
    CHECK(r.worst_torque < 1e-6);
  }
}

TEST_CASE("classic force with the near-field pair model is -grad U*", "[coenergy][near_field]") {
  // pairs at gaps of 0.003a, 0.05a, 0.4a and 1.4a (the cut-off step), in the fade's range
  // (weak magnet) and saturated (strong): the forces on balls and magnet, the magnet's torque;
  // on eq. 10's curve and on the iron sphere's, each with its own widening
  for (const Curve curve : {Curve::Tanh, Curve::Iron}) {
    for (double strength : {0.3, 30.0}) {
      FieldOptions f;
      f.near_field.model = NearField::Pair;
      f.near_field.curve = curve;
      MomentSet s = random_set(10, 5, strength, 2.5);
      const double a = kBallRadius;
      s.position[1] = s.position[0] + 2.003 * a * Vec3(0.6, -0.48, 0.64);
      s.position[3] = s.position[2] + 2.05 * a * Vec3(0, 0.8, -0.6);
      s.position[5] = s.position[4] + 2.4 * a * Vec3(0.36, 0.48, 0.8);
      s.position[7] = s.position[6] + 3.4 * a * Vec3(1, 0, 0);
      NearFieldWorkspace nws;
      find_near_pairs(s, &nws);
      REQUIRE(nws.pairs.size() >= 4);
      // steps of 20 nm: the closest pair's force changes on the scale of its 15 µm gap
      const Check r = check_gradient(s, curve, f, ForceModel::Classic, 2e-8);
      INFO(kCurveNames.name(curve) << ", strength " << strength << ": " << nws.pairs.size()
                                   << " near pairs; force " << r.worst_force << " torque " << r.worst_torque);
      CHECK(r.worst_force < 1e-6);
      CHECK(r.worst_torque < 1e-6);
    }
  }
  SECTION("eq. 7's curve") {
    FieldOptions f;
    f.near_field.model = NearField::Pair;
    MomentSet s = random_set(8, 3, 10.0, 2.5);
    s.position[1] = s.position[0] + 2.01 * kBallRadius * Vec3(0, 0, 1);
    const Check r = check_gradient(s, Curve::Kim, f, ForceModel::Classic, 2e-8);
    INFO("force " << r.worst_force << " torque " << r.worst_torque);
    CHECK(r.worst_force < 1e-6);
    CHECK(r.worst_torque < 1e-6);
  }
}

TEST_CASE("eq. 4 is not -grad U*", "[coenergy]") {
  const Check r = check_gradient(random_set(11, 7, 0.3), Curve::Tanh, FieldOptions{}, ForceModel::Zeeman);
  INFO("force " << r.worst_force);
  // in the linear range eq. 4 is 8 ∇U*: 7/8 of it is surplus
  CHECK(r.worst_force > 0.3);
}

TEST_CASE("classic force does no work around a closed loop, eq. 4 does", "[coenergy]") {
  // one ball carried around a circle of radius 4 mm past another ball and the magnet, the
  // work Σ F·dp by the trapezoid rule, every magnetization re-solved at each point
  MomentSet s;
  s.add_induced(Vec3(0.012, 0, 0), ball_volume(), kIronMs);
  s.add_induced(Vec3(0.012, 0, 0.0115), ball_volume(), kIronMs);
  s.add_permanent(Vec3(0, 0, 0), 1e-6, Vec3(0, 0, 1.0));
  s.H0 = Vec3(0, 0, 1e3);
  const Vec3 c0 = s.position[1];
  auto work = [&](ForceModel model) {
    const int N = 400;
    double W = 0, path = 0;
    Vec3 prevF = Vec3::Zero(), prevP = Vec3::Zero();
    for (int k = 0; k <= N; ++k) {
      const double t = 2 * kPi * k / N;
      MomentSet t_s = s;
      t_s.position[1] = c0 + 0.004 * Vec3(std::cos(t) - 1, std::sin(t), 0.3 * std::sin(t));
      std::vector<Vec3> F, tau;
      forces_solved(&t_s, Curve::Tanh, FieldOptions{}, model, &F, &tau);
      if (k > 0) {
        const Vec3 dp = t_s.position[1] - prevP;
        W += 0.5 * (F[1] + prevF).dot(dp);
        path += 0.5 * (F[1].norm() + prevF.norm()) * dp.norm();
      }
      prevF = F[1];
      prevP = t_s.position[1];
    }
    return W / path;
  };
  const double classic = work(ForceModel::Classic), zeeman = work(ForceModel::Zeeman);
  INFO("loop work / path work: classic " << classic << ", eq. 4 " << zeeman);
  CHECK(std::abs(classic) < 1e-5);  // the trapezoid's O(1/N²) error, not a surplus
  CHECK(std::abs(zeeman) > 10 * std::abs(classic));
}
