// magnetics/simd.hpp — internal: one small set of AVX-512 operations on 8 doubles (V8) and
// 16 floats (V16), so that each kernel (the pair sweep, the far-cell series) is written once
// and instantiated per precision. Overloads pick the lane type from the arguments; a
// constant is cst<V>(x); loads pick it from the pointer (ld(const double*) → V8,
// ld(const float*) → V16). Include only from magnetics/*.cpp, after field_kernel.hpp.
#pragma once

#include "magnetics/field_kernel.hpp"

#ifdef MAGSIM_AVX512_KERNEL

#include <cstddef>
#include <cstdint>

namespace magsim::mag::detail::simd {

using V8 = __m512d;
using V16 = __m512;

// clang-format off
MAGSIM_TARGET_AVX512 inline V8 ld(const double* p) { return _mm512_loadu_pd(p); }
MAGSIM_TARGET_AVX512 inline V16 ld(const float* p) { return _mm512_loadu_ps(p); }
MAGSIM_TARGET_AVX512 inline V8 add(V8 a, V8 b) { return _mm512_add_pd(a, b); }
MAGSIM_TARGET_AVX512 inline V16 add(V16 a, V16 b) { return _mm512_add_ps(a, b); }
MAGSIM_TARGET_AVX512 inline V8 sub(V8 a, V8 b) { return _mm512_sub_pd(a, b); }
MAGSIM_TARGET_AVX512 inline V16 sub(V16 a, V16 b) { return _mm512_sub_ps(a, b); }
MAGSIM_TARGET_AVX512 inline V8 mul(V8 a, V8 b) { return _mm512_mul_pd(a, b); }
MAGSIM_TARGET_AVX512 inline V16 mul(V16 a, V16 b) { return _mm512_mul_ps(a, b); }
/// a·b + c
MAGSIM_TARGET_AVX512 inline V8 fma(V8 a, V8 b, V8 c) { return _mm512_fmadd_pd(a, b, c); }
MAGSIM_TARGET_AVX512 inline V16 fma(V16 a, V16 b, V16 c) { return _mm512_fmadd_ps(a, b, c); }
/// c − a·b
MAGSIM_TARGET_AVX512 inline V8 fnma(V8 a, V8 b, V8 c) { return _mm512_fnmadd_pd(a, b, c); }
MAGSIM_TARGET_AVX512 inline V16 fnma(V16 a, V16 b, V16 c) { return _mm512_fnmadd_ps(a, b, c); }
/// a in the lanes of k, 0 elsewhere
MAGSIM_TARGET_AVX512 inline V8 keep(__mmask8 k, V8 a) { return _mm512_maskz_mov_pd(k, a); }
MAGSIM_TARGET_AVX512 inline V16 keep(__mmask16 k, V16 a) { return _mm512_maskz_mov_ps(k, a); }
/// lanes where a < b
MAGSIM_TARGET_AVX512 inline __mmask8 less(V8 a, V8 b) { return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ); }
MAGSIM_TARGET_AVX512 inline __mmask16 less(V16 a, V16 b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
MAGSIM_TARGET_AVX512 inline V8 max(V8 a, V8 b) { return _mm512_maskz_max_pd(0xff, a, b); }
MAGSIM_TARGET_AVX512 inline V16 max(V16 a, V16 b) { return _mm512_maskz_max_ps(0xffff, a, b); }
/// √a in the lanes of k, 0 elsewhere
MAGSIM_TARGET_AVX512 inline V8 sqrt(__mmask8 k, V8 a) { return _mm512_maskz_sqrt_pd(k, a); }
MAGSIM_TARGET_AVX512 inline V16 sqrt(__mmask16 k, V16 a) { return _mm512_maskz_sqrt_ps(k, a); }
/// a/b in the lanes of k, 0 elsewhere
MAGSIM_TARGET_AVX512 inline V8 div(__mmask8 k, V8 a, V8 b) { return _mm512_maskz_div_pd(k, a, b); }
MAGSIM_TARGET_AVX512 inline V16 div(__mmask16 k, V16 a, V16 b) { return _mm512_maskz_div_ps(k, a, b); }
/// a·b in the lanes of k, a elsewhere
MAGSIM_TARGET_AVX512 inline V8 mul_in(__mmask8 k, V8 a, V8 b) { return _mm512_mask_mul_pd(a, k, a, b); }
MAGSIM_TARGET_AVX512 inline V16 mul_in(__mmask16 k, V16 a, V16 b) { return _mm512_mask_mul_ps(a, k, a, b); }
// clang-format on

/// A constant in every lane of V (cst<V8>(x), cst<V16>(x); overloads on a V argument,
/// whose value is ignored).
MAGSIM_TARGET_AVX512 inline V8 splat(V8, double x) { return _mm512_set1_pd(x); }
MAGSIM_TARGET_AVX512 inline V16 splat(V16, double x) { return _mm512_set1_ps(static_cast<float>(x)); }
template <class V>
MAGSIM_TARGET_AVX512 inline V cst(double x) { return splat(V(), x); }

/// a·x + b·y + c·z
template <class V>
MAGSIM_TARGET_AVX512 inline V dot3(V a, V b, V c, V x, V y, V z) {
  return fma(c, z, fma(b, y, mul(a, x)));
}

/// 1/√q in the lanes of `k` (0 elsewhere).
/// Double: y0 = vrsqrt14pd(q) (|rel. error| ≤ 2⁻¹⁴), e = 1 − q y0²,
/// y = y0 (1 + e/2 + 3e²/8 + 5e³/16) — the series of (1 − e)^{-1/2} cut after e³ leaves
/// (35/128) e⁴ < 1e-16. Float: one Newton–Raphson step y0 + (y0/2)(1 − q y0²)
/// (rel. error ≈ 1.5·2⁻²⁸, below float rounding). (The masked forms also avoid GCC 12's
/// false -Wmaybe-uninitialized inside the unmasked intrinsics.)
MAGSIM_TARGET_AVX512 inline V8 rsqrt(__mmask8 k, V8 q) {
  const V8 y = _mm512_maskz_rsqrt14_pd(k, q);
  const V8 e = fnma(q, mul(y, y), cst<V8>(1.0));
  const V8 p = fma(fma(cst<V8>(5.0 / 16.0), e, cst<V8>(3.0 / 8.0)), e, cst<V8>(0.5));
  return fma(mul(y, e), p, y);
}
MAGSIM_TARGET_AVX512 inline V16 rsqrt(__mmask16 k, V16 q) {
  const V16 y = _mm512_maskz_rsqrt14_ps(k, q);
  const V16 e = fnma(q, mul(y, y), cst<V16>(1.0));
  return fma(mul(y, cst<V16>(0.5)), e, y);
}

/// Horizontal sum of the eight double lanes in a fixed order (deterministic).
MAGSIM_TARGET_AVX512 inline double hsum(V8 v) {
  alignas(64) double t[8];
  _mm512_store_pd(t, v);
  return ((t[0] + t[4]) + (t[1] + t[5])) + ((t[2] + t[6]) + (t[3] + t[7]));
}

/// A chunk's partial sums added to double accumulators: 16 float lanes are widened
/// (exactly) and lane k of acc gets float lanes k and k + 8, in a fixed order; 8 double
/// lanes are added lane by lane (a double kernel sums in one chunk: 0 + v is v bitwise, as
/// no partial sum that starts at +0 can be −0).
MAGSIM_TARGET_AVX512 inline V8 fold(V8 acc, V16 v) {
  const __m512d vd = _mm512_castps_pd(v);
  const __m256 l = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 0));
  const __m256 h = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 1));
  return add(acc, add(_mm512_maskz_cvtps_pd(0xff, l), _mm512_maskz_cvtps_pd(0xff, h)));
}
MAGSIM_TARGET_AVX512 inline V8 fold(V8 acc, V8 v) { return add(acc, v); }

/// The first n lanes (n ≤ the lane count); the lane type picks the overload (its value
/// is ignored).
MAGSIM_TARGET_AVX512 inline __mmask8 first_lanes(V8, std::size_t n) {
  return static_cast<__mmask8>((1u << n) - 1u);
}
MAGSIM_TARGET_AVX512 inline __mmask16 first_lanes(V16, std::size_t n) {
  return static_cast<__mmask16>((1u << n) - 1u);
}

/// Lanes whose ids differ from `self`: ids stored as doubles (compared as doubles, NaN
/// never equal) or as int32.
MAGSIM_TARGET_AVX512 inline __mmask8 differ(const double* ids, double self) {
  return _mm512_cmp_pd_mask(_mm512_loadu_pd(ids), _mm512_set1_pd(self), _CMP_NEQ_UQ);
}
MAGSIM_TARGET_AVX512 inline __mmask16 differ(const std::int32_t* ids, std::int32_t self) {
  return _mm512_cmpneq_epi32_mask(_mm512_loadu_si512(ids), _mm512_set1_epi32(self));
}

}  // namespace magsim::mag::detail::simd

#endif  // MAGSIM_AVX512_KERNEL
