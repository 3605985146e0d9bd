// magnetics/anderson.cpp — Anderson-accelerated Picard iteration for M = f(H(M)).
//
// The Picard map x ↦ g(x) = f(H(x))/Ms (eq. 10 applied to the field of eq. 1) is a
// contraction only where the moments are weakly coupled: in a packed pile of soft iron the
// linearized map has eigenvalues below −1 (each ball's demagnetizing neighbours), and Picard
// alone diverges. Anderson mixing (Walker & Ni 2011, "type II") combines the last few
// residuals so that, for the linear part, it acts like GMRES on (I − g'), and converges in a
// handful of field evaluations where the dynamics take tens to thousands of sweeps.
#include "magnetics/anderson.hpp"

#include "magnetics/curves.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace magsim::mag {

namespace {

// Fields at the current state, then g_j = f(H_j)/Ms_j (eq. 10) for the induced moments.
void picard_image(const MomentDesc& set, const Magnetization& mz, const DynamicsOptions& opt,
                  MagWorkspace* ws) {
  compute_fields(set, mz, opt.field, &ws->H, nullptr, &ws->field);
  AndersonHistory& h = ws->anderson;
  const Curve curve = curve_of(Method::Anderson, opt.field.near_field.curve);
  const long k = static_cast<long>(h.idx.size());
#pragma omp parallel for schedule(static)
  for (long a = 0; a < k; ++a) {
    const int j = h.idx[a];
    const Vec3 g = curve_M(curve, ws->H[j], set.Ms[j]) / set.Ms[j];
    h.g[3 * a] = g.x();
    h.g[3 * a + 1] = g.y();
    h.g[3 * a + 2] = g.z();
  }
}

double dot(const double* a, const double* b, std::size_t n) {
  double s = 0;
  for (std::size_t i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

// γ = argmin ‖f − ΔF γ‖ by modified Gram–Schmidt on the held columns (oldest first).
// A column whose part orthogonal to the older ones is below 1e-8 of its norm makes the
// problem ill-conditioned: the oldest column is dropped and the factorization redone.
// Returns the number of columns used (their γ in h->gamma, oldest first).
int least_squares(AndersonHistory* h, int depth) {
  const std::size_t n = h->x.size();
  for (;;) {
    const int m = h->cols;
    if (m == 0) return 0;
    bool ok = true;
    for (int i = 0; i < m && ok; ++i) {
      const int slot = (h->head - m + i + depth) % depth;
      double* q = &h->Q[std::size_t(i) * n];
      const double* col = &h->dF[std::size_t(slot) * n];
      std::copy(col, col + n, q);
      const double cn = std::sqrt(dot(q, q, n));
      for (int j = 0; j < i; ++j) {
        const double* qj = &h->Q[std::size_t(j) * n];
        const double r = dot(qj, q, n);
        h->R[std::size_t(j) * depth + i] = r;
        for (std::size_t e = 0; e < n; ++e) q[e] -= r * qj[e];
      }
      const double rii = std::sqrt(dot(q, q, n));
      if (!(rii > 1e-8 * cn)) {
        ok = false;
        break;
      }
      h->R[std::size_t(i) * depth + i] = rii;
      for (std::size_t e = 0; e < n; ++e) q[e] /= rii;
    }
    if (ok) break;
    --h->cols;  // drop the oldest difference
  }
  const int m = h->cols;
  // γ = R⁻¹ Qᵀ f
  for (int i = 0; i < m; ++i) h->gamma[i] = dot(&h->Q[std::size_t(i) * n], h->f.data(), n);
  for (int i = m - 1; i >= 0; --i) {
    double v = h->gamma[i];
    for (int j = i + 1; j < m; ++j) v -= h->R[std::size_t(i) * depth + j] * h->gamma[j];
    h->gamma[i] = v / h->R[std::size_t(i) * depth + i];
  }
  return m;
}

// Writes the stacked x back into the set: M_j = Ms_j x_j, sub-pairs about it.
void store(const AndersonHistory& h, const MomentDesc& set, Magnetization* mz) {
  const long k = static_cast<long>(h.idx.size());
#pragma omp parallel for schedule(static)
  for (long a = 0; a < k; ++a) {
    const int j = h.idx[a];
    mz->set_magnetization(j, set.Ms[j] * Vec3(h.x[3 * a], h.x[3 * a + 1], h.x[3 * a + 2]),
                          set.Ms[j]);
  }
}

}  // namespace

double picard_iteration(const MomentDesc& set, Magnetization* mz, const DynamicsOptions& opt,
                        MagWorkspace* ws) {
  compute_fields(set, *mz, opt.field, &ws->H, nullptr, &ws->field);
  const Curve curve = curve_of(Method::Anderson, opt.field.near_field.curve);
  const long n = static_cast<long>(set.size());
  double max_change = 0.0;
#pragma omp parallel for schedule(static) reduction(max : max_change)
  for (long j = 0; j < n; ++j) {
    if (!set.solved(j)) continue;
    const double Ms = set.Ms[j];
    const Vec3 M_old = mz->M[j];
    mz->set_magnetization(j, curve_M(curve, ws->H[j], Ms), Ms);  // M = f(H)
    max_change = std::max(max_change, (mz->M[j] - M_old).norm() / Ms);
  }
  return max_change;
}

RelaxStats relax_anderson(const MomentDesc& set, Magnetization* mz, const DynamicsOptions& opt,
                          MagWorkspace* ws,
                          const std::function<void(int, const Magnetization&)>& on_iteration) {
  RelaxStats st;
  AndersonHistory& h = ws->anderson;
  h.idx.clear();
  for (std::size_t j = 0; j < set.size(); ++j)
    if (set.solved(j)) h.idx.push_back(static_cast<int>(j));
  const int depth = std::max(0, opt.anderson_depth);
  const std::size_t n = 3 * h.idx.size();
  for (auto* v : {&h.x, &h.g, &h.f, &h.x_prev, &h.f_prev}) v->resize(n);
  const std::size_t cols_cap = static_cast<std::size_t>(std::max(depth, 1));
  for (auto* v : {&h.dX, &h.dF, &h.Q}) v->resize(n * cols_cap);
  h.R.resize(cols_cap * cols_cap);
  h.gamma.resize(cols_cap);
  h.cols = 0;
  h.head = 0;
  h.beta = opt.anderson_damping;
  for (std::size_t a = 0; a < h.idx.size(); ++a) {
    const int j = h.idx[a];
    for (int c = 0; c < 3; ++c) h.x[3 * a + c] = mz->M[j][c] / set.Ms[j];
  }
  double f_norm_prev = std::numeric_limits<double>::infinity();
  for (int it = 1; it <= opt.max_iter; ++it) {
    // residual r = g(x) − x at the current iterate (one field evaluation)
    picard_image(set, *mz, opt, ws);
    double f2 = 0, f_max = 0;
    for (std::size_t a = 0; a < h.idx.size(); ++a) {
      double b2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double r = h.g[3 * a + c] - h.x[3 * a + c];
        h.f[3 * a + c] = r;
        b2 += r * r;
      }
      f2 += b2;
      f_max = std::max(f_max, std::sqrt(b2));
    }
    const double f_norm = std::sqrt(f2);
    // new differences, or a restart when the residual grew
    if (it > 1 && depth > 0) {
      if (f_norm > opt.anderson_restart_growth * f_norm_prev) {
        h.cols = 0;
        h.head = 0;
        h.beta = std::max(0.5 * h.beta, 0.125 * opt.anderson_damping);
      } else {
        double* dx = &h.dX[std::size_t(h.head) * n];
        double* df = &h.dF[std::size_t(h.head) * n];
        for (std::size_t e = 0; e < n; ++e) {
          dx[e] = h.x[e] - h.x_prev[e];
          df[e] = h.f[e] - h.f_prev[e];
        }
        h.head = (h.head + 1) % depth;
        h.cols = std::min(h.cols + 1, depth);
      }
    }
    std::copy(h.x.begin(), h.x.end(), h.x_prev.begin());
    std::copy(h.f.begin(), h.f.end(), h.f_prev.begin());
    f_norm_prev = f_norm;
    // x_{k+1} = x_k + β r_k − Σ γ_i (Δx_i + β Δr_i), then |x_j| ≤ 1
    const int m = depth > 0 ? least_squares(&h, depth) : 0;
    const double beta = h.beta;
    for (std::size_t e = 0; e < n; ++e) h.x[e] += beta * h.f[e];
    for (int i = 0; i < m; ++i) {
      const int slot = (h.head - m + i + depth) % depth;
      const double* dx = &h.dX[std::size_t(slot) * n];
      const double* df = &h.dF[std::size_t(slot) * n];
      const double gi = h.gamma[i];
      for (std::size_t e = 0; e < n; ++e) h.x[e] -= gi * (dx[e] + beta * df[e]);
    }
    double change = 0;
    for (std::size_t a = 0; a < h.idx.size(); ++a) {
      double* v = &h.x[3 * a];
      const double vn = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (vn > 1.0)
        for (int c = 0; c < 3; ++c) v[c] /= vn;
      const double dx = v[0] - h.x_prev[3 * a], dy = v[1] - h.x_prev[3 * a + 1],
                   dz = v[2] - h.x_prev[3 * a + 2];
      change = std::max(change, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    store(h, set, mz);
    st.iterations = it;
    st.last_change = change;
    st.last_residual = f_max;
    if (on_iteration) on_iteration(it, *mz);
    // the dynamics' stopping rule (DynamicsOptions::criterion): the residual of the iterate
    // the fields came from, or the change of this step — with the residual too, so that a
    // stalled mixing cannot stop early
    const double crit = opt.criterion == DynamicsOptions::Criterion::Residual
                            ? f_max
                            : std::max(change, f_max);
    if (crit < opt.tol) {
      st.converged = true;
      break;
    }
  }
  return st;
}

}  // namespace magsim::mag
