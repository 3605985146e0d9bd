// magnetics/forces.cpp — forces after the magnetizations have converged (Algorithm 1,
// second half): one field + Jacobian evaluation, then a per-moment 3×3 formula.
#include "magnetics/forces.hpp"

#include "magnetics/curves.hpp"
#include "magnetics/dipole_field.hpp"
#include "magnetics/force_laws.hpp"
#include "magnetics/forces_total.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace magsim::mag {

namespace {

// The classic torques on bodies of several moments (forces.hpp, compute_forces):
//   τ_j = μ0 m_j × (H_j − H_j^same) (permanent),  τ_j = −μ0 m_j × H_j^same (induced),
// H^same the field of the moment's own group, summed here as compute_fields sums a pair
// (softened, bounded pairs clamped). Groups of one moment keep τ as it is.
void same_body_torques(const MomentDesc& set, const Magnetization& mz, const FieldOptions& field,
                       MagWorkspace* ws, std::vector<Vec3>* tau) {
  std::vector<int>& order = ws->group_order;
  order.clear();
  for (std::size_t j = 0; j < set.size(); ++j)
    if (set.group[j] >= 0) order.push_back(static_cast<int>(j));
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return set.group[a] < set.group[b]; });
  const bool bounded = pairs_bounded(set, field);
  const double eps2 = field.softening * field.softening;
  for (std::size_t b = 0; b < order.size();) {
    std::size_t e = b + 1;
    while (e < order.size() && set.group[order[e]] == set.group[order[b]]) ++e;
    for (std::size_t x = b; e - b > 1 && x < e; ++x) {
      const int j = order[x];
      Vec3 Hs = Vec3::Zero();
      for (std::size_t y = b; y < e; ++y) {
        const int i = order[y];
        if (i == j) continue;
        const Vec3 r = set.position[j] - set.position[i];
        const Vec3 rb = bounded ? bounded_separation(r, set.radius[i] + set.radius[j]) : r;
        Hs += dipole_field(rb, moment(set, mz, i), eps2);
      }
      const Vec3 m = moment(set, mz, j);
      (*tau)[j] = set.kind[j] == MomentKind::Permanent ? Vec3(kMu0 * m.cross(ws->H[j] - Hs))
                                                       : Vec3(-kMu0 * m.cross(Hs));
    }
    b = e;
  }
}

// Bounded pairs under the classic force: the clamped pair energy E(r) = E_dip(r_b(r)),
// r_b = r R/|r| for |r| < R = a_i + a_j, gives F_j = μ0 (∂r_b/∂r)ᵀ J(r_b) m_j with
// ∂r_b/∂r = (R/|r|)(I − r̂ r̂ᵀ): inside its bound a pair pulls no deeper (the energy is flat
// along r there) and its tangential part is scaled by R/|r|. compute_fields sums J(r_b)
// (sum_pairs); this adds μ0 (P − I) J(r_b) m_j for each pair of different groups inside its
// bound. The pairs are found on a grid of cells of 2 max_j a_j (one cell's 27 neighbours).
void bounded_pair_forces(const MomentDesc& set, const Magnetization& mz, const FieldOptions& field,
                         MagWorkspace* ws, std::vector<Vec3>* F) {
  const std::size_t n = set.size();
  double amax = 0.0;
  for (double a : set.radius) amax = std::max(amax, a);
  if (!(amax > 0.0)) return;
  const double cell = 2.0 * amax, eps2 = field.softening * field.softening;
  auto key_of = [&](const Vec3& p, int dx, int dy, int dz) {
    const auto c = [&](double x, int d) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(x / cell)) + d + (1 << 20)) & 0x1fffff;
    };
    return (c(p.x(), dx) << 42) | (c(p.y(), dy) << 21) | c(p.z(), dz);
  };
  std::vector<std::pair<std::uint64_t, int>>& cells = ws->bounded_cells;
  cells.clear();
  for (std::size_t j = 0; j < n; ++j)
    if (set.radius[j] > 0.0) cells.push_back({key_of(set.position[j], 0, 0, 0), static_cast<int>(j)});
  std::sort(cells.begin(), cells.end());
  for (const auto& [kj, j] : cells) {
    (void)kj;
    const Vec3 mj = moment(set, mz, j);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const std::uint64_t k = key_of(set.position[j], dx, dy, dz);
          auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(k, -1));
          for (; it != cells.end() && it->first == k; ++it) {
            const int i = it->second;
            if (i == j || (set.group[i] >= 0 && set.group[i] == set.group[j])) continue;
            const Vec3 r = set.position[j] - set.position[i];
            const double d = r.norm(), R = set.radius[i] + set.radius[j];
            if (!(d < R && d > 0.0)) continue;
            const Vec3 u = r / d;
            const Mat3 P = (R / d) * (Mat3::Identity() - u * u.transpose());
            const Vec3 Jm = dipole_jacobian(u * R, moment(set, mz, i), eps2) * mj;
            (*F)[j] += kMu0 * (P * Jm - Jm);
          }
        }
  }
}

}  // namespace

void compute_forces(const MomentDesc& set, const Magnetization& mz, ForceModel model,
                    Curve curve, const FieldOptions& field, MagWorkspace* ws, std::vector<Vec3>* F,
                    std::vector<Vec3>* tau, std::vector<Vec3>* F_classic,
                    bool reaction_symmetric, double total_tol, int total_max_iter) {
  compute_fields(set, mz, field, &ws->H, &ws->J, &ws->field);
  if (model == ForceModel::ZeemanTotal) {
    detail::zeeman_total_forces(set, mz, curve, field, ws, F, tau, F_classic, total_tol,
                                total_max_iter);
    return;
  }
  const long n = static_cast<long>(set.size());
  F->resize(n);
  if (tau) tau->resize(n);
  if (F_classic) F_classic->resize(n);
#pragma omp parallel for schedule(static)
  for (long j = 0; j < n; ++j) {
    const Vec3& H = ws->H[j];
    const Mat3& J = ws->J[j];
    const Vec3 m = moment(set, mz, j);
    const Vec3 Fc = classic_force(m, J);
    if (F_classic) (*F_classic)[j] = Fc;
    if (set.kind[j] == MomentKind::Permanent) {
      (*F)[j] = Fc;
      if (tau) (*tau)[j] = kMu0 * m.cross(H);  // τ = μ0 m × H
    } else {
      (*F)[j] = model == ForceModel::Zeeman
                    ? zeeman_force(curve, set.volume[j], set.Ms[j], mz.M[j], H, J)
                    : Fc;
      if (tau) (*tau)[j] = Vec3::Zero();
    }
  }
  if (model == ForceModel::Classic && pairs_bounded(set, field))
    bounded_pair_forces(set, mz, field, ws, F);
  if (model == ForceModel::Classic && tau) same_body_torques(set, mz, field, ws, tau);
  // the pair model's forces: −∇ of its pair energy, as the classic force is of U*'s pair sum
  if (model == ForceModel::Classic)
    add_near_field_forces(set, mz, field.near_field, &ws->field.near, F, tau);
  if (!(reaction_symmetric && model == ForceModel::Zeeman)) return;
  // the effective moments m̃_j = V_j [A_j(2M_j + H_j) + M_j] as sources (scratch set reused)
  MomentSet& eff = ws->effective;
  eff.assign(set, mz);
  for (long j = 0; j < n; ++j) {
    if (set.kind[j] != MomentKind::Induced) continue;
    const Mat3 A = curve_dMdH(curve, ws->H[j], set.Ms[j]);
    eff.M[j] = zeeman_effective_magnetization(A, mz.M[j], ws->H[j]);
  }
  compute_fields(eff, field, &ws->H_eff_src, &ws->J_eff_src, &ws->field);
  // F_j = ½ (F_zeeman,j + μ0 J̃_j m_j)
  for (long j = 0; j < n; ++j)
    (*F)[j] = 0.5 * ((*F)[j] + classic_force(moment(set, mz, j), ws->J_eff_src[j]));
  if (!tau) return;
  // the torque of a permanent moment from the same pair energy
  //   U_ij = −½ μ0 [m̃_j·H_i(m_i) + m_j·H_i(m̃_i)],  m̃ = m for permanent moments:
  //   τ_j = ½ μ0 m_j × (H_j + H̃_j),  H̃ the field of the effective moments.
  // Induced moments get none: M is re-induced, it does not turn with its ball. With the
  // literal τ = μ0 m × H the magnet of falling_magnet (0.25 kg, iron on it) tumbles and rolls
  // off across the ground: 432 balls, 1 s, final KE 0.55 J → 0.27 J with this torque.
  for (long j = 0; j < n; ++j)
    if (set.kind[j] == MomentKind::Permanent)
      (*tau)[j] = 0.5 * kMu0 * moment(set, mz, j).cross(ws->H[j] + ws->H_eff_src[j]);
}

}  // namespace magsim::mag
