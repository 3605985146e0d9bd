// magnetics/forces_total.cpp — eq. 4 as the gradient of the system's Zeeman energy
// (ForceModel::ZeemanTotal; the derivation is at the top of forces_total.hpp).
#include "magnetics/forces_total.hpp"

#include "magnetics/curves.hpp"
#include "magnetics/force_laws.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace magsim::mag {
namespace detail {
namespace {

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i].dot(b[i]);
  return s;
}

// (V A)^{1/2} of a symmetric positive semi-definite 3×3 (A = ∂f/∂H of a monotone curve);
// eigenvalues below zero can only be rounding and count as zero
Mat3 sqrt_psd(const Mat3& S) {
  Eigen::SelfAdjointEigenSolver<Mat3> es(S);
  const Vec3 l = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return es.eigenvectors() * l.asDiagonal() * es.eigenvectors().transpose();
}

// z = T u: the field at the induced moments of moments u (A·m²) placed at the induced moments
void apply_T(const std::vector<Vec3>& u, const FieldOptions& field, MagWorkspace* ws,
             std::vector<Vec3>* z) {
  ZeemanTotalScratch& t = ws->total;
  for (std::size_t a = 0; a < t.idx.size(); ++a) {
    const int j = t.idx[a];
    t.src.M[j] = u[a] / t.src.volume[j];
  }
  compute_fields(t.src, field, &t.Hs, nullptr, &ws->field);
  z->resize(t.idx.size());
  for (std::size_t a = 0; a < t.idx.size(); ++a) (*z)[a] = t.Hs[t.idx[a]];
}

// q = (I − B T B) u
void apply_S(const std::vector<Vec3>& u, const FieldOptions& field, MagWorkspace* ws,
             std::vector<Vec3>* q) {
  ZeemanTotalScratch& t = ws->total;
  const std::size_t k = t.idx.size();
  std::vector<Vec3>& Bu = t.z;  // scratch: B u, then T B u
  Bu.resize(k);
  for (std::size_t a = 0; a < k; ++a) Bu[a] = t.B[a] * u[a];
  apply_T(Bu, field, ws, &Bu);
  q->resize(k);
  for (std::size_t a = 0; a < k; ++a) (*q)[a] = u[a] - t.B[a] * Bu[a];
}

}  // namespace

// (forces_total.hpp)
void permanent_field(const MomentDesc& set, const Magnetization& mz, const FieldOptions& field,
                     MomentSet* scratch, std::vector<int>* perm, std::vector<Vec3>* Hp,
                     std::vector<Mat3>* Jp, FieldWorkspace* ws) {
  perm->clear();
  scratch->assign(set, mz);
  for (std::size_t j = 0; j < set.size(); ++j) {
    if (set.kind[j] == MomentKind::Induced)
      scratch->M[j] = Vec3::Zero();
    else
      perm->push_back(static_cast<int>(j));
  }
  if (!perm->empty()) compute_fields_at(*scratch, field, *perm, Hp, Jp, ws);
}

void zeeman_total_forces(const MomentDesc& set, const Magnetization& mz, Curve curve,
                         const FieldOptions& field, MagWorkspace* ws, std::vector<Vec3>* F,
                         std::vector<Vec3>* tau, std::vector<Vec3>* F_classic, double tol,
                         int max_iter) {
  ZeemanTotalScratch& t = ws->total;
  const std::size_t n = set.size();
  t.idx.clear();
  for (std::size_t j = 0; j < n; ++j)
    if (set.kind[j] == MomentKind::Induced) t.idx.push_back(static_cast<int>(j));
  const std::size_t k = t.idx.size();
  if (t.w.size() != k) t.w.assign(k, Vec3::Zero());  // no warm start across a change of set

  // the sources of the adjoint field: induced moments only, no uniform field
  t.src.assign(set, mz);
  t.src.H0 = Vec3::Zero();
  for (std::size_t j = 0; j < n; ++j)
    if (set.kind[j] == MomentKind::Permanent) t.src.m_perm[j] = Vec3::Zero();

  // m̃_i = V_i [A_i (2M_i + H_i) + M_i],  B_i = (V_i A_i)^{1/2}
  t.mt.resize(k);
  t.B.resize(k);
  for (std::size_t a = 0; a < k; ++a) {
    const int j = t.idx[a];
    const Mat3 A = curve_dMdH(curve, ws->H[j], set.Ms[j]);
    t.mt[a] = set.volume[j] * zeeman_effective_magnetization(A, mz.M[j], ws->H[j]);
    t.B[a] = sqrt_psd(set.volume[j] * 0.5 * (A + A.transpose()));
  }

  // (I − B T B) w = c,  c = B T m̃: preconditioner-free conjugate gradients, warm-started
  apply_T(t.mt, field, ws, &t.c);
  for (std::size_t a = 0; a < k; ++a) t.c[a] = t.B[a] * t.c[a];
  const double c_norm = std::sqrt(dot(t.c, t.c));
  t.iterations = 0;
  t.converged = true;
  t.residual = 0.0;
  if (c_norm > 0.0) {
    apply_S(t.w, field, ws, &t.q);
    t.r.resize(k);
    for (std::size_t a = 0; a < k; ++a) t.r[a] = t.c[a] - t.q[a];
    t.p = t.r;
    double rr = dot(t.r, t.r);
    while (std::sqrt(rr) > tol * c_norm && t.iterations < max_iter) {
      apply_S(t.p, field, ws, &t.q);
      const double pq = dot(t.p, t.q);
      if (!(pq > 0.0)) break;  // not positive definite here (an unstable equilibrium)
      const double alpha = rr / pq;
      for (std::size_t a = 0; a < k; ++a) {
        t.w[a] += alpha * t.p[a];
        t.r[a] -= alpha * t.q[a];
      }
      const double rr_new = dot(t.r, t.r);
      for (std::size_t a = 0; a < k; ++a) t.p[a] = t.r[a] + (rr_new / rr) * t.p[a];
      rr = rr_new;
      ++t.iterations;
    }
    t.residual = std::sqrt(rr) / c_norm;
    t.converged = t.residual <= tol;
  } else {
    std::fill(t.w.begin(), t.w.end(), Vec3::Zero());
  }

  // λ̃ = m̃ + B w as sources: H̃ and J̃ at every moment
  for (std::size_t a = 0; a < k; ++a) {
    const int j = t.idx[a];
    t.src.M[j] = (t.mt[a] + t.B[a] * t.w[a]) / set.volume[j];
  }
  compute_fields(t.src, field, &t.Hs, &t.Js, &ws->field);

  // the permanent moments' own field (with H0) at the permanent moments
  permanent_field(set, mz, field, &ws->effective, &t.perm, &t.Hp, &t.Jp, &ws->field);

  F->resize(n);
  if (tau) tau->resize(n);
  if (F_classic) F_classic->resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    const Vec3 m = moment(set, mz, j);
    if (F_classic) (*F_classic)[j] = classic_force(m, ws->J[j]);
    if (tau) (*tau)[j] = Vec3::Zero();
  }
  // F_k = μ0 [J_kᵀ λ̃_k + J̃_kᵀ m_k]
  for (std::size_t a = 0; a < k; ++a) {
    const int j = t.idx[a];
    const Vec3 lam = set.volume[j] * t.src.M[j];
    (*F)[j] = kMu0 * (ws->J[j].transpose() * lam + t.Js[j].transpose() * moment(set, mz, j));
  }
  // F_p = μ0 (J̃_p + J^perm_p)ᵀ m_p,  τ_p = μ0 m_p × (H̃_p + H^perm_p)
  for (std::size_t a = 0; a < t.perm.size(); ++a) {
    const int p = t.perm[a];
    const Vec3 m = moment(set, mz, p);
    (*F)[p] = kMu0 * ((t.Js[p] + t.Jp[a]).transpose() * m);
    if (tau) (*tau)[p] = kMu0 * m.cross(t.Hs[p] + t.Hp[a]);
  }
}

}  // namespace detail

// E_sys = Σ_{i induced} e_i(H_i) + U_pp (forces_total.hpp), from the field at every moment and
// the permanent moments' own field Hp at the permanent moments perm
double zeeman_total_energy(const MomentDesc& set, const Magnetization& mz, Curve curve,
                           const std::vector<Vec3>& H, const std::vector<int>& perm,
                           const std::vector<Vec3>& Hp) {
  double E = 0.0;
  for (std::size_t j = 0; j < set.size(); ++j)
    if (set.kind[j] == MomentKind::Induced) E += zeeman_energy(curve, set.volume[j], set.Ms[j], H[j]);
  // U_pp = −μ0 [½ Σ_p m_p·(H^perm_p − H0) + Σ_p m_p·H0]
  for (std::size_t a = 0; a < perm.size(); ++a) {
    const Vec3 m = moment(set, mz, perm[a]);
    E -= kMu0 * (0.5 * m.dot(Hp[a] - set.H0) + m.dot(set.H0));
  }
  return E;
}

double zeeman_total_energy(const MomentDesc& set, const Magnetization& mz, Curve curve,
                           const FieldOptions& field, FieldWorkspace* ws) {
  std::vector<Vec3> H, Hp;
  compute_fields(set, mz, field, &H, nullptr, ws);
  MomentSet scratch;
  std::vector<int> perm;
  detail::permanent_field(set, mz, field, &scratch, &perm, &Hp, nullptr, ws);
  return zeeman_total_energy(set, mz, curve, H, perm, Hp);
}

}  // namespace magsim::mag
