// Tests for the bounded pair interaction (FieldOptions::bounded_pairs, field_kernel.hpp):
// exact at and beyond contact, continuous through it, no growth inside an overlap, the
// same in every kernel (direct AVX-512 and portable, Barnes–Hut double and float).
#include "magnetics/curves.hpp"
#include "magnetics/dipole_field.hpp"
#include "magnetics/field_kernel.hpp"
#include "magnetics/fields.hpp"
#include "magnetics/force_laws.hpp"
#include "magnetics/forces.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

#include <random>

using namespace magsim::mag;
using magsim::test::ball_volume;
using magsim::test::kBallRadius;
using magsim::test::kIronMs;

namespace {

// An iron ball (radius a) at p in the field of a 33.5 A·m² magnet (radius R) at the origin,
// the falling_magnet pair; both carry their interaction radii.
MomentSet magnet_and_ball(const Vec3& p, double R = 0.02) {
  MomentSet s;
  s.add_permanent(Vec3::Zero(), 4.0 / 3.0 * kPi * R * R * R, Vec3(0, 0, 33.5), 0);
  s.add_induced(p, ball_volume(), kIronMs, 1);
  s.radius = {R, kBallRadius};
  return s;
}

// Classic force on the ball (eq. 13) with M = f(H) of eq. 10 at its position.
Vec3 ball_force(const Vec3& p, bool bounded) {
  MomentSet s = magnet_and_ball(p);
  FieldOptions o;
  o.solver = FieldSolver::Direct;
  o.bounded_pairs = bounded;
  FieldWorkspace ws;
  std::vector<Vec3> H;
  std::vector<Mat3> J;
  compute_fields(s, o, &H, &J, &ws);
  const Vec3 M = curve_M(Curve::Tanh, H[1], kIronMs);
  return classic_force(s.volume[1] * M, J[1]);
}

}  // namespace

TEST_CASE("bounded pairs: exact at and beyond contact, frozen at contact inside an overlap",
          "[field][bounded]") {
  const double contact = 0.02 + kBallRadius;
  const Vec3 dir = Vec3(0.3, -0.2, 0.9).normalized();
  for (double f : {1.0, 1.01, 1.5, 3.0}) {
    const Vec3 p = f * contact * dir;
    const Vec3 Fb = ball_force(p, true), Fu = ball_force(p, false);
    INFO("separation " << f << " x contact");
    CHECK((Fb - Fu).norm() <= 1e-12 * Fu.norm());
  }
  // inside: the value at contact along the same direction, whatever the overlap
  const Vec3 Fc = ball_force(contact * dir, false);
  for (double f : {0.999, 0.9, 0.8, 0.5}) {
    const Vec3 Fb = ball_force(f * contact * dir, true);
    const Vec3 Fu = ball_force(f * contact * dir, false);
    INFO("overlap: separation " << f << " x contact");
    CHECK((Fb - Fc).norm() <= 1e-9 * Fc.norm());
    CHECK(Fu.norm() > Fc.norm());  // the unbounded pull grows (the feedback this removes)
  }
}

TEST_CASE("bounded pairs: the force is continuous through contact and never grows with "
          "overlap (random directions, 20 % overlap)",
          "[field][bounded]") {
  const double contact = 0.02 + kBallRadius;
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  for (int k = 0; k < 50; ++k) {
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 in = ball_force((1 - 1e-9) * contact * dir, true);
    const Vec3 out = ball_force((1 + 1e-9) * contact * dir, true);
    CHECK((in - out).norm() <= 1e-6 * out.norm());
    const double at = ball_force(contact * dir, true).norm();
    for (double f : {0.95, 0.9, 0.8}) CHECK(ball_force(f * contact * dir, true).norm() <= at * (1 + 1e-12));
  }
}

TEST_CASE("bounded pairs: the Jacobian is the derivative of the field beyond contact (FD)",
          "[field][bounded][fd]") {
  const double contact = 0.02 + kBallRadius;
  const Vec3 p = 1.05 * contact * Vec3(0.2, 0.5, -0.8).normalized();
  FieldOptions o;
  o.solver = FieldSolver::Direct;
  o.bounded_pairs = true;
  auto field = [&](const Vec3& q, Mat3* J) {
    MomentSet s = magnet_and_ball(q);
    FieldWorkspace ws;
    std::vector<Vec3> H;
    std::vector<Mat3> Js;
    compute_fields(s, o, &H, &Js, &ws);
    if (J) *J = Js[1];
    return H[1];
  };
  Mat3 J;
  field(p, &J);
  const double h = 1e-6;
  for (int b = 0; b < 3; ++b) {
    Vec3 d = Vec3::Zero();
    d[b] = h;
    const Vec3 col = (field(p + d, nullptr) - field(p - d, nullptr)) / (2 * h);
    CHECK((col - J.col(b)).norm() <= 1e-6 * J.norm());
  }
}

TEST_CASE("bounded pairs: every kernel agrees on an overlapping pile", "[field][bounded]") {
  MAGSIM_NOTE_IF_NO_SIMD();
  // the dense pile squeezed by 10 %: every neighbour pair overlaps
  MomentSet s = magsim::test::fcc_pile(2500);
  for (Vec3& p : s.position) p *= 0.9;
  s.radius.assign(s.size(), kBallRadius);
  s.radius.back() = 0.01;  // the magnet
  FieldOptions d;
  d.solver = FieldSolver::Direct;
  d.bounded_pairs = true;
  FieldWorkspace ws;
  std::vector<Vec3> Hs, Hp, Hu;
  std::vector<Mat3> Js, Jp, Ju;
  compute_fields(s, d, &Hs, &Js, &ws);
  detail::limit_kernel_path(detail::KernelPath::Generic);  // the slowest path: no FMA unit
  compute_fields(s, d, &Hp, &Jp, &ws);
  detail::limit_kernel_path(detail::KernelPath::Avx512);
  FieldOptions u = d;
  u.bounded_pairs = false;
  compute_fields(s, u, &Hu, &Ju, &ws);
  double dsp = 0, dbu = 0, n = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    dsp = std::max(dsp, (Hs[i] - Hp[i]).norm() / Hs[i].norm());
    dbu = std::max(dbu, (Hs[i] - Hu[i]).norm() / Hs[i].norm());
    n = std::max(n, (Js[i] - Jp[i]).norm() / Js[i].norm());
  }
  INFO("SIMD vs portable: H " << dsp << ", J " << n << "; bounded vs unbounded H " << dbu);
  CHECK(dsp == 0.0);  // the two kernels give the same bits (magnetics/simd.hpp)
  CHECK(n == 0.0);
  CHECK(dbu > 1e-3);  // the bound is active in this pile
  // Barnes–Hut (float and double near field) against the bounded direct sum
  for (bool fl : {true, false}) {
    FieldOptions b = d;
    b.solver = FieldSolver::BarnesHut;
    b.bh_near_float = fl;
    std::vector<Vec3> Hb;
    std::vector<Mat3> Jb;
    FieldWorkspace wb;
    compute_fields(s, b, &Hb, &Jb, &wb);
    double hn = 0, hd = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      hn += (Hb[i] - Hs[i]).squaredNorm();
      hd += Hs[i].squaredNorm();
    }
    INFO("Barnes-Hut (float near field " << fl << ") relative RMS " << std::sqrt(hn / hd));
    CHECK(std::sqrt(hn / hd) <= 1e-3);
  }
}
