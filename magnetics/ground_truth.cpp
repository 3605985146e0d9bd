// magnetics/ground_truth.cpp — Newton's method on R(M) = M − f(H(M)).
//
// H is affine in the induced magnetizations: H_j = Hb_j + Σ_{i≠j} G(p_j − p_i) V_i M_i,
// with Hb the external field plus the permanent moments' fields and
// G(r) = (1/4π)(3 r rᵀ − q I)/q^{5/2} (eq. 1 as a matrix). So ∂R/∂M = I − A T with
// A = blockdiag(∂f/∂H) and T the dense interaction matrix. The near-field pair model's field
// (near_field.hpp) is not affine in M: it is evaluated at each iterate, and its blocks
// ∂H/∂M join T in the Newton matrix.
#include "magnetics/ground_truth.hpp"

#include "magnetics/curves.hpp"
#include "magnetics/dipole_field.hpp"
#include "magnetics/near_field.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace magsim::mag {

namespace {

struct Problem {
  std::vector<int> idx;   // induced moment indices
  Eigen::VectorXd Hb;     // (3k) field from H0 and permanent moments
  Eigen::MatrixXd T;      // (3k × 3k) induced–induced interaction (times volume)
};

Problem build(const MomentDesc& set, const FieldOptions& field) {
  Problem P;
  for (std::size_t j = 0; j < set.size(); ++j)
    if (set.kind[j] == MomentKind::Induced) P.idx.push_back(static_cast<int>(j));
  const int k = static_cast<int>(P.idx.size());
  const double eps2 = field.softening * field.softening;
  // pairs as compute_fields sums them: softened, and clamped to their bound (bounded pairs)
  const bool bounded = pairs_bounded(set, field);
  auto sep = [&](std::size_t j, std::size_t i) {
    const Vec3 r = set.position[j] - set.position[i];
    return bounded ? bounded_separation(r, set.radius[i] + set.radius[j]) : r;
  };
  P.Hb.resize(3 * k);
  P.T.setZero(3 * k, 3 * k);
  const double inv4pi = 1.0 / (4.0 * kPi);
  for (int a = 0; a < k; ++a) {
    const int j = P.idx[a];
    Vec3 hb = set.H0;
    for (std::size_t i = 0; i < set.size(); ++i)
      if (set.kind[i] == MomentKind::Permanent)
        hb += dipole_field(sep(j, i), set.m_perm[i], eps2);
    P.Hb.segment<3>(3 * a) = hb;
    for (int b = 0; b < k; ++b) {
      if (a == b) continue;
      const int i = P.idx[b];
      const Vec3 r = sep(j, i);
      const double q = r.squaredNorm() + eps2;
      const double inv = 1.0 / std::sqrt(q);
      const double inv3 = inv * inv * inv;
      const double inv5 = inv3 * inv * inv;
      const Mat3 G = inv4pi * (3.0 * inv5 * (r * r.transpose()) - inv3 * Mat3::Identity());
      P.T.block<3, 3>(3 * a, 3 * b) = G * set.volume[i];
    }
  }
  return P;
}

// The pair model's field at the iterate M (scratch: a magnetization holding M, and the
// field of every moment)
struct Near {
  const NearFieldOptions* opt;
  NearFieldWorkspace ws;
  Magnetization mz;
  std::vector<Vec3> H;
  bool on() const { return opt->model == NearField::Pair; }
  void load(const Problem& P, const Eigen::VectorXd& M) {
    for (std::size_t a = 0; a < P.idx.size(); ++a) mz.M[P.idx[a]] = M.segment<3>(3 * a);
  }
};

Eigen::VectorXd residual(const MomentDesc& set, const Problem& P, Curve curve, Near* nf,
                         const Eigen::VectorXd& M, Eigen::VectorXd* H) {
  *H = P.Hb + P.T * M;
  if (nf->on()) {
    nf->load(P, M);
    nf->H.assign(set.size(), Vec3::Zero());
    add_near_field(set, nf->mz, *nf->opt, &nf->ws, &nf->H);
    for (std::size_t a = 0; a < P.idx.size(); ++a) H->segment<3>(3 * a) += nf->H[P.idx[a]];
  }
  Eigen::VectorXd R(M.size());
  for (std::size_t a = 0; a < P.idx.size(); ++a) {
    const Vec3 Ha = H->segment<3>(3 * a);
    R.segment<3>(3 * a) = M.segment<3>(3 * a) - curve_M(curve, Ha, set.Ms[P.idx[a]]);
  }
  return R;
}

}  // namespace

ExactStats solve_exact(const MomentDesc& set, Magnetization* mz, Curve curve,
                       const FieldOptions& field, double rel_tol, int max_steps,
                       const std::function<void(int, double)>& on_step) {
  ExactStats st;
  const Problem P = build(set, field);
  const int k = static_cast<int>(P.idx.size());
  if (k == 0) {
    st.converged = true;
    return st;
  }
  Eigen::VectorXd M(3 * k), H;
  for (int a = 0; a < k; ++a) M.segment<3>(3 * a) = mz->M[P.idx[a]];
  // an unmagnetized start begins from each ball alone in the applied field: from M = 0 a
  // stiff curve (Curve::Iron) can send Newton to |M| ≈ Ms, where the pair model's saturation
  // is clamped flat and ‖R‖ stalls
  if (M.squaredNorm() == 0.0)
    for (int a = 0; a < k; ++a) M.segment<3>(3 * a) = curve_M(curve, P.Hb.segment<3>(3 * a), set.Ms[P.idx[a]]);
  Near nf{&field.near_field, {}, *mz, {}};
  std::vector<int> slot(set.size(), -1);
  for (int a = 0; a < k; ++a) slot[P.idx[a]] = a;
  std::vector<NearBlock> blocks;
  Eigen::VectorXd R = residual(set, P, curve, &nf, M, &H);
  auto rel = [&](const Eigen::VectorXd& r, const Eigen::VectorXd& m) {
    const double mn = m.norm();
    return mn > 0 ? r.norm() / mn : r.norm();
  };
  Eigen::MatrixXd Jac(3 * k, 3 * k);
  for (int step = 0; step < max_steps; ++step) {
    st.residual = rel(R, M);
    if (st.residual <= rel_tol && M.norm() > 0) {
      st.converged = true;
      break;
    }
    // Newton matrix I − A (T + ∂H_near/∂M)
    Jac = -P.T;
    if (nf.on()) {
      nf.load(P, M);
      near_field_jacobian(set, nf.mz, *nf.opt, &nf.ws, &blocks);
      for (const NearBlock& b : blocks) Jac.block<3, 3>(3 * slot[b.a], 3 * slot[b.b]) -= b.D;
    }
    for (int a = 0; a < k; ++a) {
      const Mat3 A = curve_dMdH(curve, H.segment<3>(3 * a), set.Ms[P.idx[a]]);
      Jac.middleRows<3>(3 * a) = A * Jac.middleRows<3>(3 * a);
    }
    Jac += Eigen::MatrixXd::Identity(3 * k, 3 * k);
    const Eigen::VectorXd delta = Jac.partialPivLu().solve(-R);
    // backtracking line search on ‖R‖
    double lam = 1.0;
    const double r0 = R.norm();
    Eigen::VectorXd Mn, Hn, Rn;
    for (int ls = 0; ls < 40; ++ls) {
      Mn = M + lam * delta;
      Rn = residual(set, P, curve, &nf, Mn, &Hn);
      if (Rn.norm() < (1.0 - 1e-4 * lam) * r0 || Rn.norm() == 0.0) break;
      lam *= 0.5;
    }
    M = Mn;
    H = Hn;
    R = Rn;
    st.newton_steps = step + 1;
    if (on_step) on_step(st.newton_steps, rel(R, M));
  }
  st.residual = rel(R, M);
  st.converged = st.converged || st.residual <= rel_tol;
  for (int a = 0; a < k; ++a) {
    const int j = P.idx[a];
    const Vec3 Mj = M.segment<3>(3 * a);
    if (Mj.norm() <= set.Ms[j]) mz->set_magnetization(j, Mj, set.Ms[j]);
    else mz->M[j] = Mj;  // cannot happen for a converged solve: f saturates at Ms
  }
  return st;
}

// eq. 12
double magnetization_error(const MomentSet& set, const std::vector<Vec3>& M_gt) {
  double num = 0, den = 0;
  for (std::size_t j = 0; j < set.size(); ++j) {
    if (set.kind[j] != MomentKind::Induced) continue;
    num += (M_gt[j] - set.M[j]).squaredNorm();
    den += M_gt[j].squaredNorm();
  }
  return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

double max_moment_error(const MomentSet& set, const std::vector<Vec3>& M_gt) {
  double e = 0;
  for (std::size_t j = 0; j < set.size(); ++j) {
    if (set.kind[j] != MomentKind::Induced) continue;
    const double d = M_gt[j].norm();
    if (d > 0) e = std::max(e, (M_gt[j] - set.M[j]).norm() / d);
  }
  return e;
}

}  // namespace magsim::mag
