// SimOptions::balance_magnetic_torque (engine/apply_forces.cpp): the reaction-symmetric
// Zeeman forces sum to zero but leave a net torque; the balance cancels it with the least
// forces that do.
#include "engine/simulation.hpp"
#include "engine/stages.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <random>

using namespace magsim;
using namespace magsim::test;

namespace {

double weighted_norm(const std::vector<Vec3>& f, const std::vector<double>& w) {
  double s = 0;
  for (std::size_t b = 0; b < f.size(); ++b)
    if (w[b] > 0) s += f[b].squaredNorm() / w[b];
  return s;
}

Vec3 net_force(const std::vector<Vec3>& f) {
  Vec3 s = Vec3::Zero();
  for (const Vec3& v : f) s += v;
  return s;
}

Vec3 net_torque(const std::vector<Vec3>& x, const std::vector<Vec3>& f) {
  Vec3 s = Vec3::Zero();
  for (std::size_t b = 0; b < f.size(); ++b) s += x[b].cross(f[b]);
  return s;
}

}  // namespace

TEST_CASE("torque balance: the least forces with no net force that cancel a net torque",
          "[torque_balance]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  std::vector<Vec3> x(12);
  std::vector<double> w(12);
  for (std::size_t b = 0; b < x.size(); ++b) {
    x[b] = Vec3(u(rng), u(rng), u(rng));
    w[b] = b % 4 == 3 ? 0.0 : 0.1 + 10 * std::abs(u(rng));  // every fourth body takes none
  }
  const Vec3 L(0.3, -0.7, 0.2);  // N·m
  std::vector<Vec3> dF;
  engine::torque_balance_forces(x, w, L, &dF);
  double largest = 0;
  for (const Vec3& f : dF) largest = std::max(largest, f.norm());
  REQUIRE(largest > 0);
  CHECK(net_force(dF).norm() <= 1e-12 * largest);
  CHECK((net_torque(x, dF) + L).norm() <= 1e-10 * L.norm());  // about the origin: Σ δF = 0
  for (std::size_t b = 3; b < x.size(); b += 4) CHECK(dF[b] == Vec3::Zero());
  // least: any other correction differs by forces with no net force and no net torque, e.g.
  // two opposite forces along the line through two bodies; each makes it larger
  const double best = weighted_norm(dF, w);
  for (double e : {-1e-3, 1e-3, 0.5}) {
    std::vector<Vec3> other = dF;
    const Vec3 along = (x[0] - x[5]).normalized();
    other[0] += e * along;
    other[5] -= e * along;
    CHECK((net_torque(x, other) + L).norm() <= 1e-10 * L.norm());
    CHECK(weighted_norm(other, w) > best);
  }
}

TEST_CASE("torque balance: bodies on a line cancel what forces can and nothing else",
          "[torque_balance]") {
  // forces on bodies along x make no torque about x: that part of L stays, the rest goes
  const std::vector<Vec3> x = {Vec3(-0.02, 0, 0), Vec3(0.01, 0, 0), Vec3(0.04, 0, 0)};
  const std::vector<double> w = {1.0, 2.0, 0.5};
  const Vec3 L(0.4, -0.1, 0.3);
  std::vector<Vec3> dF;
  engine::torque_balance_forces(x, w, L, &dF);
  for (const Vec3& f : dF) REQUIRE(f.allFinite());
  CHECK(net_force(dF).norm() <= 1e-12);
  const Vec3 left = net_torque(x, dF) + L;
  CHECK(std::abs(left.x() - 0.4) <= 1e-12);
  CHECK(std::abs(left.y()) <= 1e-12);
  CHECK(std::abs(left.z()) <= 1e-12);
  // no weight at all: nothing to do
  engine::torque_balance_forces(x, {0.0, 0.0, 0.0}, L, &dF);
  for (const Vec3& f : dF) CHECK(f == Vec3::Zero());
}

namespace {

// A free NdFeB sphere magnet (tilted moment) with iron balls stuck on it and on each other,
// no gravity, no ground: nothing outside acts, so the total angular momentum must stay 0.
engine::SceneDesc free_magnet_with_iron(bool balance) {
  engine::SceneDesc s = free_space("free_magnet");
  s.options.reaction_symmetric_forces = true;
  s.options.balance_magnetic_torque = balance;
  engine::BodyDesc magnet;
  magnet.name = "magnet";
  magnet.magnet = true;
  magnet.density = 7500.0;
  magnet.shapes.push_back({ShapeKind::Sphere, Vec3::Zero(), Quat::Identity(), Vec3(kR, kR, kR)});
  MomentDesc md;
  md.permanent = true;
  md.volume = sphere_volume(kR);
  md.moment = Vec3(0.3, -0.2, 1.0).normalized() * 1.2e6 * sphere_volume(kR);  // NdFeB, A·m²
  magnet.moments.push_back(md);
  s.bodies.push_back(magnet);
  // an uneven cluster, every ball touching the magnet or a ball: a chain of three below, two
  // on one side, one on top
  const double d = 2 * kR;
  const std::vector<Vec3> at = {Vec3(0, 0, -d),      Vec3(0, 0, -2 * d),  Vec3(0.004, 0, -3 * d),
                                Vec3(d, 0, 0),       Vec3(2 * d, 0.002, 0), Vec3(0, 0.002, d)};
  for (std::size_t k = 0; k < at.size(); ++k) s.bodies.push_back(iron_ball("ball_" + std::to_string(k), at[k]));
  return s;
}

Vec3 angular_momentum(const engine::Simulation& sim) {
  const engine::Model& m = sim.model();
  Vec3 L = Vec3::Zero();
  for (int b : m.dynamic_bodies) {
    const engine::Mat3 R = sim.body_orientation(b).toRotationMatrix();
    L += m.body_mass[b] * sim.body_position(b).cross(sim.body_velocity(b)) +
         R * m.body_inertia[b] * R.transpose() * sim.body_angular_velocity(b);
  }
  return L;
}

}  // namespace

TEST_CASE("torque balance: a free magnet with iron on it keeps zero angular momentum",
          "[torque_balance]") {
  // Without the balance the magnetic forces alone spin the free cluster up (their sum is
  // zero, their torque is not); with it the angular momentum stays at ODE's round-off.
  auto run = [](bool balance) {
    engine::Simulation sim(free_magnet_with_iron(balance));
    double largest = 0;
    for (int k = 0; k < 300; ++k) {
      sim.step();
      largest = std::max(largest, angular_momentum(sim).norm());
    }
    return std::make_pair(largest, sim.metrics().momentum.norm());
  };
  const auto [off, p_off] = run(false);
  const auto [on, p_on] = run(true);
  INFO("largest |L| over 0.3 s: without the balance " << off << ", with it " << on
                                                       << " kg m^2/s; |p| " << p_off << ", " << p_on);
  CHECK(off > 1e-7);
  CHECK(on < 1e-3 * off);
  CHECK(p_off < 1e-9);  // the symmetric forces conserve momentum either way
  CHECK(p_on < 1e-9);
}
