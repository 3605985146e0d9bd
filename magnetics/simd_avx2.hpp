// magnetics/simd_avx2.hpp — internal: the lane operations of simd.hpp in AVX2+FMA registers,
// for the kernels' AVX2+FMA instance (pair_kernel.cpp, barnes_hut_far.cpp). 8 double lanes
// are two __m256d (lanes 0–3, 4–7), 16 float lanes two __m256 (lanes 0–7, 8–15); a mask is
// the matching pair, all ones (true) or zero per lane. Every operation gives the bits of the
// portable and AVX-512 sets, lane by lane, masked-off lanes included: the same correctly
// rounded steps in the same order (double a·b + c fused, float a·b + c rounded twice, 1/√q
// as 1 ÷ √q, the same fold and hsum trees). Written as intrinsics on the halves because
// GCC 12 spills the 64-byte portable lanes to the stack when it splits them under AVX2.
// Include only from magnetics/*.cpp, after field_kernel.hpp.
#pragma once

#include "magnetics/simd.hpp"

#ifdef MAGSIM_FMA_KERNEL

#include <immintrin.h>

#include <cstddef>
#include <cstdint>

#pragma GCC push_options
#pragma GCC target("avx2,fma")

namespace magsim::mag::detail::simd {

/// 8 double lanes, 16 float lanes, and their masks (each a low and a high register)
struct A8 {
  __m256d lo, hi;
};
struct A16 {
  __m256 lo, hi;
};
struct A8m {
  __m256d lo, hi;
};
struct A16m {
  __m256 lo, hi;
};

/// The AVX2 lane set
template <class T>
using Avx2LaneOf = LaneSetOf<T, A8, A16>;

// clang-format off
inline A8 ld(const double* p, A8) { return A8{_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)}; }
inline A16 ld(const float* p, A16) { return A16{_mm256_loadu_ps(p), _mm256_loadu_ps(p + 8)}; }
inline A8 add(A8 a, A8 b) { return A8{_mm256_add_pd(a.lo, b.lo), _mm256_add_pd(a.hi, b.hi)}; }
inline A16 add(A16 a, A16 b) { return A16{_mm256_add_ps(a.lo, b.lo), _mm256_add_ps(a.hi, b.hi)}; }
inline A8 sub(A8 a, A8 b) { return A8{_mm256_sub_pd(a.lo, b.lo), _mm256_sub_pd(a.hi, b.hi)}; }
inline A16 sub(A16 a, A16 b) { return A16{_mm256_sub_ps(a.lo, b.lo), _mm256_sub_ps(a.hi, b.hi)}; }
inline A8 mul(A8 a, A8 b) { return A8{_mm256_mul_pd(a.lo, b.lo), _mm256_mul_pd(a.hi, b.hi)}; }
inline A16 mul(A16 a, A16 b) { return A16{_mm256_mul_ps(a.lo, b.lo), _mm256_mul_ps(a.hi, b.hi)}; }
/// max as the x86 instruction (and the portable a > b ? a : b) has it: b where either is NaN
/// or both are zeros
inline A8 max(A8 a, A8 b) { return A8{_mm256_max_pd(a.lo, b.lo), _mm256_max_pd(a.hi, b.hi)}; }
inline A16 max(A16 a, A16 b) { return A16{_mm256_max_ps(a.lo, b.lo), _mm256_max_ps(a.hi, b.hi)}; }
/// a in the lanes of m, +0 elsewhere
inline A8 keep(A8m m, A8 a) { return A8{_mm256_and_pd(m.lo, a.lo), _mm256_and_pd(m.hi, a.hi)}; }
inline A16 keep(A16m m, A16 a) { return A16{_mm256_and_ps(m.lo, a.lo), _mm256_and_ps(m.hi, a.hi)}; }
inline A8m less(A8 a, A8 b) {
  return A8m{_mm256_cmp_pd(a.lo, b.lo, _CMP_LT_OQ), _mm256_cmp_pd(a.hi, b.hi, _CMP_LT_OQ)};
}
inline A16m less(A16 a, A16 b) {
  return A16m{_mm256_cmp_ps(a.lo, b.lo, _CMP_LT_OQ), _mm256_cmp_ps(a.hi, b.hi, _CMP_LT_OQ)};
}
inline A8m operator&(A8m a, A8m b) { return A8m{_mm256_and_pd(a.lo, b.lo), _mm256_and_pd(a.hi, b.hi)}; }
inline A16m operator&(A16m a, A16m b) { return A16m{_mm256_and_ps(a.lo, b.lo), _mm256_and_ps(a.hi, b.hi)}; }
inline bool any(A8m m) { return _mm256_movemask_pd(_mm256_or_pd(m.lo, m.hi)) != 0; }
inline bool any(A16m m) { return _mm256_movemask_ps(_mm256_or_ps(m.lo, m.hi)) != 0; }
/// √a, a ÷ b in the lanes of m, 0 elsewhere (computed in every lane, then selected)
inline A8 sqrt(A8m m, A8 a) { return keep(m, A8{_mm256_sqrt_pd(a.lo), _mm256_sqrt_pd(a.hi)}); }
inline A16 sqrt(A16m m, A16 a) { return keep(m, A16{_mm256_sqrt_ps(a.lo), _mm256_sqrt_ps(a.hi)}); }
inline A8 div(A8m m, A8 a, A8 b) { return keep(m, A8{_mm256_div_pd(a.lo, b.lo), _mm256_div_pd(a.hi, b.hi)}); }
inline A16 div(A16m m, A16 a, A16 b) { return keep(m, A16{_mm256_div_ps(a.lo, b.lo), _mm256_div_ps(a.hi, b.hi)}); }
/// a·b in the lanes of m, a elsewhere
inline A8 mul_in(A8m m, A8 a, A8 b) {
  const A8 p = mul(a, b);
  return A8{_mm256_blendv_pd(a.lo, p.lo, m.lo), _mm256_blendv_pd(a.hi, p.hi, m.hi)};
}
inline A16 mul_in(A16m m, A16 a, A16 b) {
  const A16 p = mul(a, b);
  return A16{_mm256_blendv_ps(a.lo, p.lo, m.lo), _mm256_blendv_ps(a.hi, p.hi, m.hi)};
}
inline A8 splat(A8, double x) { return A8{_mm256_set1_pd(x), _mm256_set1_pd(x)}; }
inline A16 splat(A16, double x) {
  const float f = static_cast<float>(x);
  return A16{_mm256_set1_ps(f), _mm256_set1_ps(f)};
}
// clang-format on

/// Lanes k < n
inline A8m first_lanes(A8, std::size_t n) {
  const __m256i c = _mm256_set1_epi64x(static_cast<long long>(n < 8 ? n : 8));
  return A8m{_mm256_castsi256_pd(_mm256_cmpgt_epi64(c, _mm256_setr_epi64x(0, 1, 2, 3))),
             _mm256_castsi256_pd(_mm256_cmpgt_epi64(c, _mm256_setr_epi64x(4, 5, 6, 7)))};
}
inline A16m first_lanes(A16, std::size_t n) {
  const __m256i c = _mm256_set1_epi32(static_cast<int>(n < 16 ? n : 16));
  const __m256i lo = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i hi = _mm256_setr_epi32(8, 9, 10, 11, 12, 13, 14, 15);
  return A16m{_mm256_castsi256_ps(_mm256_cmpgt_epi32(c, lo)),
              _mm256_castsi256_ps(_mm256_cmpgt_epi32(c, hi))};
}

// a·b + c and c − a·b: double fused (one rounding, the FMA instruction), float rounded twice
// (as unfused_float); a·x + b·y + c·z as mul_add(c, z, mul_add(b, y, a·x))
inline A8 mul_add(A8 a, A8 b, A8 c) {
  return A8{_mm256_fmadd_pd(a.lo, b.lo, c.lo), _mm256_fmadd_pd(a.hi, b.hi, c.hi)};
}
inline A16 mul_add(A16 a, A16 b, A16 c) { return add(mul(a, b), c); }
inline A8 neg_mul_add(A8 a, A8 b, A8 c) {
  return A8{_mm256_fnmadd_pd(a.lo, b.lo, c.lo), _mm256_fnmadd_pd(a.hi, b.hi, c.hi)};
}
inline A16 neg_mul_add(A16 a, A16 b, A16 c) { return sub(c, mul(a, b)); }
inline A8 dot3(A8 a, A8 b, A8 c, A8 x, A8 y, A8 z) {
  return mul_add(c, z, mul_add(b, y, mul(a, x)));
}
inline A16 dot3(A16 a, A16 b, A16 c, A16 x, A16 y, A16 z) {
  return mul_add(c, z, mul_add(b, y, mul(a, x)));
}

/// 1/√q as 1 ÷ √q (two correctly rounded steps) in the lanes of m, 0 elsewhere
inline A8 inv_sqrt(A8m m, A8 q) {
  const __m256d one = _mm256_set1_pd(1.0);
  return keep(m, A8{_mm256_div_pd(one, _mm256_sqrt_pd(q.lo)),
                    _mm256_div_pd(one, _mm256_sqrt_pd(q.hi))});
}
inline A16 inv_sqrt(A16m m, A16 q) {
  const __m256 one = _mm256_set1_ps(1.0f);
  return keep(m, A16{_mm256_div_ps(one, _mm256_sqrt_ps(q.lo)),
                     _mm256_div_ps(one, _mm256_sqrt_ps(q.hi))});
}

/// Lanes whose ids differ from `self` (ids as doubles, NaN never equal; or as int32)
inline A8m differ_lanes(const double* ids, double self, A8) {
  const __m256d s = _mm256_set1_pd(self);
  return A8m{_mm256_cmp_pd(_mm256_loadu_pd(ids), s, _CMP_NEQ_UQ),
             _mm256_cmp_pd(_mm256_loadu_pd(ids + 4), s, _CMP_NEQ_UQ)};
}
inline A16m differ_lanes(const std::int32_t* ids, std::int32_t self, A16) {
  const __m256i s = _mm256_set1_epi32(self), ones = _mm256_set1_epi32(-1);
  const __m256i lo = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids));
  const __m256i hi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + 8));
  return A16m{_mm256_castsi256_ps(_mm256_xor_si256(_mm256_cmpeq_epi32(lo, s), ones)),
              _mm256_castsi256_ps(_mm256_xor_si256(_mm256_cmpeq_epi32(hi, s), ones))};
}

/// acc + v lane by lane (double); 16 float lanes: lane k of acc gets float lanes k and k + 8,
/// widened exactly, as acc_k + (v_k + v_{k+8})
inline A8 fold(A8 acc, A8 v) { return add(acc, v); }
inline A8 fold(A8 acc, A16 v) {
  const __m256d lo = _mm256_add_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(v.lo)),
                                   _mm256_cvtps_pd(_mm256_castps256_ps128(v.hi)));
  const __m256d hi = _mm256_add_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(v.lo, 1)),
                                   _mm256_cvtps_pd(_mm256_extractf128_ps(v.hi, 1)));
  return A8{_mm256_add_pd(acc.lo, lo), _mm256_add_pd(acc.hi, hi)};
}
/// the eight lanes summed in simd.hpp's tree ((l0 + l4) + (l1 + l5)) + ((l2 + l6) + (l3 + l7))
inline double hsum(A8 v) {
  alignas(32) double t[4];
  _mm256_store_pd(t, _mm256_add_pd(v.lo, v.hi));
  return (t[0] + t[1]) + (t[2] + t[3]);
}

}  // namespace magsim::mag::detail::simd

#pragma GCC pop_options

#endif  // MAGSIM_FMA_KERNEL
