// magnetics/dipole_field.cpp — direct O(N·S) sum of dipole fields and Jacobians.
//
// The kernel packs the sources into flat arrays once per call and sweeps them with a
// branch-free inner loop (self and same-group terms are masked, not skipped), so the
// compiler vectorizes it; targets are split across threads.
#include "magnetics/dipole_field.hpp"

#include <cmath>

namespace magsim::mag {

namespace {
constexpr double kInv4Pi = 1.0 / (4.0 * kPi);
}

// eq. 1: h = (1/4π)(3 r (r·m) − q m)/q^{5/2}, q = |r|² + ε²
Vec3 dipole_field(const Vec3& r, const Vec3& m, double eps2) {
  const double q = r.squaredNorm() + eps2;
  const double inv = 1.0 / std::sqrt(q);
  const double inv3 = inv * inv * inv;
  const double inv5 = inv3 * inv * inv;
  return kInv4Pi * (3.0 * r.dot(m) * inv5 * r - inv3 * m);
}

// ∂h/∂r = (1/4π)[3(I(r·m) + r mᵀ + m rᵀ)/q^{5/2} − 15 r rᵀ (r·m)/q^{7/2}]
Mat3 dipole_jacobian(const Vec3& r, const Vec3& m, double eps2) {
  const double q = r.squaredNorm() + eps2;
  const double inv = 1.0 / std::sqrt(q);
  const double inv2 = inv * inv;
  const double inv5 = inv2 * inv2 * inv;
  const double inv7 = inv5 * inv2;
  const double rm = r.dot(m);
  Mat3 J = 3.0 * inv5 * (rm * Mat3::Identity() + r * m.transpose() + m * r.transpose()) -
           15.0 * inv7 * rm * (r * r.transpose());
  return kInv4Pi * J;
}

namespace {

void pack_sources(const MomentSet& set, FieldWorkspace* ws) {
  ws->sx.clear(); ws->sy.clear(); ws->sz.clear();
  ws->smx.clear(); ws->smy.clear(); ws->smz.clear();
  ws->sindex.clear(); ws->sgroup.clear();
  for (std::size_t i = 0; i < set.size(); ++i) {
    const Vec3 m = set.moment(i);
    if (m.x() == 0.0 && m.y() == 0.0 && m.z() == 0.0) continue;
    const Vec3& p = set.position[i];
    ws->sx.push_back(p.x()); ws->sy.push_back(p.y()); ws->sz.push_back(p.z());
    ws->smx.push_back(m.x()); ws->smy.push_back(m.y()); ws->smz.push_back(m.z());
    ws->sindex.push_back(static_cast<std::int32_t>(i));
    ws->sgroup.push_back(set.group[i]);
  }
}

// Sum over the packed sources at target j. kJac: also the 6 unique Jacobian entries
// (xx, yy, zz, xy, xz, yz) over sources of another group.
template <bool kJac>
void sum_at(const FieldWorkspace& ws, double eps2, double px, double py, double pz,
            std::int32_t self, std::int32_t grp, double* Hout, double* Jout) {
  const std::size_t ns = ws.sx.size();
  const double* __restrict sx = ws.sx.data();
  const double* __restrict sy = ws.sy.data();
  const double* __restrict sz = ws.sz.data();
  const double* __restrict mx = ws.smx.data();
  const double* __restrict my = ws.smy.data();
  const double* __restrict mz = ws.smz.data();
  const std::int32_t* __restrict si = ws.sindex.data();
  const std::int32_t* __restrict sg = ws.sgroup.data();
  double hx = 0, hy = 0, hz = 0;
  double jxx = 0, jyy = 0, jzz = 0, jxy = 0, jxz = 0, jyz = 0;
#pragma omp simd reduction(+ : hx, hy, hz, jxx, jyy, jzz, jxy, jxz, jyz)
  for (std::size_t i = 0; i < ns; ++i) {
    const double dx = px - sx[i], dy = py - sy[i], dz = pz - sz[i];
    const bool is_self = si[i] == self;
    const double q = is_self ? 1.0 : dx * dx + dy * dy + dz * dz + eps2;
    const double w = is_self ? 0.0 : 1.0;
    const double inv = 1.0 / std::sqrt(q);
    const double inv2 = inv * inv;
    const double inv3 = inv2 * inv;
    const double inv5 = inv3 * inv2;
    const double rm = dx * mx[i] + dy * my[i] + dz * mz[i];
    // eq. 1
    const double a = w * 3.0 * rm * inv5;
    const double b = w * inv3;
    hx += a * dx - b * mx[i];
    hy += a * dy - b * my[i];
    hz += a * dz - b * mz[i];
    if constexpr (kJac) {
      const double wj = (grp >= 0 && sg[i] == grp) ? 0.0 : w;
      const double c3 = wj * 3.0 * inv5;
      const double c15 = wj * 15.0 * inv5 * inv2 * rm;
      jxx += c3 * (rm + 2.0 * dx * mx[i]) - c15 * dx * dx;
      jyy += c3 * (rm + 2.0 * dy * my[i]) - c15 * dy * dy;
      jzz += c3 * (rm + 2.0 * dz * mz[i]) - c15 * dz * dz;
      jxy += c3 * (dx * my[i] + mx[i] * dy) - c15 * dx * dy;
      jxz += c3 * (dx * mz[i] + mx[i] * dz) - c15 * dx * dz;
      jyz += c3 * (dy * mz[i] + my[i] * dz) - c15 * dy * dz;
    }
  }
  Hout[0] = hx * kInv4Pi; Hout[1] = hy * kInv4Pi; Hout[2] = hz * kInv4Pi;
  if constexpr (kJac) {
    Jout[0] = jxx * kInv4Pi; Jout[1] = jyy * kInv4Pi; Jout[2] = jzz * kInv4Pi;
    Jout[3] = jxy * kInv4Pi; Jout[4] = jxz * kInv4Pi; Jout[5] = jyz * kInv4Pi;
  }
}

}  // namespace

void compute_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                    std::vector<Mat3>* J, FieldWorkspace* ws) {
  pack_sources(set, ws);
  const long n = static_cast<long>(set.size());
  H->resize(n);
  if (J) J->resize(n);
  const double eps2 = opt.softening * opt.softening;
#pragma omp parallel for schedule(static)
  for (long j = 0; j < n; ++j) {
    const Vec3& p = set.position[j];
    double h[3], jac[6];
    if (J) {
      sum_at<true>(*ws, eps2, p.x(), p.y(), p.z(), static_cast<std::int32_t>(j), set.group[j], h, jac);
      Mat3& Jj = (*J)[j];
      Jj << jac[0], jac[3], jac[4],
            jac[3], jac[1], jac[5],
            jac[4], jac[5], jac[2];
    } else {
      sum_at<false>(*ws, eps2, p.x(), p.y(), p.z(), static_cast<std::int32_t>(j), set.group[j], h, jac);
    }
    (*H)[j] = set.H0 + Vec3(h[0], h[1], h[2]);
  }
}

Vec3 field_at(const MomentSet& set, const Vec3& p, double eps2, int skip, Mat3* J) {
  Vec3 H = set.H0;
  if (J) J->setZero();
  for (std::size_t i = 0; i < set.size(); ++i) {
    if (static_cast<int>(i) == skip) continue;
    const Vec3 m = set.moment(i);
    const Vec3 r = p - set.position[i];
    H += dipole_field(r, m, eps2);
    if (J) *J += dipole_jacobian(r, m, eps2);
  }
  return H;
}

}  // namespace magsim::mag
