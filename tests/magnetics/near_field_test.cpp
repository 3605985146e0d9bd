// Tests for magnetics/near_field.cpp, the near-field pair model: two iron balls against the
// exact linear two-sphere forces (transverse and axial, weak field) and against the nonlinear
// finite-element forces at g = 0.003a (axial, H0/Ms = 1e-4…10); the dipole model beyond the
// cut-off; momentum. That its forces are −∇U* is in coenergy_test.cpp.
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "magnetics/near_field.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace magsim::mag;
using magsim::test::ball_volume;
using magsim::test::kBallRadius;
using magsim::test::kIronMs;

namespace {

FieldOptions with_model(NearField m) {
  FieldOptions f;
  f.near_field.model = m;
  return f;
}

// Two iron balls (a = 5 mm), the upper one at +z, gap g radii, in H0; the z force on the
// upper ball at the exact magnetization, classic force with `model` (N).
double upper_force(double g, const Vec3& H0, NearField model) {
  MomentSet s;
  const double a = kBallRadius, d = (2.0 + g) * a;
  s.add_induced(Vec3(0, 0, -0.5 * d), ball_volume(), kIronMs);
  s.add_induced(Vec3(0, 0, 0.5 * d), ball_volume(), kIronMs);
  s.H0 = H0;
  const FieldOptions f = with_model(model);
  REQUIRE(solve_exact(&s, Curve::Tanh, f, 1e-13, 200).residual < 1e-11);
  MagWorkspace ws;
  std::vector<Vec3> F, tau;
  compute_forces(s, ForceModel::Classic, Curve::Tanh, f, &ws, &F, &tau);
  CHECK(std::abs(F[0].z() + F[1].z()) <= 1e-12 * std::abs(F[1].z()));  // action = reaction
  return F[1].z();
}

}  // namespace

TEST_CASE("pair model: axial, g = 0.003a, within 15 % of the finite-element force", "[near_field]") {
  // nonlinear axisymmetric FEM, initial μr = 1000, tanh curve; μ0 Ms² a² units
  const double h[] = {1e-4, 1e-3, 0.01, 0.03, 0.1, 0.2, 1.0 / 3.0, 0.5, 1, 3, 10};
  const double fem[] = {-2.936e-6, -2.818e-4, -0.01306, -0.05479, -0.2057, -0.3647,
                        -0.4797,   -0.5387,   -0.5595,  -0.5380,  -0.5262};
  const double unit = kMu0 * kIronMs * kIronMs * kBallRadius * kBallRadius;
  double worst = 0, worst_dipole = 0;
  for (int k = 0; k < 11; ++k) {
    const Vec3 H0(0, 0, h[k] * kIronMs);
    const double pair = upper_force(0.003, H0, NearField::Pair) / unit;
    const double dip = upper_force(0.003, H0, NearField::Dipole) / unit;
    INFO("H0/Ms " << h[k] << ": pair " << pair << ", dipole " << dip << ", FEM " << fem[k]);
    CHECK(std::abs(pair / fem[k] - 1) < 0.15);
    worst = std::max(worst, std::abs(pair / fem[k] - 1));
    worst_dipole = std::max(worst_dipole, std::abs(dip / fem[k] - 1));
  }
  WARN("pair model: worst relative error " << worst << "; dipole model: " << worst_dipole);
  CHECK(worst_dipole > 0.9);  // the dipole model is ×35 too weak at low fields
}

TEST_CASE("pair model: weak field, within 5 % of the exact linear force", "[near_field]") {
  // tools/reference/two_spheres.py force --mu 1000 --gap G --field F (μ0 H0² a², upper ball)
  struct Case {
    double g;
    bool axial;
    double exact;
  };
  const Case cases[] = {{0.3, false, 0.954468}, {0.1, false, 1.18236}, {0.01, false, 1.2909},
                        {0.3, true, -5.79781},  {0.1, true, -17.3815}, {0.03, true, -48.6153}};
  const double H = 1e-3 * kIronMs;
  const double unit = kMu0 * H * H * kBallRadius * kBallRadius;
  for (const Case& c : cases) {
    const Vec3 H0 = c.axial ? Vec3(0, 0, H) : Vec3(H, 0, 0);
    const double pair = upper_force(c.g, H0, NearField::Pair) / unit;
    const double dip = upper_force(c.g, H0, NearField::Dipole) / unit;
    INFO((c.axial ? "axial" : "transverse") << " g/a " << c.g << ": pair " << pair << ", dipole "
                                            << dip << ", exact " << c.exact);
    CHECK(std::abs(pair / c.exact - 1) < 0.05);
    CHECK(std::abs(dip / c.exact - 1) > 0.1);  // where the model matters
  }
}

TEST_CASE("pair model: beyond the cut-off the forces are the dipole model's", "[near_field]") {
  // balls on a lattice of pitch 4.05 radii (gaps 2.05a) around a magnet, and one pair at
  // 2.05 radii: the lattice is untouched, the close pair is not
  MomentSet s;
  const double a = kBallRadius, pitch = 4.05 * a;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.add_induced(Vec3(i * pitch, j * pitch, 0.01), ball_volume(), kIronMs);
  s.add_permanent(Vec3(pitch, pitch, -0.01), 1e-6, Vec3(0.1, 0.2, 3.0));
  s.H0 = Vec3(1e3, 0, 2e3);
  auto forces = [&](const MomentSet& in, NearField m) {
    MomentSet t = in;
    const FieldOptions f = with_model(m);
    REQUIRE(solve_exact(&t, Curve::Tanh, f, 1e-13, 200).residual < 1e-11);
    MagWorkspace ws;
    std::vector<Vec3> F, tau;
    compute_forces(t, ForceModel::Classic, Curve::Tanh, f, &ws, &F, &tau);
    return std::make_pair(F, tau);
  };
  const auto [Fp, tp] = forces(s, NearField::Pair);
  const auto [Fd, td] = forces(s, NearField::Dipole);
  double Fmax = 0;
  for (const Vec3& f : Fd) Fmax = std::max(Fmax, f.norm());
  for (std::size_t j = 0; j < s.size(); ++j) {
    CHECK((Fp[j] - Fd[j]).norm() <= 1e-6 * Fmax);
    CHECK((tp[j] - td[j]).norm() <= 1e-6 * Fmax * a);
  }
  MomentSet close = s;
  close.position[1] = close.position[0] + Vec3(0, 2.05 * a, 0);
  const auto [Fp2, tp2] = forces(close, NearField::Pair);
  const auto [Fd2, td2] = forces(close, NearField::Dipole);
  CHECK((Fp2[1] - Fd2[1]).norm() > 1e-3 * Fd2[1].norm());
  // momentum: the model's forces, the magnet's included, sum to zero
  Vec3 sum = Vec3::Zero(), sumd = Vec3::Zero();
  for (std::size_t j = 0; j < s.size(); ++j) {
    sum += Fp2[j];
    sumd += Fd2[j];
  }
  CHECK((sum - sumd).norm() <= 1e-9 * Fmax);
}

TEST_CASE("pair model: the coupling, switch and fade are smooth and as documented", "[near_field]") {
  const PairCouplingTable tab(1000.0);
  // the switch: 1 to g = 1, 0 from g = 2, C¹ in between
  CHECK(pair_switch(0.5) == 1.0);
  CHECK(pair_switch(2.0) == 0.0);
  CHECK(pair_switch(1.5) == Approx(0.5));
  for (double g : {0.0, 1e-4, 3e-3, 0.05, 0.7, 1.3, 1.9}) {
    const double e = 1e-7;
    const PairCoupling c = tab.at(g), cp = tab.at(g + e), cm = tab.at(g - e);
    CHECK(c.dpar == Approx((cp.par - cm.par) / (2 * e)).epsilon(1e-5));
    CHECK(c.dperp == Approx((cp.perp - cm.perp) / (2 * e)).epsilon(1e-5).margin(1e-9));
  }
  for (double h : {1e-3, 0.02, 0.5}) {
    const PairFade f = pair_fade(h);
    CHECK(f.dphi_dh == Approx((pair_fade(h + 1e-8).phi - pair_fade(h - 1e-8).phi) / 2e-8).epsilon(1e-5));
  }
  // the axial coupling strengthens towards contact; an overlap reads as contact, g_m
  CHECK(tab.at(0.0).par > tab.at(0.1).par);
  CHECK(tab.at(-0.02).par > tab.at(0.0).par);
  CHECK(pair_effective_gap(-0.05) == Approx(kPairContactGap));
  CHECK(pair_effective_gap(0.01) == Approx(0.01).epsilon(1e-6));
  CHECK(pair_fade(0.0).phi == 1.0);
  CHECK(pair_fade(kPairFadeField).phi == Approx(0.5));
  // μr: the table's span only
  NearFieldOptions o;
  o.mu_r = 5.0;
  CHECK_FALSE(validate(o).empty());
  o.mu_r = 1000.0;
  CHECK(validate(o).empty());
}

TEST_CASE("pair model: the cached couplings follow the description", "[near_field]") {
  // one workspace through three descriptions: each gives the field a fresh workspace gives
  MomentSet s;
  const double a = kBallRadius;
  s.add_induced(Vec3(0, 0, 0), ball_volume(), kIronMs);
  s.add_induced(Vec3(0, 0, 2.01 * a), ball_volume(), kIronMs);
  s.add_induced(Vec3(2.3 * a, 0, 0), ball_volume(), kIronMs);
  s.add_permanent(Vec3(0, 0, 0.03), 1e-6, Vec3(0, 0, 2.0));
  for (std::size_t j = 0; j < 3; ++j) s.set_magnetization(j, Vec3(1e4, 2e4 * j, 3e4));
  NearFieldOptions o;
  o.model = NearField::Pair;
  NearFieldWorkspace reused;
  auto field = [&](const MomentSet& t, NearFieldWorkspace* ws) {
    std::vector<Vec3> H(t.size(), Vec3::Zero());
    add_near_field(t, t, o, ws, &H);
    return H;
  };
  MomentSet moved = s, turned = s;
  moved.position[1].z() += 0.1 * a;
  turned.m_perm[3] = Vec3(0, 1.5, 1.0);
  for (const MomentSet* t : {&s, &moved, &s, &turned}) {
    NearFieldWorkspace fresh;
    const auto Hr = field(*t, &reused), Hf = field(*t, &fresh);
    for (std::size_t j = 0; j < t->size(); ++j) CHECK(Hr[j] == Hf[j]);
    CHECK(near_field_energy(*t, *t, o, &reused) == near_field_energy(*t, *t, o, &fresh));
  }
  CHECK(field(s, &reused)[0] != field(moved, &reused)[0]);
  CHECK(field(s, &reused)[0] != field(turned, &reused)[0]);
}
