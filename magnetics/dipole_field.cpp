// magnetics/dipole_field.cpp — the dipole field of one moment and the direct O(N·S) sum of
// dipole fields and Jacobians.
//
// The nonzero sources are packed into flat, padded arrays once per call and swept by the
// pair kernel (pair_kernel.cpp: AVX-512 where the CPU has it, else a portable loop).
// Targets are split across threads; sources are swept in cache-sized chunks so that 100k
// sources stream from L2, not from memory.
#include "magnetics/dipole_field.hpp"

#include "magnetics/field_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace magsim::mag {

using detail::kInv4Pi;

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

// bounded pairs: r → r·R/|r| when |r| < R (|r| = 0 stays 0)
Vec3 bounded_separation(const Vec3& r, double R) {
  const double d = r.norm();
  return d < R && d > 0 ? Vec3(r * (R / d)) : r;
}

namespace {

// Sources per cache chunk: 8 arrays × 8 B × 4096 = 256 KB, resident in L2 while every
// target of a block sweeps it.
constexpr std::size_t kChunk = 4096;
// Targets per block (the unit of work of a thread).
constexpr long kTargetBlock = 32;

void pack_sources(const MomentDesc& set, const Magnetization& mz, detail::SourceBuffer* src) {
  src->clear();
  for (std::size_t i = 0; i < set.size(); ++i) {
    const Vec3 m = moment(set, mz, i);
    if (m.x() == 0.0 && m.y() == 0.0 && m.z() == 0.0) continue;
    const Vec3& p = set.position[i];
    src->push(p.x(), p.y(), p.z(), m.x(), m.y(), m.z(), static_cast<double>(i), set.group[i],
              set.radius[i]);
  }
  src->pad();
}

detail::Target target_of(const MomentDesc& set, std::size_t j) {
  const Vec3& p = set.position[j];
  const double g = set.group[j] >= 0 ? static_cast<double>(set.group[j])
                                     : std::numeric_limits<double>::quiet_NaN();
  return detail::Target{p.x(), p.y(), p.z(), static_cast<double>(j), g, set.radius[j]};
}

// The direct sum at targets idx[0..nt) (or 0..nt when idx is null), H0 added.
void direct_sum(const MomentDesc& set, const DirectSumOptions& opt,
                const detail::SourceBuffer& src, const int* idx, long nt, Vec3* H, Mat3* J) {
  const double eps2 = opt.softening * opt.softening;
  const std::size_t ns = src.size();
  const detail::PairTerms terms = J ? detail::PairTerms::HJ : detail::PairTerms::H;
  const long nblocks = (nt + kTargetBlock - 1) / kTargetBlock;
#pragma omp parallel for schedule(static)
  for (long b = 0; b < nblocks; ++b) {
    const long j0 = b * kTargetBlock, j1 = std::min(nt, j0 + kTargetBlock);
    double acc[kTargetBlock][9] = {};
    detail::Target tg[kTargetBlock];
    for (long j = j0; j < j1; ++j) tg[j - j0] = target_of(set, idx ? idx[j] : j);
    for (std::size_t c = 0; c < ns; c += kChunk) {
      const detail::SourceView v = detail::view_of(src, opt.bounded, c, std::min(ns, c + kChunk));
      for (long j = j0; j < j1; ++j)
        detail::sum_pairs(v, tg[j - j0], eps2, terms, acc[j - j0], acc[j - j0] + 3);
    }
    for (long j = j0; j < j1; ++j) {
      const double* h = acc[j - j0];
      H[j] = set.H0 + Vec3(h[0], h[1], h[2]);
      if (J) {
        const double* q = h + 3;
        J[j] << q[0], q[3], q[4],
                q[3], q[1], q[5],
                q[4], q[5], q[2];
      }
    }
  }
}

}  // namespace

void direct_sum_fields(const MomentDesc& set, const Magnetization& mz,
                       const DirectSumOptions& opt, const std::vector<int>* targets,
                       std::vector<Vec3>* H, std::vector<Mat3>* J, detail::SourceBuffer* src) {
  const long nt = static_cast<long>(targets ? targets->size() : set.size());
  H->resize(nt);
  if (J) J->resize(nt);
  pack_sources(set, mz, src);
  direct_sum(set, opt, *src, targets ? targets->data() : nullptr, nt, H->data(),
             J ? J->data() : nullptr);
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
