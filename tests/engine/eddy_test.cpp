// SimOptions::eddy_conductivity (engine/eddy.cpp): the eddy-current loss of an induced body
// whose flux density changes in its own frame.
#include "engine/simulation.hpp"
#include "engine/stages.hpp"
#include "fixtures.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/dipole_field.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace magsim;
using namespace magsim::test;

TEST_CASE("eddy: dB/dp is the derivative of B = mu0 (H + 2/3 f(H)) near a dipole (finite differences)",
          "[eddy]") {
  // eq. 1's field of a 1 A.m^2 dipole, at points where the iron is linear, bent and saturated
  const Vec3 m(0.2, -0.3, 1.0);
  const double Ms = 1.6e6;
  for (const mag::Curve curve : {mag::Curve::Tanh, mag::Curve::Kim}) {
    for (const Vec3& p : {Vec3(0.011, 0.004, 0.009), Vec3(0.03, -0.01, 0.02), Vec3(0.002, 0.08, -0.05)}) {
      auto B = [&](const Vec3& q) {
        const Vec3 H = mag::dipole_field(q, m);
        return engine::eddy_flux_density(H, mag::curve_M(curve, H, Ms));
      };
      const Vec3 H = mag::dipole_field(p, m);
      const engine::Mat3 G = engine::eddy_flux_gradient(curve, H, Ms, mag::dipole_jacobian(p, m));
      const double d = 1e-7 * p.norm();
      engine::Mat3 fd;
      for (int k = 0; k < 3; ++k) {
        const Vec3 e = Vec3::Unit(k) * d;
        fd.col(k) = (B(p + e) - B(p - e)) / (2 * d);
      }
      INFO("curve " << static_cast<int>(curve) << " at " << p.transpose() << ": |H|/Ms " << H.norm() / Ms);
      CHECK((G - fd).norm() <= 1e-6 * fd.norm());
    }
  }
}

namespace {

// One iron ball in a uniform field, no gravity, no ground: nothing but the eddy loss acts on
// its spin.
engine::SceneDesc spinning_ball(const Vec3& w0, double sigma) {
  engine::SceneDesc s = free_space("spinning_ball");
  s.options.eddy_conductivity = sigma;
  s.H0 = Vec3(0, 0, 1e5);  // A/m: M = Ms tanh(3 |H| / Ms) = 0.19 Ms
  BodyDesc ball = iron_ball("ball", Vec3::Zero());
  ball.angular_velocity = w0;
  s.bodies.push_back(ball);
  return s;
}

}  // namespace

TEST_CASE("eddy: a ball spinning across a field slows at c |B|^2 / I, one spinning about it keeps its spin",
          "[eddy]") {
  const double sigma = 1e7, h = 1e-3;
  const int steps = 40;
  // the rate: P = c |Bdot|^2 with Bdot = omega x B, so I domega/dt = -c |B|^2 omega
  const Vec3 H0(0, 0, 1e5);
  const Vec3 B = engine::eddy_flux_density(H0, mag::curve_M(mag::Curve::Tanh, H0, 1.6e6));
  const double V = sphere_volume(kR), mass = 7870.0 * V, I = 0.4 * mass * kR * kR;
  const double k = engine::eddy_coefficient(sigma, V) * B.squaredNorm() / I;
  REQUIRE(k * h > 0.02);  // a measurable decay over the run
  REQUIRE(k * h < 0.2);

  engine::Simulation across(spinning_ball(Vec3(200, 0, 0), sigma));
  REQUIRE(across.model().body_mass[0] == Approx(mass).epsilon(1e-12));  // iron's density
  for (int s = 0; s < steps; ++s) across.step();
  // backward Euler over every step but the first (no previous B to measure Bdot from)
  const double expect = 200.0 * std::pow(1.0 + k * h, -(steps - 1));
  const Vec3 w = across.body_angular_velocity(0);
  INFO("omega after " << steps << " steps " << w.transpose() << ", expected " << expect << " (k = " << k << " /s)");
  CHECK(w.x() == Approx(expect).epsilon(0.02));
  CHECK(std::abs(w.y()) + std::abs(w.z()) < 1e-3 * expect);
  CHECK(across.body_velocity(0).norm() < 1e-9);  // a uniform field: no drag on the centre
  // the audit books the loss as the eddy channel's work, nothing is left to the contacts
  const engine::EnergyFlow& e = across.energy().total;
  CHECK(e.eddy_work == Approx(e.kinetic_change).epsilon(1e-9));
  CHECK(e.eddy_work < -0.9 * 0.5 * I * 200.0 * 200.0);
  CHECK(std::abs(e.contact_work) < 1e-9 * std::abs(e.eddy_work));

  engine::Simulation about(spinning_ball(Vec3(0, 0, 200), sigma));
  for (int s = 0; s < steps; ++s) about.step();
  CHECK(about.body_angular_velocity(0).z() == Approx(200.0).epsilon(1e-9));
  CHECK(std::abs(about.energy().total.eddy_work) < 1e-9 * 0.5 * I * 200.0 * 200.0);

  engine::Simulation without(spinning_ball(Vec3(200, 0, 0), 0.0));
  for (int s = 0; s < steps; ++s) without.step();
  CHECK(without.body_angular_velocity(0).x() == Approx(200.0).epsilon(1e-12));
  CHECK(without.energy().total.eddy_work == 0.0);
}

TEST_CASE("eddy: a ball flying past a magnet only loses energy to the loss", "[eddy]") {
  // a fixed 1 A.m^2 magnet, a ball passing 3 cm from it at 1 m/s. In a still field the loss
  // would take energy at every step (Q . q' = -q'^T K q' <= 0 when Bdot = D q); Bdot is
  // measured over the last step, so near the closest approach, where B along the path turns,
  // a step can give back a little (second order). The ball leaves slower than without the
  // loss by what the loss took.
  auto run = [](double sigma, double* given_back) {
    engine::SceneDesc s = free_space("flyby");
    s.options.eddy_conductivity = sigma;
    s.bodies.push_back(cube_magnet(Vec3::Zero(), Vec3(0, 0, 1.0)));
    BodyDesc ball = iron_ball("ball", Vec3(0.03, -0.06, 0));
    ball.velocity = Vec3(0, 1.0, 0);
    s.bodies.push_back(ball);
    engine::Simulation sim(s);
    *given_back = 0;
    for (int k = 0; k < 120; ++k) {
      sim.step();
      *given_back += std::max(0.0, sim.energy().last.eddy_work);
    }
    return std::make_pair(sim.energy().total.eddy_work, sim.body_velocity(1).norm());
  };
  double back_with = 0, back_without = 0;
  const auto [w_with, v_with] = run(1e7, &back_with);
  const auto [w_without, v_without] = run(0.0, &back_without);
  const double mass = 7870.0 * sphere_volume(kR);
  const double dK = 0.5 * mass * (v_with * v_with - v_without * v_without);
  INFO("eddy work " << w_with << " J, given back " << back_with << " J; speed at 0.12 s " << v_with
                    << " against " << v_without << " m/s, a kinetic energy " << dK << " J apart");
  CHECK(w_with < 0.0);
  CHECK(back_with <= 0.01 * std::abs(w_with));
  CHECK(w_without == 0.0);
  CHECK(dK == Approx(w_with).epsilon(0.1));
}

TEST_CASE("eddy: a run restored mid-way continues as the uninterrupted one", "[eddy][state]") {
  // the loss measures Bdot from the flux density of the last ODE step (engine/eddy.cpp): a
  // saved state must carry it, or the first step after a restore takes no loss and the run
  // leaves the uninterrupted one
  engine::SceneDesc s = free_space("flyby");
  s.options.eddy_conductivity = 1e7;
  s.bodies.push_back(cube_magnet(Vec3::Zero(), Vec3(0, 0, 1.0)));
  BodyDesc ball = iron_ball("ball", Vec3(0.03, -0.06, 0));
  ball.velocity = Vec3(0, 1.0, 0);
  s.bodies.push_back(ball);

  engine::Simulation sim(s);
  sim.run(50);
  const engine::State saved = sim.save_state();
  sim.run(30);
  const std::uint64_t uninterrupted = sim.state_hash();
  REQUIRE(sim.energy().total.eddy_work < 0.0);  // the loss acted over the continuation

  sim.restore_state(saved);  // the same simulation
  sim.run(30);
  CHECK(sim.state_hash() == uninterrupted);

  engine::Simulation other(s);  // a fresh one
  other.restore_state(saved);
  other.run(30);
  CHECK(other.state_hash() == uninterrupted);
}
