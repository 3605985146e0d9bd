// magnetics/simd.hpp — internal: the lane operations of the field kernels, in two sets that
// give the same bits: portable lanes (Lanes<T, W>, plain loops that any compiler vectorizes
// at any width) and AVX-512 registers (__m512d, __m512). A kernel body is written once over
// these names (pair_sweep.inc, far_block.inc) and compiled for both sets, so its result does
// not depend on the CPU. Every operation is element-wise IEEE (+, −, ×, ÷, √, max, compare,
// select), FMA is never used ("mul_add" rounds twice), sums across lanes follow one tree
// (hsum), and 1/√q is computed the same way on both (inv_sqrt). Double kernels run 8 lanes,
// float kernels 16, whatever the hardware width. Include only from magnetics/*.cpp, after
// field_kernel.hpp.
#pragma once

#include "magnetics/field_kernel.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace magsim::mag::detail::simd {

// ---- portable lanes ---------------------------------------------------------------------

/// W lanes of T; masks are bit sets (lane k ↔ bit k)
template <class T, int W>
struct Lanes {
  T v[W];
};
using PD = Lanes<double, 8>;
using PF = Lanes<float, 16>;
using PMask = std::uint32_t;

#define MAGSIM_LANES template <class T, int W> inline
MAGSIM_LANES Lanes<T, W> ld_lanes(const T* p) {
  Lanes<T, W> r;
  for (int k = 0; k < W; ++k) r.v[k] = p[k];
  return r;
}
/// loads W lanes from p; the second argument (its value unused) picks the lane set
inline PD ld(const double* p, PD) { return ld_lanes<double, 8>(p); }
inline PF ld(const float* p, PF) { return ld_lanes<float, 16>(p); }
MAGSIM_LANES Lanes<T, W> add(Lanes<T, W> a, Lanes<T, W> b) {
  for (int k = 0; k < W; ++k) a.v[k] = a.v[k] + b.v[k];
  return a;
}
MAGSIM_LANES Lanes<T, W> sub(Lanes<T, W> a, Lanes<T, W> b) {
  for (int k = 0; k < W; ++k) a.v[k] = a.v[k] - b.v[k];
  return a;
}
MAGSIM_LANES Lanes<T, W> mul(Lanes<T, W> a, Lanes<T, W> b) {
  for (int k = 0; k < W; ++k) a.v[k] = a.v[k] * b.v[k];
  return a;
}
/// max(a, b) as the x86 instruction has it: b where either is NaN or both are zeros
MAGSIM_LANES Lanes<T, W> max(Lanes<T, W> a, Lanes<T, W> b) {
  for (int k = 0; k < W; ++k) a.v[k] = a.v[k] > b.v[k] ? a.v[k] : b.v[k];
  return a;
}
/// a in the lanes of m, 0 elsewhere
MAGSIM_LANES Lanes<T, W> keep(PMask m, Lanes<T, W> a) {
  for (int k = 0; k < W; ++k) a.v[k] = (m >> k) & 1u ? a.v[k] : T(0);
  return a;
}
/// lanes where a < b (false for NaN)
MAGSIM_LANES PMask less(Lanes<T, W> a, Lanes<T, W> b) {
  PMask m = 0;
  for (int k = 0; k < W; ++k) m |= static_cast<PMask>(a.v[k] < b.v[k]) << k;
  return m;
}
/// √a in the lanes of m, 0 elsewhere
MAGSIM_LANES Lanes<T, W> sqrt(PMask m, Lanes<T, W> a) {
  for (int k = 0; k < W; ++k) a.v[k] = (m >> k) & 1u ? std::sqrt(a.v[k]) : T(0);
  return a;
}
/// a/b in the lanes of m, 0 elsewhere
MAGSIM_LANES Lanes<T, W> div(PMask m, Lanes<T, W> a, Lanes<T, W> b) {
  for (int k = 0; k < W; ++k) a.v[k] = (m >> k) & 1u ? a.v[k] / b.v[k] : T(0);
  return a;
}
/// a·b in the lanes of m, a elsewhere
MAGSIM_LANES Lanes<T, W> mul_in(PMask m, Lanes<T, W> a, Lanes<T, W> b) {
  for (int k = 0; k < W; ++k) a.v[k] = (m >> k) & 1u ? a.v[k] * b.v[k] : a.v[k];
  return a;
}
MAGSIM_LANES Lanes<T, W> splat(Lanes<T, W>, double x) {
  Lanes<T, W> r;
  for (int k = 0; k < W; ++k) r.v[k] = static_cast<T>(x);
  return r;
}
/// the first n lanes (n ≤ W)
MAGSIM_LANES PMask first_lanes(Lanes<T, W>, std::size_t n) {
  return static_cast<PMask>((1ull << n) - 1ull);
}
/// a·b + c, rounded twice (never fused: the same on every CPU)
MAGSIM_LANES Lanes<T, W> mul_add(Lanes<T, W> a, Lanes<T, W> b, Lanes<T, W> c) {
  return add(mul(a, b), c);
}
/// c − a·b, rounded twice
MAGSIM_LANES Lanes<T, W> neg_mul_add(Lanes<T, W> a, Lanes<T, W> b, Lanes<T, W> c) {
  return sub(c, mul(a, b));
}
/// a·x + b·y + c·z, left to right
MAGSIM_LANES Lanes<T, W> dot3(Lanes<T, W> a, Lanes<T, W> b, Lanes<T, W> c, Lanes<T, W> x,
                              Lanes<T, W> y, Lanes<T, W> z) {
  return add(add(mul(a, x), mul(b, y)), mul(c, z));
}
#undef MAGSIM_LANES

/// A constant in every lane of V (cst<PD>(x), cst<V8>(x), …)
template <class V>
inline V cst(double x) {
  return splat(V(), x);
}

/// 1/√q in the lanes of m, 0 elsewhere; see inv_sqrt for __m512d
inline PD inv_sqrt(PMask m, PD q) {
  PD y;
  for (int k = 0; k < 8; ++k) {
    const float qf = static_cast<float>(q.v[k]);
    double r = static_cast<double>(1.0f / std::sqrt(qf));
    const double h = 0.5 * q.v[k];
    for (int it = 0; it < 2; ++it) r = r * (1.5 - h * (r * r));
    y.v[k] = (m >> k) & 1u ? r : 0.0;
  }
  return y;
}
inline PF inv_sqrt(PMask m, PF q) {
  for (int k = 0; k < 16; ++k) q.v[k] = (m >> k) & 1u ? 1.0f / std::sqrt(q.v[k]) : 0.0f;
  return q;
}

/// Lanes whose ids differ from `self` (ids as doubles, NaN never equal; or as int32)
inline PMask differ_lanes(const double* ids, double self, PD) {
  PMask m = 0;
  for (int k = 0; k < 8; ++k) m |= static_cast<PMask>(!(ids[k] == self)) << k;
  return m;
}
inline PMask differ_lanes(const std::int32_t* ids, std::int32_t self, PF) {
  PMask m = 0;
  for (int k = 0; k < 16; ++k) m |= static_cast<PMask>(ids[k] != self) << k;
  return m;
}

/// acc + v lane by lane (double); 16 float lanes: lane k of acc gets float lanes k and k + 8,
/// widened exactly, as acc_k + (v_k + v_{k+8})
inline PD fold(PD acc, PD v) { return add(acc, v); }
inline PD fold(PD acc, PF v) {
  for (int k = 0; k < 8; ++k)
    acc.v[k] = acc.v[k] + (static_cast<double>(v.v[k]) + static_cast<double>(v.v[k + 8]));
  return acc;
}
/// the eight lanes summed in one fixed tree
inline double hsum(PD v) {
  const double* t = v.v;
  return ((t[0] + t[4]) + (t[1] + t[5])) + ((t[2] + t[6]) + (t[3] + t[7]));
}

}  // namespace magsim::mag::detail::simd

#ifdef MAGSIM_AVX512_KERNEL

#pragma GCC push_options
#pragma GCC target("avx512f")

namespace magsim::mag::detail::simd {

// ---- AVX-512 registers: the same operations, the same bits ------------------------------
// (masked forms where GCC 12 warns falsely, -Wmaybe-uninitialized, inside the unmasked ones)

using V8 = __m512d;
using V16 = __m512;

// clang-format off
inline V8 ld(const double* p, V8) { return _mm512_loadu_pd(p); }
inline V16 ld(const float* p, V16) { return _mm512_loadu_ps(p); }
inline V8 add(V8 a, V8 b) { return _mm512_add_pd(a, b); }
inline V16 add(V16 a, V16 b) { return _mm512_add_ps(a, b); }
inline V8 sub(V8 a, V8 b) { return _mm512_sub_pd(a, b); }
inline V16 sub(V16 a, V16 b) { return _mm512_sub_ps(a, b); }
inline V8 mul(V8 a, V8 b) { return _mm512_mul_pd(a, b); }
inline V16 mul(V16 a, V16 b) { return _mm512_mul_ps(a, b); }
inline V8 keep(__mmask8 k, V8 a) { return _mm512_maskz_mov_pd(k, a); }
inline V16 keep(__mmask16 k, V16 a) { return _mm512_maskz_mov_ps(k, a); }
inline __mmask8 less(V8 a, V8 b) { return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ); }
inline __mmask16 less(V16 a, V16 b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
inline V8 max(V8 a, V8 b) { return _mm512_maskz_max_pd(0xff, a, b); }
inline V16 max(V16 a, V16 b) { return _mm512_maskz_max_ps(0xffff, a, b); }
inline V8 sqrt(__mmask8 k, V8 a) { return _mm512_maskz_sqrt_pd(k, a); }
inline V16 sqrt(__mmask16 k, V16 a) { return _mm512_maskz_sqrt_ps(k, a); }
inline V8 div(__mmask8 k, V8 a, V8 b) { return _mm512_maskz_div_pd(k, a, b); }
inline V16 div(__mmask16 k, V16 a, V16 b) { return _mm512_maskz_div_ps(k, a, b); }
inline V8 mul_in(__mmask8 k, V8 a, V8 b) { return _mm512_mask_mul_pd(a, k, a, b); }
inline V16 mul_in(__mmask16 k, V16 a, V16 b) { return _mm512_mask_mul_ps(a, k, a, b); }
inline V8 splat(V8, double x) { return _mm512_set1_pd(x); }
inline V16 splat(V16, double x) { return _mm512_set1_ps(static_cast<float>(x)); }
inline __mmask8 first_lanes(V8, std::size_t n) { return static_cast<__mmask8>((1u << n) - 1u); }
inline __mmask16 first_lanes(V16, std::size_t n) { return static_cast<__mmask16>((1u << n) - 1u); }
// clang-format on

template <>
inline V8 cst<V8>(double x) { return _mm512_set1_pd(x); }
template <>
inline V16 cst<V16>(double x) { return _mm512_set1_ps(static_cast<float>(x)); }
// mul_add, neg_mul_add, dot3 as for the portable lanes (never fused)
#define MAGSIM_AVX_HELPERS(V)                                                       \
  inline V mul_add(V a, V b, V c) { return add(mul(a, b), c); }                     \
  inline V neg_mul_add(V a, V b, V c) { return sub(c, mul(a, b)); }                 \
  inline V dot3(V a, V b, V c, V x, V y, V z) { return add(add(mul(a, x), mul(b, y)), mul(c, z)); }
MAGSIM_AVX_HELPERS(V8)
MAGSIM_AVX_HELPERS(V16)
#undef MAGSIM_AVX_HELPERS

/// 1/√q in the lanes of k (0 elsewhere), the same bits as the portable lanes: a float start
/// 1/√(float q) (correctly rounded steps: relative error < 1e-7), then two Newton steps in
/// double, y ← y (3/2 − (q/2) y²), each squaring the error (< 1e-28 after the second), so
/// that the result is within a few ulp of 1/√q. (q must lie in float's normal range, as
/// every separation the kernels see does: 1e-19 … 1e19 m².)
inline V8 inv_sqrt(__mmask8 k, V8 q) {
  const __m256 qf = _mm512_maskz_cvtpd_ps(0xff, q);
  const __m256 yf = _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_sqrt_ps(qf));
  V8 y = _mm512_maskz_cvtps_pd(0xff, yf);
  const V8 h = mul(_mm512_set1_pd(0.5), q), c = _mm512_set1_pd(1.5);
  for (int it = 0; it < 2; ++it) y = mul(y, sub(c, mul(h, mul(y, y))));
  return keep(k, y);
}
/// 1/√q in float, correctly rounded steps (√ then ÷) in the lanes of k, 0 elsewhere
inline V16 inv_sqrt(__mmask16 k, V16 q) {
  return _mm512_maskz_div_ps(k, _mm512_set1_ps(1.0f), _mm512_maskz_sqrt_ps(k, q));
}

inline __mmask8 differ_lanes(const double* ids, double self, V8) {
  return _mm512_cmp_pd_mask(_mm512_loadu_pd(ids), _mm512_set1_pd(self), _CMP_NEQ_UQ);
}
inline __mmask16 differ_lanes(const std::int32_t* ids, std::int32_t self, V16) {
  return _mm512_cmpneq_epi32_mask(_mm512_loadu_si512(ids), _mm512_set1_epi32(self));
}

inline V8 fold(V8 acc, V8 v) { return add(acc, v); }
inline V8 fold(V8 acc, V16 v) {
  const __m512d vd = _mm512_castps_pd(v);
  const __m256 l = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 0));
  const __m256 h = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 1));
  return add(acc, add(_mm512_maskz_cvtps_pd(0xff, l), _mm512_maskz_cvtps_pd(0xff, h)));
}
inline double hsum(V8 v) {
  alignas(64) double t[8];
  _mm512_store_pd(t, v);
  return ((t[0] + t[4]) + (t[1] + t[5])) + ((t[2] + t[6]) + (t[3] + t[7]));
}

}  // namespace magsim::mag::detail::simd

#pragma GCC pop_options

#endif  // MAGSIM_AVX512_KERNEL
