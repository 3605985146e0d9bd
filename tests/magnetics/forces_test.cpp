// Tests for magnetics/forces.cpp: the Zeeman force of eq. 4 against −∇E by finite
// differences, the classic force (eqs. 13–14) against its closed form, Newton's third law.
#include "magnetics/forces.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/dipole_field.hpp"
#include "magnetics/force_laws.hpp"
#include "magnetics/ground_truth.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

using namespace magsim::mag;

namespace {
// −∂E_j/∂p_j by central differences, sources fixed, M_j = f(H_j(p_j))
Vec3 fd_zeeman(const MomentSet& s, std::size_t j, Curve c, double h) {
  Vec3 F;
  for (int b = 0; b < 3; ++b) {
    Vec3 d = Vec3::Zero();
    d[b] = h;
    const Vec3 Hp = field_at(s, s.position[j] + d, 0.0, static_cast<int>(j));
    const Vec3 Hm = field_at(s, s.position[j] - d, 0.0, static_cast<int>(j));
    F[b] = -(zeeman_energy(c, s.volume[j], s.Ms[j], Hp) -
             zeeman_energy(c, s.volume[j], s.Ms[j], Hm)) / (2 * h);
  }
  return F;
}

struct FdResult {
  double worst_ours = 0;   // J A (2M + H) + J M
  double worst_paper = 0;  // A J (2M + H) + J M, the printed order
};

FdResult zeeman_fd(double magnet_strength) {
  MomentSet s = magsim::test::random_cloud(24, 11, magnet_strength);
  REQUIRE(solve_exact(&s, Curve::Tanh, FieldOptions{}).converged);
  FieldWorkspace ws;
  std::vector<Vec3> H;
  std::vector<Mat3> J;
  compute_fields(s, FieldOptions{}, &H, &J, &ws);
  FdResult r;
  for (std::size_t j = 0; j < s.size(); ++j) {
    if (s.kind[j] != MomentKind::Induced) continue;
    const Vec3 M = curve_M(Curve::Tanh, H[j], s.Ms[j]);
    const Vec3 F = zeeman_force(Curve::Tanh, s.volume[j], s.Ms[j], M, H[j], J[j]);
    const Vec3 Ffd = fd_zeeman(s, j, Curve::Tanh, 1e-7);
    const Mat3 A = curve_dMdH(Curve::Tanh, H[j], s.Ms[j]);
    const Vec3 Fp = kMu0 * s.volume[j] * (A * J[j] * (2 * M + H[j]) + J[j] * M);
    r.worst_ours = std::max(r.worst_ours, (F - Ffd).norm() / Ffd.norm());
    r.worst_paper = std::max(r.worst_paper, (Fp - Ffd).norm() / Ffd.norm());
  }
  return r;
}
}  // namespace

TEST_CASE("Zeeman force (eq. 4) equals −∇E by finite differences on 24 moments",
          "[forces][fd]") {
  // moderate magnets: linear to mid-curve; strong magnets: several moments near saturation
  for (double strength : {3.0, 300.0}) {
    const FdResult r = zeeman_fd(strength);
    INFO("magnet " << strength << " A·m²: worst FD error " << r.worst_ours
                   << ", printed order " << r.worst_paper);
    CHECK(r.worst_ours <= 1e-6);
    if (strength > 100) CHECK(r.worst_paper > 1e-3);  // the printed product order is wrong
  }
}

TEST_CASE("Zeeman force is 8× the classic force in the linear regime", "[forces]") {
  MomentSet s;
  s.add_permanent(Vec3(0, 0, 0), 1e-6, Vec3(0, 0, 0.01));
  s.add_induced(Vec3(0.003, 0.001, 0.05), magsim::test::ball_volume(), magsim::test::kIronMs);
  REQUIRE(solve_exact(&s, Curve::Tanh, FieldOptions{}).converged);
  MagWorkspace ws;
  std::vector<Vec3> F, Fc;
  compute_forces(s, ForceModel::Zeeman, Curve::Tanh, FieldOptions{}, &ws, &F, nullptr, &Fc);
  CHECK(F[1].isApprox(8.0 * Fc[1], 1e-4));
}

TEST_CASE("classic force between two permanent dipoles: closed form (eq. 14), 3rd law",
          "[forces]") {
  const Vec3 m1(0.2, -0.4, 1.0), m2(-0.5, 0.3, 0.6);
  const Vec3 p1(0.01, 0.02, -0.01), p2(-0.02, 0.03, 0.015);
  MomentSet s;
  s.add_permanent(p1, 1e-6, m1);
  s.add_permanent(p2, 1e-6, m2);
  MagWorkspace ws;
  std::vector<Vec3> F, tau;
  compute_forces(s, ForceModel::Classic, Curve::Tanh, FieldOptions{}, &ws, &F, &tau);
  // eq. 14 (the printed r⁴ in its second term must be r⁵ for the units to agree):
  // F on m from m_i, r = p − p_i:
  // μ0/(4π) [−15 r (m·r)(m_i·r)/r⁷ + 3 (r (m·m_i) + m (m_i·r) + m_i (m·r))/r⁵]
  auto closed = [](const Vec3& m, const Vec3& mi, const Vec3& r) {
    const double d = r.norm();
    return kMu0 / (4 * kPi) *
           (-15.0 * r * m.dot(r) * mi.dot(r) / std::pow(d, 7) +
            3.0 * (r * m.dot(mi) + m * mi.dot(r) + mi * m.dot(r)) / std::pow(d, 5));
  };
  CHECK(F[0].isApprox(closed(m1, m2, p1 - p2), 1e-12));
  CHECK(F[1].isApprox(closed(m2, m1, p2 - p1), 1e-12));
  CHECK((F[0] + F[1]).norm() <= 1e-12 * F[0].norm());
  // torques: τ = μ0 m × H; total angular momentum balance about the origin
  const Vec3 L = tau[0] + tau[1] + p1.cross(F[0]) + p2.cross(F[1]);
  CHECK(L.norm() <= 1e-10 * tau[0].norm());
}

TEST_CASE("reaction-symmetric Zeeman forces sum to zero where the literal ones do not",
          "[forces]") {
  // a strong 36-ball cluster under a magnet: the per-moment gradient of eq. 4 leaves a net
  // internal force (action ≠ reaction); the pairwise antisymmetrized force does not
  MomentSet s = magsim::test::cluster(500.0);
  REQUIRE(solve_exact(&s, Curve::Tanh, FieldOptions{}).converged);
  MagWorkspace ws;
  std::vector<Vec3> F, Fs;
  compute_forces(s, ForceModel::Zeeman, Curve::Tanh, FieldOptions{}, &ws, &F, nullptr);
  compute_forces(s, ForceModel::Zeeman, Curve::Tanh, FieldOptions{}, &ws, &Fs, nullptr, nullptr,
                 true);
  Vec3 net = Vec3::Zero(), net_s = Vec3::Zero();
  double largest = 0;
  for (std::size_t j = 0; j < s.size(); ++j) {
    net += F[j];
    net_s += Fs[j];
    largest = std::max(largest, F[j].norm());
  }
  INFO("net literal " << net.norm() << " N, symmetric " << net_s.norm() << " N, largest "
                      << largest << " N");
  CHECK(net.norm() > 0.1 * largest);
  CHECK(net_s.norm() <= 1e-10 * largest);
}

TEST_CASE("reaction-symmetric forces and torques conserve angular momentum", "[forces]") {
  // The pair energy behind the symmetric forces, U_ij = −½ μ0 [m̃_j·H_i(m_i) + m_j·H_i(m̃_i)],
  // conserves angular momentum when every moment gets its torque ½ μ0 (m̃ × H + m × H̃).
  // Induced moments get none (M is re-induced, it does not turn with its ball), so
  //   Σ_j (p_j × F_j + τ_j) = −½ μ0 Σ_induced m_j × H̃_j
  // exactly (about any origin), and the literal magnet torque μ0 m × H misses far more.
  // The magnet is tilted and off-centre so that symmetry cancels nothing.
  MomentSet s;
  for (int k = 0; k < 20; ++k)
    s.add_induced(Vec3(0.011 * (k % 4) - 0.015, 0.011 * ((k / 4) % 3) - 0.01, -0.012 - 0.011 * (k / 12)),
                  magsim::test::ball_volume(), magsim::test::kIronMs);
  s.add_permanent(Vec3(0.004, -0.003, 0.012), 1e-6, Vec3(0.4, -0.3, 1.0).normalized() * 20.0);
  REQUIRE(solve_exact(&s, Curve::Tanh, FieldOptions{}).converged);
  MagWorkspace ws;
  std::vector<Vec3> Fs, tau_s;
  compute_forces(s, ForceModel::Zeeman, Curve::Tanh, FieldOptions{}, &ws, &Fs, &tau_s, nullptr, true);
  const Vec3 origin(0.013, -0.021, 0.007);
  Vec3 L = Vec3::Zero(), induced_part = Vec3::Zero(), L_lit = Vec3::Zero();
  double scale = 0;
  for (std::size_t j = 0; j < s.size(); ++j) {
    const Vec3 r = s.position[j] - origin;
    L += r.cross(Fs[j]) + tau_s[j];
    const Vec3 tau_literal = s.kind[j] == MomentKind::Permanent ? Vec3(kMu0 * s.moment(j).cross(ws.H[j]))
                                                                : Vec3::Zero();
    L_lit += r.cross(Fs[j]) + tau_literal;
    if (s.kind[j] == MomentKind::Induced) induced_part += 0.5 * kMu0 * s.moment(j).cross(ws.H_eff_src[j]);
    scale = std::max(scale, r.norm() * Fs[j].norm());
  }
  INFO("net torque " << L.norm() << ", induced part " << induced_part.norm() << ", with the literal magnet torque "
                     << L_lit.norm() << ", scale " << scale << " N·m");
  CHECK((L + induced_part).norm() <= 1e-9 * scale);
  CHECK(L.norm() < 0.5 * L_lit.norm());
}
