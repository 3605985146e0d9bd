// Tests for magnetics/near_field.cpp, the near-field pair model: two iron balls against the
// exact linear two-sphere forces (transverse and axial, weak field) and against the nonlinear
// finite-element table (axial, g = 0.003a–0.3a, H0/Ms = 0.001–3, and chains of 3 and 5); the
// dipole model beyond the cut-off; momentum; its forces are −∇U* (here for pairs and chains
// across the widened gap's range, and in coenergy_test.cpp for random sets).
#include "magnetics/coenergy.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "magnetics/near_field.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <utility>

using namespace magsim::mag;
using magsim::test::ball_volume;
using magsim::test::kBallRadius;
using magsim::test::kIronMs;

namespace {

FieldOptions with_model(NearField m, Curve c = Curve::Tanh) {
  FieldOptions f;
  f.near_field.model = m;
  f.near_field.curve = c;
  return f;
}

// Two iron balls (a = 5 mm), the upper one at +z, gap g radii, in H0; the z force on the
// upper ball at the exact magnetization of curve c, classic force with `model` (N).
double upper_force(double g, const Vec3& H0, NearField model, Curve c = Curve::Tanh) {
  MomentSet s;
  const double a = kBallRadius, d = (2.0 + g) * a;
  s.add_induced(Vec3(0, 0, -0.5 * d), ball_volume(), kIronMs);
  s.add_induced(Vec3(0, 0, 0.5 * d), ball_volume(), kIronMs);
  s.H0 = H0;
  const FieldOptions f = with_model(model, c);
  REQUIRE(solve_exact(&s, c, f, 1e-13, 200).residual < 1e-11);
  MagWorkspace ws;
  std::vector<Vec3> F, tau;
  compute_forces(s, ForceModel::Classic, c, f, &ws, &F, &tau);
  CHECK(std::abs(F[0].z() + F[1].z()) <= 1e-12 * std::abs(F[1].z()));  // action = reaction
  return F[1].z();
}

// A chain of n balls on the z axis at touching gaps (0.003a) in H0 = h Ms along it, on curve c
// with the pair model: (the top ball's z force / F_ref, the chain's moment / m_ref).
std::pair<double, double> chain_ratios(int n, double h, double F_ref, double m_ref, Curve c) {
  const FieldOptions f = with_model(NearField::Pair, c);
  MomentSet s;
  const double d = 2.003 * kBallRadius;
  for (int k = 0; k < n; ++k) s.add_induced(Vec3(0, 0, (k - 0.5 * (n - 1)) * d), ball_volume(), kIronMs);
  s.H0 = Vec3(0, 0, h * kIronMs);
  REQUIRE(solve_exact(&s, c, f, 1e-13, 200).residual < 1e-11);
  MagWorkspace ws;
  std::vector<Vec3> F, tau;
  compute_forces(s, ForceModel::Classic, c, f, &ws, &F, &tau);
  double m = 0;
  for (int k = 0; k < n; ++k) m += s.moment(k).z();
  return {F[n - 1].z() / F_ref, m / m_ref};
}

// U* at the exact magnetization of s on the curve of f (J)
double coenergy_at(MomentSet s, const FieldOptions& f) {
  const Curve c = f.near_field.curve;
  REQUIRE(solve_exact(&s, c, f, 1e-14, 100).residual < 1e-11);
  FieldWorkspace ws;
  std::vector<Vec3> H;
  compute_fields(s, f, &H, nullptr, &ws);
  return magnetic_coenergy(s, s, c, H, f.near_field, &ws.near);
}

// −dU*/dt by central differences of step d, Richardson-extrapolated from d and d/2
// (error O(d⁴)), where move(s, t) displaces one coordinate by t
double minus_dU(const MomentSet& s, const FieldOptions& f, double d,
                const std::function<void(MomentSet*, double)>& move) {
  auto central = [&](double e) {
    MomentSet p = s, m = s;
    move(&p, e);
    move(&m, -e);
    return -(coenergy_at(p, f) - coenergy_at(m, f)) / (2 * e);
  };
  return (4 * central(0.5 * d) - central(d)) / 3;
}

// A tilted pair at gap g (radii) and a bent chain of four with gaps g, 1.5g, 0.7 (the last in
// the contact count's step; the first two balls' second neighbour in the cut-off step), a
// magnet below them and H0 of h Ms. The magnet adds a fifth of h Ms at 25 mm, so the balls'
// magnetizations, which set each contact's widened gap, differ from ball to ball.
MomentSet pair_and_chain(double g, double h) {
  MomentSet s;
  const double a = kBallRadius;
  const Vec3 pc(-0.025, 0.002, 0.004), axis = Vec3(0.6, -0.48, 0.64);
  s.add_induced(pc - 0.5 * (2 + g) * a * axis, ball_volume(), kIronMs);
  s.add_induced(pc + 0.5 * (2 + g) * a * axis, ball_volume(), kIronMs);
  const Vec3 dirs[3] = {Vec3(1, 0, 0), Vec3(0.5, 0, 0.866025403784), Vec3(1, 0, 0.05).normalized()};
  const double gaps[3] = {g, 1.5 * g, 0.7};
  Vec3 p(0.006, -0.001, 0.002);
  s.add_induced(p, ball_volume(), kIronMs);
  for (int k = 0; k < 3; ++k) {
    p += (2 + gaps[k]) * a * dirs[k];
    s.add_induced(p, ball_volume(), kIronMs);
  }
  const double r = 0.025, Hm = 0.2 * h * kIronMs;  // on-axis dipole field 2m/(4π r³) = Hm
  s.add_permanent(Vec3(0, 0, -r), 1e-6, Vec3(0.2, -0.1, 1.0).normalized() * (2 * kPi * r * r * r * Hm));
  s.H0 = Vec3(0.3, -0.2, 1.0).normalized() * (h * kIronMs);
  return s;
}

}  // namespace

TEST_CASE("pair model: axial pairs against the nonlinear finite-element table", "[near_field]") {
  // Fz_N of the upper ball, tools/reference/data/near_field_fem.csv (axisym_fem.py: bulk law
  // M = Ms tanh(999 |H|/Ms), a = 5 mm, Ms = 1.6e6 A/m, H0 along the line of centres; level 4).
  // The mark 0.85–1.15 is asserted where the model meets it; the cells it misses are below,
  // each held to its present ratio ± 0.03 so that a change in either direction shows.
  struct Cell {
    double g, h, fem;
  };
  const Cell in_band[] = {
      {0.3, 0.001, -0.00046646801}, {0.3, 0.03, -0.4198016},   {0.3, 1.0, -24.829131},
      {0.1, 0.003, -0.012581621},   {0.1, 0.3, -38.191949},    {0.1, 3.0, -35.472448},
      {0.03, 0.01, -0.39100519},    {0.03, 0.1, -20.296721},   {0.03, 0.3, -44.810873},
      {0.01, 0.001, -0.009348042},  {0.01, 0.03, -5.6663327},  {0.01, 0.1, -22.768453},
      {0.003, 0.003, -0.21234652},  {0.003, 0.01, -1.6608051}, {0.003, 0.03, -6.5472841},
      {0.003, 0.3, -47.806369},     {0.003, 1.0, -45.163359}};
  for (const Cell& c : in_band) {
    const double pair = upper_force(c.g, Vec3(0, 0, c.h * kIronMs), NearField::Pair);
    INFO("g/a " << c.g << ", H0/Ms " << c.h << ": pair " << pair << " N, FEM " << c.fem << " N");
    CHECK(pair / c.fem > 0.85);
    CHECK(pair / c.fem < 1.15);
  }
  // outside the mark (tools/findings/near_field_reference.md): the engine's sphere curve
  // tanh(3H/Ms) against a bulk-iron sphere at 0.3 Ms, g ≥ 0.3a (0.71); the knee at
  // 0.1 Ms, g = 0.1a (0.77) and 0.03 Ms, g = 0.03a (0.84); an overshoot at g = 0.003a, 0.1 Ms (1.19)
  struct Missed {
    double g, h, fem, ratio;
  };
  const Missed missed[] = {{0.3, 0.3, -25.354207, 0.71},
                           {0.1, 0.1, -13.203432, 0.77},
                           {0.03, 0.03, -3.508341, 0.84},
                           {0.003, 0.1, -23.686265, 1.19}};
  for (const Missed& c : missed) {
    const double pair = upper_force(c.g, Vec3(0, 0, c.h * kIronMs), NearField::Pair);
    INFO("g/a " << c.g << ", H0/Ms " << c.h << ": pair / FEM " << pair / c.fem << ", recorded " << c.ratio);
    CHECK(std::abs(pair / c.fem - c.ratio) < 0.03);
  }
  // the dipole model, where the pair model matters: 0.03 × at g = 0.003a, 0.003 Ms
  const double dip = upper_force(0.003, Vec3(0, 0, 0.003 * kIronMs), NearField::Dipole);
  CHECK(dip / -0.21234652 < 0.05);
}

TEST_CASE("pair model: chains of 3 and 5 on the axis against the finite-element table", "[near_field]") {
  // The top ball's z force (N) and the chain's moment (A·m²), tools/reference/data/
  // near_field_fem.csv (touching gaps g = 0.003a, H0 along the chain). Mark: 25 % for both.
  // The pairwise sum over-counts a chain's contacts; the coupling ν^−β and the saturation
  // read from the balls' own flux are what bring it in (the 5-chain's end ball was 1.33 × at
  // 0.03 Ms with the saturation read from H0).
  struct Cell {
    int n;
    double h, F, m;
  };
  const Cell cells[] = {{3, 0.001, -0.037972087, 0.017582198}, {3, 0.003, -0.34089319, 0.052738455},
                        {3, 0.01, -2.2653532, 0.17032794},     {3, 0.03, -8.4030321, 0.4697306},
                        {3, 0.1, -28.460259, 1.3184377},       {3, 0.3, -50.000593, 2.5014281},
                        {3, 1.0, -47.517581, 2.5109874},       {3, 3.0, -45.764226, 2.5127141},
                        {5, 0.001, -0.052607481, 0.039591817}, {5, 0.003, -0.46856004, 0.11855924},
                        {5, 0.01, -2.7369874, 0.37060827},     {5, 0.03, -9.6550859, 0.97596118},
                        {5, 0.1, -30.884655, 2.5399135},       {5, 0.3, -50.603349, 4.1724699},
                        {5, 1.0, -48.156452, 4.1846039},       {5, 3.0, -46.429134, 4.1877944}};
  for (const Cell& c : cells) {
    const auto [rF, rm] = chain_ratios(c.n, c.h, c.F, c.m, Curve::Tanh);
    INFO("N " << c.n << ", H0/Ms " << c.h << ": end ball " << rF << ", moment " << rm);
    CHECK(std::abs(rF - 1) < 0.25);
    CHECK(std::abs(rm - 1) < 0.25);
  }
}

TEST_CASE("pair model, iron curve: axial pairs against the finite-element table", "[near_field]") {
  // The same table with the balls on the reference's own law (Curve::Iron: a sphere of bulk
  // iron, μr,i 1000) and the widening fitted for it: the 0.3 Ms column, which eq. 10's lone
  // sphere under-magnetizes (moment 0.80×), comes into the mark, and the blended widening
  // (PairWidening) brings in the knee, g = 0.03a–0.1a at 0.03–0.1 Ms, which the sum
  // g_e + κ h^q left at 0.81 and 0.84. Every cell g = 0.003a–0.3a, H0/Ms = 0.001–3 is in
  // 0.85–1.15.
  struct Cell {
    double g, h, fem;
  };
  const Cell cells[] = {
      {0.3, 0.001, -0.000466468}, {0.3, 0.003, -0.00419821}, {0.3, 0.01, -0.0466466},
      {0.3, 0.03, -0.419802},     {0.3, 0.1, -4.66193},      {0.3, 0.3, -25.3542},
      {0.3, 1, -24.8291},         {0.3, 3, -24.3874},        {0.1, 0.001, -0.00139796},
      {0.1, 0.003, -0.0125816},   {0.1, 0.01, -0.139793},    {0.1, 0.03, -1.25795},
      {0.1, 0.1, -13.2034},       {0.1, 0.3, -38.1919},      {0.1, 1, -36.6131},
      {0.1, 3, -35.4724},         {0.03, 0.001, -0.00391056}, {0.03, 0.003, -0.0351947},
      {0.03, 0.01, -0.391005},    {0.03, 0.03, -3.50834},    {0.03, 0.1, -20.2967},
      {0.03, 0.3, -44.8109},      {0.03, 1, -42.525},        {0.03, 3, -40.8809},
      {0.01, 0.001, -0.00934804}, {0.01, 0.003, -0.0841248}, {0.01, 0.01, -0.933508},
      {0.01, 0.03, -5.66633},     {0.01, 0.1, -22.7685},     {0.01, 0.3, -47.0024},
      {0.01, 1, -44.4575},        {0.01, 3, -42.6248},       {0.003, 0.001, -0.0236251},
      {0.003, 0.003, -0.212347},  {0.003, 0.01, -1.66081},   {0.003, 0.03, -6.54728},
      {0.003, 0.1, -23.6863},     {0.003, 0.3, -47.8064},    {0.003, 1, -45.1634},
      {0.003, 3, -43.2587}};
  for (const Cell& c : cells) {
    const double r = upper_force(c.g, Vec3(0, 0, c.h * kIronMs), NearField::Pair, Curve::Iron) / c.fem;
    INFO("g/a " << c.g << ", H0/Ms " << c.h << ": pair / FEM " << r);
    CHECK(r > 0.85);
    CHECK(r < 1.15);
  }
  // the lone sphere: eq. 10's moment is 0.80× the iron's at 0.3 Ms, the reason for the curve
  const Vec3 H(0, 0, 0.3 * kIronMs);
  CHECK(curve_M(Curve::Tanh, H, kIronMs).z() / curve_M(Curve::Iron, H, kIronMs).z() ==
        Approx(std::tanh(0.9) / 0.8956).epsilon(2e-3));
}

TEST_CASE("pair model, iron curve: chains of 3 and 5 on the axis", "[near_field]") {
  // End ball's force and the chain's moment within 25 % of the FEM (the cells of the tanh test
  // above); with the iron curve the ball next to the 5-chain's end is within 0.77–1.20 ×.
  struct Cell {
    int n;
    double h, F, m;
  };
  const Cell cells[] = {{3, 0.001, -0.037972087, 0.017582198}, {3, 0.01, -2.2653532, 0.17032794},
                        {3, 0.1, -28.460259, 1.3184377},       {3, 0.3, -50.000593, 2.5014281},
                        {5, 0.001, -0.052607481, 0.039591817}, {5, 0.03, -9.6550859, 0.97596118},
                        {5, 0.1, -30.884655, 2.5399135},       {5, 0.3, -50.603349, 4.1724699}};
  for (const Cell& c : cells) {
    const auto [rF, rm] = chain_ratios(c.n, c.h, c.F, c.m, Curve::Iron);
    INFO("N " << c.n << ", H0/Ms " << c.h << ": end ball " << rF << ", moment " << rm);
    CHECK(std::abs(rF - 1) < 0.25);
    CHECK(std::abs(rm - 1) < 0.25);
  }
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
  // transverse at 0.03 Ms: the linear solution still holds there (its largest interior field
  // keeps the bulk law within 1 % of linear up to 0.06 Ms, tools/reference/
  // near_field_transverse.py), and the widened gap must not pull the force off it
  const double Hs = 0.03 * kIronMs;
  for (const Case& c : cases) {
    if (c.axial) continue;
    const double pair = upper_force(c.g, Vec3(Hs, 0, 0), NearField::Pair) /
                        (kMu0 * Hs * Hs * kBallRadius * kBallRadius);
    INFO("transverse g/a " << c.g << " at 0.03 Ms: pair " << pair << ", exact " << c.exact);
    CHECK(std::abs(pair / c.exact - 1) < 0.03);
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

TEST_CASE("pair model: the coupling, switch and widened gap are smooth and as documented", "[near_field]") {
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
  // the widened gap: its h-derivatives, beyond the table's last node (G > 2.2) too
  for (double g : {3e-3, 0.05, 1.3}) {
    for (double h : {1e-3, 0.02, 0.5, 3.0}) {
      const double e = 1e-4 * h;  // Δt moves by ~1e-13 of itself per 1e-7 h at h = 0.001
      const PairCoupling c = tab.at(g, h), cp = tab.at(g, h + e), cm = tab.at(g, h - e);
      INFO("g " << g << " h " << h);
      CHECK(c.dpar_dh == Approx((cp.par - cm.par) / (2 * e)).epsilon(1e-5).margin(1e-12));
      CHECK(c.dperp_dh == Approx((cp.perp - cm.perp) / (2 * e)).epsilon(1e-5).margin(1e-12));
      CHECK(c.dpar_dh < 0);  // the correction weakens as the contact saturates
      const PairCoupling gp = tab.at(g + 1e-7, h), gm = tab.at(g - 1e-7, h);
      CHECK(c.dpar == Approx((gp.par - gm.par) / 2e-7).epsilon(1e-5).margin(1e-12));
    }
  }
  // the tail beyond the last node continues the spline: value and slope at G = 2.2
  {
    const double h = std::pow((2.2 - pair_effective_gap(0.5)) / kPairWidenScale, 1.0 / kPairWidenPower);
    const PairCoupling lo = tab.at(0.5, h * (1 - 1e-9)), hi = tab.at(0.5, h * (1 + 1e-9));
    CHECK(lo.par == Approx(hi.par).epsilon(1e-7));
    CHECK(lo.dpar_dh == Approx(hi.dpar_dh).epsilon(1e-6));
  }
  // the saturation field of the balls' magnetization: ζ/3 to first order (a lone ball's
  // linear law ζ = 3h), its derivative, unbounded towards saturation, held past ζ ≈ 1
  CHECK(pair_flux_field(0.0) == 0.0);
  CHECK(pair_flux_field(1e-4) == Approx(1e-4 / 3).epsilon(1e-8));
  for (double z : {0.01, 0.3, 0.7, 0.95, 0.999}) {
    double d = 0;
    pair_flux_field(z, &d);
    const double e = 1e-6 * (1 - z);
    CHECK(d == Approx((pair_flux_field(z + e) - pair_flux_field(z - e)) / (2 * e)).epsilon(1e-6));
  }
  CHECK(pair_flux_field(0.999) > 7.0);
  double dsat = 1;
  CHECK(pair_flux_field(1.0, &dsat) == pair_flux_field(1.5));
  CHECK(dsat == 0.0);
  CHECK(std::isfinite(pair_flux_field(1.0)));
  // the contact count: 1 to g = 0.5, 0 from g = 1; a straight 3-chain counts 1, 2, 1
  CHECK(pair_count_switch(0.5) == 1.0);
  CHECK(pair_count_switch(1.0) == 0.0);
  CHECK(pair_count_switch(0.75) == Approx(0.5));
  {
    MomentSet chain;
    for (int k = 0; k < 3; ++k) chain.add_induced(Vec3(0, 0, k * 2.003 * kBallRadius), ball_volume(), kIronMs);
    NearFieldWorkspace nws;
    find_near_pairs(chain, &nws);
    REQUIRE(nws.count.size() == 3);
    CHECK(nws.count[0] == 1.0);
    CHECK(nws.count[1] == 2.0);
    CHECK(nws.count[2] == 1.0);
  }
  // the axial coupling strengthens towards contact; an overlap reads as contact, g_m
  CHECK(tab.at(0.0).par > tab.at(0.1).par);
  CHECK(tab.at(-0.02).par > tab.at(0.0).par);
  CHECK(pair_effective_gap(-0.05) == Approx(kPairContactGap));
  CHECK(pair_effective_gap(0.01) == Approx(0.01).epsilon(1e-6));
  CHECK(pair_widened_gap(0.01, 0.0) == pair_effective_gap(0.01));
  CHECK(pair_widened_gap(0.01, 1.0) == Approx(pair_effective_gap(0.01) + kPairWidenScale));
  // the iron's blend: G = g_e at h = 0; a thin layer widens little, a thick one adds to
  // (1 − λ) g_e; dG/dg_e ≥ 1 − λ (the correction attracts); both derivatives by central
  // differences over gaps 1e-3–2 and h from 1e-4 to the clamp's 7e3
  const PairWidening iron = pair_widening(Curve::Iron);
  double dge = 0, dh = 0;
  CHECK(pair_blended_gap(iron, 0.05, 0.0, &dge, &dh) == Approx(0.05).epsilon(1e-15));
  CHECK(dh == 0.0);
  CHECK(pair_blended_gap(iron, 0.05, 1e-3, &dge, &dh) - 0.05 < 1e-9);
  CHECK(pair_blended_gap(iron, 0.001, 1.0, &dge, &dh) ==
        Approx((1 - kPairWidenShareIron) * 0.001 + kPairWidenScaleIron).epsilon(1e-6));
  double worst_ge = 0, worst_h = 0, least_slope = 1;
  for (double ge : {1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 1.0, 2.0})
    for (double h : {1e-4, 1e-3, 0.01, 0.03, 0.1, 0.3, 1.0, 10.0, 7e3}) {
      const double G = pair_blended_gap(iron, ge, h, &dge, &dh);
      least_slope = std::min(least_slope, dge);
      double u = 0, v = 0;
      const double eg = 1e-6 * ge, eh = 1e-6 * h;
      const double fd_ge = (pair_blended_gap(iron, ge + eg, h, &u, &v) - pair_blended_gap(iron, ge - eg, h, &u, &v)) / (2 * eg);
      const double fd_h = (pair_blended_gap(iron, ge, h + eh, &u, &v) - pair_blended_gap(iron, ge, h - eh, &u, &v)) / (2 * eh);
      if (G < 10) worst_ge = std::max(worst_ge, std::abs(fd_ge - dge));  // else G's rounding over 2 eg swamps it
      worst_h = std::max(worst_h, std::abs(fd_h - dh) / std::max(1.0, std::abs(dh)));
    }
  CHECK(worst_ge < 1e-6);
  CHECK(worst_h < 1e-6);
  CHECK(least_slope >= 1 - kPairWidenShareIron - 1e-12);
  CHECK(least_slope < 1 - kPairWidenShareIron + 0.01);  // reached where the layer dominates
  // μr: the table's span only
  NearFieldOptions o;
  o.mu_r = 5.0;
  CHECK_FALSE(validate(o).empty());
  o.mu_r = 1000.0;
  CHECK(validate(o).empty());
}

TEST_CASE("pair model: the cached geometry follows the description", "[near_field]") {
  // one workspace through descriptions and magnetizations: each gives the field and energy a
  // fresh workspace gives
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
  MomentSet moved = s, turned = s, stronger = s;
  moved.position[1].z() += 0.1 * a;
  turned.m_perm[3] = Vec3(0, 1.5, 1.0);
  stronger.set_magnetization(1, Vec3(1e5, 4e5, 6e5));
  for (const MomentSet* t : {&s, &moved, &s, &turned, &stronger}) {
    NearFieldWorkspace fresh;
    const auto Hr = field(*t, &reused), Hf = field(*t, &fresh);
    for (std::size_t j = 0; j < t->size(); ++j) CHECK(Hr[j] == Hf[j]);
    CHECK(near_field_energy(*t, *t, o, &reused) == near_field_energy(*t, *t, o, &fresh));
  }
  CHECK(field(s, &reused)[0] != field(moved, &reused)[0]);
  // the saturation reads the balls' own magnetization, not the magnet's field
  CHECK(field(s, &reused)[0] == field(turned, &reused)[0]);
  CHECK(field(s, &reused)[0] != field(stronger, &reused)[0]);
}

TEST_CASE("pair model: forces and the magnet's torque are -grad U* across the widened gap",
          "[near_field]") {
  // central differences of U* (every magnetization re-solved), against the classic forces on
  // every ball and the magnet and the magnet's torque; gaps 0.003a–0.3a, H0 from the linear
  // range through the knee to saturation (G = g_e + κ h(ζ̄)^q from g_e to past the table's
  // end; ζ̄ moves with every re-solved magnetization, so this holds the saturation term too);
  // on eq. 10's curve and on the iron sphere's, each with its own widening
  double worst_F = 0, worst_T = 0;
  for (const Curve curve : {Curve::Tanh, Curve::Iron}) {
    for (double g : {0.003, 0.03, 0.3}) {
      const FieldOptions f = with_model(NearField::Pair, curve);
      for (double h : {0.001, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0}) {
        INFO("curve " << static_cast<int>(curve) << ", g/a " << g << ", H0/Ms " << h);
        MomentSet s = pair_and_chain(g, h);
        NearFieldWorkspace nws;
        find_near_pairs(s, &nws);
        // the pair, three contacts, and (below g = 0.3a) a second neighbour
        REQUIRE(nws.pairs.size() == (g < 0.3 ? 5u : 4u));
        MomentSet solved = s;
        REQUIRE(solve_exact(&solved, curve, f, 1e-14, 100).residual < 1e-11);
        MagWorkspace mws;
        std::vector<Vec3> F, tau;
        compute_forces(solved, ForceModel::Classic, curve, f, &mws, &F, &tau);
        double Fmax = 0;
        for (const Vec3& x : F) Fmax = std::max(Fmax, x.norm());
        double eF = 0, eT = 0;
        const int magnet = static_cast<int>(s.size()) - 1;
        for (int j = 0; j <= magnet; ++j)
          for (int c = 0; c < 3; ++c) {
            const double Ffd = minus_dU(s, f, 1e-8, [&](MomentSet* t, double d) { t->position[j][c] += d; });
            eF = std::max(eF, std::abs(Ffd - F[j][c]) / Fmax);
          }
        for (int c = 0; c < 3; ++c) {  // the magnet turned about its centre
          const double Tfd = minus_dU(s, f, 1e-6, [&](MomentSet* t, double d) {
            t->m_perm[magnet] = Eigen::AngleAxisd(d, Vec3::Unit(c)).toRotationMatrix() * t->m_perm[magnet];
            t->M[magnet] = t->m_perm[magnet] / t->volume[magnet];
          });
          eT = std::max(eT, std::abs(Tfd - tau[magnet][c]) / tau[magnet].norm());
        }
        INFO(kCurveNames.name(curve) << ", g/a " << g << ", H0/Ms " << h << ": force error " << eF << ", torque error " << eT
                    << " (|F|max " << Fmax << " N)");
        CHECK(eF < 1e-6);
        CHECK(eT < 1e-6);
        worst_F = std::max(worst_F, eF);
        worst_T = std::max(worst_T, eT);
      }
    }
  }
  WARN("worst relative error: force " << worst_F << ", magnet torque " << worst_T);
}
