// magnetics/dipole_field.cpp — direct O(N·S) sum of dipole fields and Jacobians.
//
// The nonzero sources are packed into flat, padded arrays once per call and swept by the
// pair kernel (pair_kernel.cpp: AVX-512 where the CPU has it, else a portable loop).
// Targets are split across threads; sources are swept in cache-sized chunks so that 100k
// sources stream from L2, not from memory.
#include "magnetics/dipole_field.hpp"

#include "magnetics/barnes_hut.hpp"
#include "magnetics/field_kernel.hpp"

#include <cmath>
#include <limits>
#include <sstream>

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

std::string validate(const FieldOptions& o) {
  std::ostringstream e;
  if (!(o.softening >= 0 && std::isfinite(o.softening)))
    e << "softening must be >= 0, got " << o.softening;
  else if (!(o.bh_theta >= 0 && o.bh_theta <= 1))
    e << "bh_theta must be in [0, 1], got " << o.bh_theta;
  else if (o.auto_threshold < 0) e << "auto_threshold must be >= 0, got " << o.auto_threshold;
  else if (o.bh_leaf_size < 1) e << "bh_leaf_size must be >= 1, got " << o.bh_leaf_size;
  else if (o.bh_group_size < 1) e << "bh_group_size must be >= 1, got " << o.bh_group_size;
  else if (o.bh_order < 1 || o.bh_order > 2) e << "bh_order must be 1 or 2, got " << o.bh_order;
  else return validate(o.near_field);
  return e.str();
}

bool pairs_bounded(const MomentDesc& set, const FieldOptions& opt) {
  if (!opt.bounded_pairs) return false;
  for (double a : set.radius)
    if (a > 0) return true;
  return false;
}

FieldSolver resolve_solver(const FieldOptions& opt, std::size_t n) {
  if (opt.solver != FieldSolver::Auto) return opt.solver;
  return n >= static_cast<std::size_t>(opt.auto_threshold) ? FieldSolver::BarnesHut
                                                            : FieldSolver::Direct;
}

// scratch: a copy starts with the packed arrays but builds its own tree
FieldWorkspace::FieldWorkspace(const FieldWorkspace& o)
    : src(o.src), bounded(o.bounded), near(o.near) {}
FieldWorkspace& FieldWorkspace::operator=(const FieldWorkspace& o) {
  if (this != &o) {
    FieldWorkspace t(o);
    *this = std::move(t);
  }
  return *this;
}

namespace detail {

void SourceBuffer::clear() {
  x.clear(); y.clear(); z.clear(); mx.clear(); my.clear(); mz.clear(); id.clear(); grp.clear();
  rad.clear();
}

void SourceBuffer::push(double px, double py, double pz, double qx, double qy, double qz,
                        double index, double group, double radius) {
  x.push_back(px); y.push_back(py); z.push_back(pz);
  mx.push_back(qx); my.push_back(qy); mz.push_back(qz);
  id.push_back(index); grp.push_back(group < 0 ? -1.0 : group);
  rad.push_back(radius);
}

void SourceBuffer::append(const SourceBuffer& s, std::size_t b, std::size_t e) {
  std::vector<double>* to[9] = {&x, &y, &z, &mx, &my, &mz, &id, &grp, &rad};
  const std::vector<double>* from[9] = {&s.x, &s.y, &s.z, &s.mx, &s.my, &s.mz, &s.id, &s.grp, &s.rad};
  for (int k = 0; k < 9; ++k) to[k]->insert(to[k]->end(), from[k]->begin() + b, from[k]->begin() + e);
}

void SourceBuffer::pad() {
  while (size() % kSourcePad != 0)
    push(kPadPosition, kPadPosition, kPadPosition, 0.0, 0.0, 0.0, -1.0, -1.0, 0.0);
}

}  // namespace detail

namespace {

// Sources per cache chunk: 8 arrays × 8 B × 4096 = 256 KB, resident in L2 while every
// target of a block sweeps it.
constexpr std::size_t kChunk = 4096;
// Targets per block (the unit of work of a thread).
constexpr long kTargetBlock = 32;

void pack_sources(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                  FieldWorkspace* ws) {
  ws->src.clear();
  for (std::size_t i = 0; i < set.size(); ++i) {
    const Vec3 m = moment(set, mz, i);
    if (m.x() == 0.0 && m.y() == 0.0 && m.z() == 0.0) continue;
    const Vec3& p = set.position[i];
    ws->src.push(p.x(), p.y(), p.z(), m.x(), m.y(), m.z(), static_cast<double>(i), set.group[i],
                 set.radius[i]);
  }
  ws->src.pad();
  ws->bounded = pairs_bounded(set, opt);
}

detail::Target target_of(const MomentDesc& set, std::size_t j) {
  const Vec3& p = set.position[j];
  const double g = set.group[j] >= 0 ? static_cast<double>(set.group[j])
                                     : std::numeric_limits<double>::quiet_NaN();
  return detail::Target{p.x(), p.y(), p.z(), static_cast<double>(j), g, set.radius[j]};
}

// The direct sum at targets idx[0..nt) (or 0..nt when idx is null), H0 added.
void direct_sum(const MomentDesc& set, const FieldOptions& opt, const FieldWorkspace& ws,
                const int* idx, long nt, Vec3* H, Mat3* J) {
  const double eps2 = opt.softening * opt.softening;
  const std::size_t ns = ws.src.size();
  const detail::PairTerms terms = J ? detail::PairTerms::HJ : detail::PairTerms::H;
  const long nblocks = (nt + kTargetBlock - 1) / kTargetBlock;
#pragma omp parallel for schedule(static)
  for (long b = 0; b < nblocks; ++b) {
    const long j0 = b * kTargetBlock, j1 = std::min(nt, j0 + kTargetBlock);
    double acc[kTargetBlock][9] = {};
    detail::Target tg[kTargetBlock];
    for (long j = j0; j < j1; ++j) tg[j - j0] = target_of(set, idx ? idx[j] : j);
    for (std::size_t c = 0; c < ns; c += kChunk) {
      const detail::SourceView v = detail::view_of(ws.src, ws.bounded, c, std::min(ns, c + kChunk));
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

void compute_fields(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                    std::vector<Vec3>* H, std::vector<Mat3>* J, FieldWorkspace* ws) {
  const long n = static_cast<long>(set.size());
  H->resize(n);
  if (J) J->resize(n);
  if (resolve_solver(opt, set.size()) == FieldSolver::BarnesHut) {
    if (!ws->bh) ws->bh.reset(new_barnes_hut_workspace());
    barnes_hut_fields(set, mz, opt, H, J, ws->bh.get());
  } else {
    pack_sources(set, mz, opt, ws);
    direct_sum(set, opt, *ws, nullptr, n, H->data(), J ? J->data() : nullptr);
  }
  // the pair model's field on touching spheres (near_field.hpp; J stays the dipoles': the
  // model's forces are added by compute_forces)
  add_near_field(set, mz, opt.near_field, &ws->near, H);
}

void compute_fields_at(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                       const std::vector<int>& targets, std::vector<Vec3>* H,
                       std::vector<Mat3>* J, FieldWorkspace* ws) {
  const long nt = static_cast<long>(targets.size());
  H->resize(nt);
  if (J) J->resize(nt);
  pack_sources(set, mz, opt, ws);
  direct_sum(set, opt, *ws, targets.data(), nt, H->data(), J ? J->data() : nullptr);
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
