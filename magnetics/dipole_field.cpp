// magnetics/dipole_field.cpp — direct O(N·S) sum of dipole fields and Jacobians.
//
// The kernel packs the nonzero sources into flat, padded arrays once per call and sweeps
// them eight at a time with a branch-free inner loop (self and same-group terms are masked,
// not skipped). On CPUs with AVX-512 the sweep is written with intrinsics: 1/√q comes from
// the 14-bit estimate vrsqrt14pd refined by one fourth-order step (relative error ≈ 1e-16,
// no divide or square root), which is what makes the loop fast; elsewhere a portable
// `omp simd` loop computes the same sums. Targets are split across threads; sources are
// swept in cache-sized chunks so that 100k sources stream from L2, not from memory.
#include "magnetics/dipole_field.hpp"

#include "magnetics/barnes_hut.hpp"
#include "magnetics/field_kernel.hpp"

#include <atomic>
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

const char* field_solver_name(FieldSolver s) {
  switch (s) {
    case FieldSolver::Direct: return "direct";
    case FieldSolver::BarnesHut: return "barnes-hut";
    case FieldSolver::Auto: return "auto";
  }
  return "?";
}

bool parse_field_solver(const std::string& name, FieldSolver* out) {
  for (FieldSolver s : {FieldSolver::Direct, FieldSolver::BarnesHut, FieldSolver::Auto}) {
    if (name == field_solver_name(s)) {
      *out = s;
      return true;
    }
  }
  return false;
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
  return e.str();
}

bool pairs_bounded(const MomentSet& set, const FieldOptions& opt) {
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
    : sx(o.sx), sy(o.sy), sz(o.sz), smx(o.smx), smy(o.smy), smz(o.smz), sid(o.sid),
      sgrp(o.sgrp), srad(o.srad), bounded(o.bounded) {}
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

namespace {

// Portable sweep (any CPU): the same sums as the AVX-512 one, `omp simd` vectorized.
// kBound: bounded pairs (field_kernel.hpp, sum_pairs).
template <bool kJac, bool kBound>
void sum_pairs_portable(const SourceView& v, const Target& t, double eps2, double* Hout,
                        double* Jout) {
  const double* __restrict sx = v.x;
  const double* __restrict sy = v.y;
  const double* __restrict sz = v.z;
  const double* __restrict mx = v.mx;
  const double* __restrict my = v.my;
  const double* __restrict mz = v.mz;
  const double* __restrict si = v.id;
  const double* __restrict sg = v.grp;
  const double* __restrict sr = v.rad;
  const double px = t.x, py = t.y, pz = t.z, self = t.id, grp = t.grp, trad = t.rad;
  double ax = 0, ay = 0, az = 0, bx = 0, by = 0, bz = 0;
  double ja = 0, jxx = 0, jyy = 0, jzz = 0, jxy = 0, jxz = 0, jyz = 0;
#pragma omp simd reduction(+ : ax, ay, az, bx, by, bz, ja, jxx, jyy, jzz, jxy, jxz, jyz)
  for (std::size_t i = 0; i < v.n; ++i) {
    double dx = px - sx[i], dy = py - sy[i], dz = pz - sz[i];
    const bool is_self = si[i] == self;
    double r2 = dx * dx + dy * dy + dz * dz;
    if constexpr (kBound) {
      // |r| < R = a_i + a_t: evaluate at r·R/|r| (|r| = 0 keeps r = 0: then only −m/R³)
      const double R = sr[i] + trad;
      const double s = r2 < R * R ? R / std::sqrt(std::max(r2, 1e-300)) : 1.0;
      dx *= s; dy *= s; dz *= s;
      r2 = std::max(r2, R * R);
    }
    const double q = is_self ? 1.0 : r2 + eps2;
    const double inv = is_self ? 0.0 : 1.0 / std::sqrt(q);
    const double inv2 = inv * inv;
    const double inv3 = inv2 * inv;
    const double inv5 = inv3 * inv2;
    const double rm = dx * mx[i] + dy * my[i] + dz * mz[i];
    // eq. 1, accumulated as Σ (r·m) r / q^{5/2} and Σ m / q^{3/2}
    const double a = rm * inv5;
    ax += a * dx; ay += a * dy; az += a * dz;
    bx += inv3 * mx[i]; by += inv3 * my[i]; bz += inv3 * mz[i];
    if constexpr (kJac) {
      // J/3 = u (rm I + r mᵀ + m rᵀ) − 5 rm u/q r rᵀ, u = q^{-5/2} (0 within the group)
      const double u = sg[i] == grp ? 0.0 : inv5;
      const double aj = rm * u;
      const double t5 = 5.0 * aj * inv2;
      const double gx = u * mx[i], gy = u * my[i], gz = u * mz[i];
      const double kx = gx - t5 * dx, ky = gy - t5 * dy, kz = gz - t5 * dz;
      ja += aj;
      jxx += dx * (gx + kx); jyy += dy * (gy + ky); jzz += dz * (gz + kz);
      jxy += dx * gy + dy * kx; jxz += dx * gz + dz * kx; jyz += dy * gz + dz * ky;
    }
  }
  Hout[0] += (3.0 * ax - bx) * kInv4Pi;
  Hout[1] += (3.0 * ay - by) * kInv4Pi;
  Hout[2] += (3.0 * az - bz) * kInv4Pi;
  if constexpr (kJac) {
    const double s = 3.0 * kInv4Pi;
    Jout[0] += (ja + jxx) * s; Jout[1] += (ja + jyy) * s; Jout[2] += (ja + jzz) * s;
    Jout[3] += jxy * s; Jout[4] += jxz * s; Jout[5] += jyz * s;
  }
}

#ifdef MAGSIM_AVX512_KERNEL

// 1/√q in the lanes of `keep` (0 elsewhere): y0 = vrsqrt14pd(q) (|rel. error| ≤ 2⁻¹⁴),
// e = 1 − q y0², y = y0 (1 + e/2 + 3e²/8 + 5e³/16); the series of (1 − e)^{-1/2} cut after
// e³ leaves (35/128) e⁴ < 1e-16. (The masked form also avoids GCC 12's false
// -Wuninitialized inside the unmasked intrinsic.)
MAGSIM_TARGET_AVX512 inline __m512d rsqrt_pd(__mmask8 keep, __m512d q) {
  const __m512d y = _mm512_maskz_rsqrt14_pd(keep, q);
  const __m512d e = _mm512_fnmadd_pd(q, _mm512_mul_pd(y, y), _mm512_set1_pd(1.0));
  __m512d p = _mm512_fmadd_pd(_mm512_set1_pd(5.0 / 16.0), e, _mm512_set1_pd(3.0 / 8.0));
  p = _mm512_fmadd_pd(p, e, _mm512_set1_pd(0.5));
  return _mm512_fmadd_pd(_mm512_mul_pd(y, e), p, y);
}

// Horizontal sum of the eight lanes in a fixed order (deterministic).
MAGSIM_TARGET_AVX512 inline double hsum(__m512d v) {
  alignas(64) double t[8];
  _mm512_store_pd(t, v);
  return ((t[0] + t[4]) + (t[1] + t[5])) + ((t[2] + t[6]) + (t[3] + t[7]));
}

// The sweep over eight sources at a time; the same algebra as sum_pairs_portable.
template <bool kJac, bool kBound>
MAGSIM_TARGET_AVX512 void sum_pairs_avx512(const SourceView& v, const Target& t, double eps2,
                                           double* Hout, double* Jout) {
  const __m512d px = _mm512_set1_pd(t.x), py = _mm512_set1_pd(t.y), pz = _mm512_set1_pd(t.z);
  const __m512d self = _mm512_set1_pd(t.id), grp = _mm512_set1_pd(t.grp);
  const __m512d e2 = _mm512_set1_pd(eps2);
  const __m512d five = _mm512_set1_pd(5.0);
  const __m512d trad = _mm512_set1_pd(t.rad);
  __m512d ax = _mm512_setzero_pd(), ay = ax, az = ax, bx = ax, by = ax, bz = ax;
  __m512d ja = ax, jxx = ax, jyy = ax, jzz = ax, jxy = ax, jxz = ax, jyz = ax;
  for (std::size_t i = 0; i < v.n; i += 8) {
    __m512d dx = _mm512_sub_pd(px, _mm512_loadu_pd(v.x + i));
    __m512d dy = _mm512_sub_pd(py, _mm512_loadu_pd(v.y + i));
    __m512d dz = _mm512_sub_pd(pz, _mm512_loadu_pd(v.z + i));
    const __m512d mx = _mm512_loadu_pd(v.mx + i);
    const __m512d my = _mm512_loadu_pd(v.my + i);
    const __m512d mz = _mm512_loadu_pd(v.mz + i);
    const __mmask8 other = _mm512_cmp_pd_mask(_mm512_loadu_pd(v.id + i), self, _CMP_NEQ_UQ);
    __m512d q;
    if constexpr (kBound) {
      // |r| < R = a_i + a_t: evaluate at r·R/|r| (rare: only touching pairs take the branch)
      const __m512d R = _mm512_add_pd(_mm512_loadu_pd(v.rad + i), trad);
      const __m512d R2 = _mm512_mul_pd(R, R);
      __m512d r2 = _mm512_mul_pd(dx, dx);
      r2 = _mm512_fmadd_pd(dy, dy, r2);
      r2 = _mm512_fmadd_pd(dz, dz, r2);
      const __mmask8 in = _mm512_cmp_pd_mask(r2, R2, _CMP_LT_OQ) & other;
      if (in) {
        const __m512d d = _mm512_maskz_sqrt_pd(in, _mm512_maskz_max_pd(0xff, r2, _mm512_set1_pd(1e-300)));
        const __m512d s = _mm512_maskz_div_pd(in, R, d);
        dx = _mm512_mask_mul_pd(dx, in, dx, s);
        dy = _mm512_mask_mul_pd(dy, in, dy, s);
        dz = _mm512_mask_mul_pd(dz, in, dz, s);
      }
      q = _mm512_add_pd(_mm512_maskz_max_pd(0xff, r2, R2), e2);
    } else {
      q = _mm512_fmadd_pd(dx, dx, e2);
      q = _mm512_fmadd_pd(dy, dy, q);
      q = _mm512_fmadd_pd(dz, dz, q);
    }
    const __m512d inv = rsqrt_pd(other, q);
    const __m512d inv2 = _mm512_mul_pd(inv, inv);
    const __m512d inv3 = _mm512_mul_pd(inv2, inv);
    const __m512d inv5 = _mm512_mul_pd(inv3, inv2);
    __m512d rm = _mm512_mul_pd(dx, mx);
    rm = _mm512_fmadd_pd(dy, my, rm);
    rm = _mm512_fmadd_pd(dz, mz, rm);
    // eq. 1
    const __m512d a = _mm512_mul_pd(rm, inv5);
    ax = _mm512_fmadd_pd(a, dx, ax);
    ay = _mm512_fmadd_pd(a, dy, ay);
    az = _mm512_fmadd_pd(a, dz, az);
    bx = _mm512_fmadd_pd(inv3, mx, bx);
    by = _mm512_fmadd_pd(inv3, my, by);
    bz = _mm512_fmadd_pd(inv3, mz, bz);
    if constexpr (kJac) {
      // Jacobian of eq. 1 (see dipole_jacobian), same-group sources masked
      const __mmask8 ext = _mm512_cmp_pd_mask(_mm512_loadu_pd(v.grp + i), grp, _CMP_NEQ_UQ);
      const __m512d u = _mm512_maskz_mov_pd(ext, inv5);
      const __m512d aj = _mm512_mul_pd(rm, u);
      const __m512d t5 = _mm512_mul_pd(aj, _mm512_mul_pd(inv2, five));
      const __m512d gx = _mm512_mul_pd(u, mx);
      const __m512d gy = _mm512_mul_pd(u, my);
      const __m512d gz = _mm512_mul_pd(u, mz);
      const __m512d kx = _mm512_fnmadd_pd(t5, dx, gx);
      const __m512d ky = _mm512_fnmadd_pd(t5, dy, gy);
      const __m512d kz = _mm512_fnmadd_pd(t5, dz, gz);
      ja = _mm512_add_pd(ja, aj);
      jxx = _mm512_fmadd_pd(dx, _mm512_add_pd(gx, kx), jxx);
      jyy = _mm512_fmadd_pd(dy, _mm512_add_pd(gy, ky), jyy);
      jzz = _mm512_fmadd_pd(dz, _mm512_add_pd(gz, kz), jzz);
      jxy = _mm512_fmadd_pd(dy, kx, _mm512_fmadd_pd(dx, gy, jxy));
      jxz = _mm512_fmadd_pd(dz, kx, _mm512_fmadd_pd(dx, gz, jxz));
      jyz = _mm512_fmadd_pd(dz, ky, _mm512_fmadd_pd(dy, gz, jyz));
    }
  }
  Hout[0] += (3.0 * hsum(ax) - hsum(bx)) * kInv4Pi;
  Hout[1] += (3.0 * hsum(ay) - hsum(by)) * kInv4Pi;
  Hout[2] += (3.0 * hsum(az) - hsum(bz)) * kInv4Pi;
  if constexpr (kJac) {
    const double s = 3.0 * kInv4Pi;
    const double a = hsum(ja);
    Jout[0] += (a + hsum(jxx)) * s; Jout[1] += (a + hsum(jyy)) * s;
    Jout[2] += (a + hsum(jzz)) * s;
    Jout[3] += hsum(jxy) * s; Jout[4] += hsum(jxz) * s; Jout[5] += hsum(jyz) * s;
  }
}

bool cpu_has_avx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}

#endif  // MAGSIM_AVX512_KERNEL

}  // namespace

namespace {
std::atomic<bool> g_simd_enabled{true};
}

void enable_simd_kernel(bool on) { g_simd_enabled = on; }

bool simd_kernel_active() {
#ifdef MAGSIM_AVX512_KERNEL
  return cpu_has_avx512() && g_simd_enabled.load(std::memory_order_relaxed);
#else
  return false;
#endif
}

void sum_pairs(const SourceView& v, const Target& t, double eps2, PairTerms terms, double* H,
               double* J) {
#ifdef MAGSIM_AVX512_KERNEL
  const bool bound = v.rad != nullptr;
  if (simd_kernel_active()) {
    if (terms == PairTerms::HJ) {
      if (bound) sum_pairs_avx512<true, true>(v, t, eps2, H, J);
      else sum_pairs_avx512<true, false>(v, t, eps2, H, J);
    } else {
      if (bound) sum_pairs_avx512<false, true>(v, t, eps2, H, J);
      else sum_pairs_avx512<false, false>(v, t, eps2, H, J);
    }
    return;
  }
#else
  const bool bound = v.rad != nullptr;
#endif
  if (terms == PairTerms::HJ) {
    if (bound) sum_pairs_portable<true, true>(v, t, eps2, H, J);
    else sum_pairs_portable<true, false>(v, t, eps2, H, J);
  } else {
    if (bound) sum_pairs_portable<false, true>(v, t, eps2, H, J);
    else sum_pairs_portable<false, false>(v, t, eps2, H, J);
  }
}

}  // namespace detail

namespace {

// Sources per cache chunk: 8 arrays × 8 B × 4096 = 256 KB, resident in L2 while every
// target of a block sweeps it.
constexpr std::size_t kChunk = 4096;
// Targets per block (the unit of work of a thread).
constexpr long kTargetBlock = 32;

void pack_sources(const MomentSet& set, const FieldOptions& opt, FieldWorkspace* ws) {
  std::vector<double>* a[] = {&ws->sx, &ws->sy, &ws->sz, &ws->smx, &ws->smy, &ws->smz,
                              &ws->sid, &ws->sgrp, &ws->srad};
  for (auto* v : a) v->clear();
  auto push = [&](const Vec3& p, const Vec3& m, double id, double grp, double rad) {
    ws->sx.push_back(p.x()); ws->sy.push_back(p.y()); ws->sz.push_back(p.z());
    ws->smx.push_back(m.x()); ws->smy.push_back(m.y()); ws->smz.push_back(m.z());
    ws->sid.push_back(id); ws->sgrp.push_back(grp < 0 ? -1.0 : grp);
    ws->srad.push_back(rad);
  };
  for (std::size_t i = 0; i < set.size(); ++i) {
    const Vec3 m = set.moment(i);
    if (m.x() == 0.0 && m.y() == 0.0 && m.z() == 0.0) continue;
    push(set.position[i], m, static_cast<double>(i), set.group[i], set.radius[i]);
  }
  const Vec3 far = Vec3::Constant(detail::kPadPosition);
  while (ws->sx.size() % detail::kSourcePad != 0) push(far, Vec3::Zero(), -1.0, -1.0, 0.0);
  ws->bounded = pairs_bounded(set, opt);
}

detail::SourceView packed_view(const FieldWorkspace& ws, std::size_t b, std::size_t e) {
  return detail::SourceView{ws.sx.data() + b,  ws.sy.data() + b,  ws.sz.data() + b,
                            ws.smx.data() + b, ws.smy.data() + b, ws.smz.data() + b,
                            ws.sid.data() + b, ws.sgrp.data() + b, e - b,
                            ws.bounded ? ws.srad.data() + b : nullptr};
}

detail::Target target_of(const MomentSet& set, std::size_t j) {
  const Vec3& p = set.position[j];
  const double g = set.group[j] >= 0 ? static_cast<double>(set.group[j])
                                     : std::numeric_limits<double>::quiet_NaN();
  return detail::Target{p.x(), p.y(), p.z(), static_cast<double>(j), g, set.radius[j]};
}

// The direct sum at targets idx[0..nt) (or 0..nt when idx is null), H0 added.
void direct_sum(const MomentSet& set, const FieldOptions& opt, const FieldWorkspace& ws,
                const int* idx, long nt, Vec3* H, Mat3* J) {
  const double eps2 = opt.softening * opt.softening;
  const std::size_t ns = ws.sx.size();
  const detail::PairTerms terms = J ? detail::PairTerms::HJ : detail::PairTerms::H;
  const long nblocks = (nt + kTargetBlock - 1) / kTargetBlock;
#pragma omp parallel for schedule(static)
  for (long b = 0; b < nblocks; ++b) {
    const long j0 = b * kTargetBlock, j1 = std::min(nt, j0 + kTargetBlock);
    double acc[kTargetBlock][9] = {};
    detail::Target tg[kTargetBlock];
    for (long j = j0; j < j1; ++j) tg[j - j0] = target_of(set, idx ? idx[j] : j);
    for (std::size_t c = 0; c < ns; c += kChunk) {
      const detail::SourceView v = packed_view(ws, c, std::min(ns, c + kChunk));
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

void compute_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                    std::vector<Mat3>* J, FieldWorkspace* ws) {
  const long n = static_cast<long>(set.size());
  H->resize(n);
  if (J) J->resize(n);
  if (resolve_solver(opt, set.size()) == FieldSolver::BarnesHut) {
    if (!ws->bh) ws->bh.reset(new_barnes_hut_workspace());
    barnes_hut_fields(set, opt, H, J, ws->bh.get());
    return;
  }
  pack_sources(set, opt, ws);
  direct_sum(set, opt, *ws, nullptr, n, H->data(), J ? J->data() : nullptr);
}

void compute_fields_at(const MomentSet& set, const FieldOptions& opt,
                       const std::vector<int>& targets, std::vector<Vec3>* H,
                       std::vector<Mat3>* J, FieldWorkspace* ws) {
  const long nt = static_cast<long>(targets.size());
  H->resize(nt);
  if (J) J->resize(nt);
  pack_sources(set, opt, ws);
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
