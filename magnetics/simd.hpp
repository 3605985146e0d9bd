// magnetics/simd.hpp — internal: the lane operations of the field kernels, in three sets that
// give the same bits: portable lanes (PD, PF: GCC generic vectors that the compiler splits into
// the CPU's width), AVX2+FMA registers (simd_avx2.hpp: pairs of __m256d, __m256) and AVX-512
// registers (__m512d, __m512). A kernel body is written once over these names
// (pair_sweep.inc, far_block.inc) and compiled for each set, so its result does not depend on
// the CPU. Every operation is element-wise IEEE and correctly rounded (+, −, ×, ÷, √, fused
// a·b + c, max, compare, select), sums across lanes follow one tree (hsum), and 1/√q is
// 1 ÷ √q on all three. Double mul_add is always fused, never contracted by the compiler: one
// rounding on every CPU, in the FMA instruction or, on a CPU without it, in soft_fma's exact
// emulation below (float mul_add rounds twice everywhere: unfused_float). Double kernels run 8
// lanes, float kernels 16, whatever the hardware width. Include only from magnetics/*.cpp,
// after field_kernel.hpp.
#pragma once

#include "magnetics/field_kernel.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#ifdef MAGSIM_FMA_KERNEL
#include <immintrin.h>
#endif

namespace magsim::mag::detail::simd {

// ---- portable lanes ----------------------------------------------------------------------
//
// GCC's generic vectors of 8 doubles or 16 floats: the compiler splits each operation into
// the CPU's own width (2 × AVX2, 4 × SSE2), element-wise, so the lanes round as the AVX-512
// registers do. A masked result is computed in every lane and then selected.

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // 64-byte vectors by value: all of this inlines

typedef double VecD8 __attribute__((vector_size(64)));
typedef float VecF16 __attribute__((vector_size(64)));
typedef float VecF8 __attribute__((vector_size(32)));
typedef std::int64_t VecI64x8 __attribute__((vector_size(64)));
typedef std::int32_t VecI32x16 __attribute__((vector_size(64)));

/// 8 double lanes, 16 float lanes
struct PD {
  VecD8 v;
};
struct PF {
  VecF16 v;
};
/// lane masks: all ones (true) or zero per lane
struct MD {
  VecI64x8 m;
};
struct MF {
  VecI32x16 m;
};
inline MD operator&(MD a, MD b) { return MD{a.m & b.m}; }
inline MF operator&(MF a, MF b) { return MF{a.m & b.m}; }
inline bool any(MD a) {
  std::int64_t r = 0;
  for (int k = 0; k < 8; ++k) r |= a.m[k];
  return r != 0;
}
inline bool any(MF a) {
  std::int32_t r = 0;
  for (int k = 0; k < 16; ++k) r |= a.m[k];
  return r != 0;
}

/// loads the lanes from p; the second argument (its value unused) picks the lane set
inline PD ld(const double* p, PD) {
  PD r;
  std::memcpy(&r.v, p, sizeof r.v);
  return r;
}
inline PF ld(const float* p, PF) {
  PF r;
  std::memcpy(&r.v, p, sizeof r.v);
  return r;
}

#define MAGSIM_PORTABLE_OPS(P, M, T, N)                                                      \
  inline P add(P a, P b) { return P{a.v + b.v}; }                                            \
  inline P sub(P a, P b) { return P{a.v - b.v}; }                                            \
  inline P mul(P a, P b) { return P{a.v * b.v}; }                                            \
  /* max as the x86 instruction has it: b where either is NaN or both are zeros */            \
  inline P max(P a, P b) { return P{a.v > b.v ? a.v : b.v}; }                                \
  inline P keep(M m, P a) {                                                                  \
    const P zero{};                                                                          \
    return P{m.m != 0 ? a.v : zero.v};                                                       \
  }                                                                                          \
  inline M less(P a, P b) { return M{a.v < b.v}; }                                           \
  inline P sqrt(M m, P a) {                                                                  \
    P r;                                                                                     \
    for (int k = 0; k < N; ++k) r.v[k] = std::sqrt(a.v[k]);                                  \
    return keep(m, r);                                                                       \
  }                                                                                          \
  inline P div(M m, P a, P b) { return keep(m, P{a.v / b.v}); }                              \
  inline P mul_in(M m, P a, P b) { return P{m.m != 0 ? a.v * b.v : a.v}; }                   \
  inline P splat(P, double x) {                                                              \
    P r;                                                                                     \
    for (int k = 0; k < N; ++k) r.v[k] = static_cast<T>(x);                                  \
    return r;                                                                                \
  }                                                                                          \
  inline M first_lanes(P, std::size_t n) {                                                   \
    M r;                                                                                     \
    for (int k = 0; k < N; ++k) r.m[k] = static_cast<std::size_t>(k) < n ? -1 : 0;           \
    return r;                                                                                \
  }
MAGSIM_PORTABLE_OPS(PD, MD, double, 8)
MAGSIM_PORTABLE_OPS(PF, MF, float, 16)
#undef MAGSIM_PORTABLE_OPS

// ---- fused a·b + c of the portable lanes -------------------------------------------------
//
// Two sets of mul_add, neg_mul_add and dot3 with the same bits; the portable instance of a
// kernel body picks one with a using-directive before its #include (pair_kernel.cpp,
// barnes_hut_far.cpp). The header cannot pick by itself: GCC 12 does not change __FMA__
// inside a `#pragma GCC target` region, and these functions are defined outside any.
//   fused_hw:   __builtin_fma per lane (a call to glibc's fma where the build has no FMA);
//   fused_soft: for the instance of a CPU without FMA: soft_fma below, in +, −, × and bit
//               operations that SSE2 vectorizes (fused_hw where the whole build has FMA).
// The AVX2+FMA instance has its own registers and FMA instructions (simd_avx2.hpp).

/// Correctly rounded (round-to-nearest-even) a·b + c lane by lane, bit for bit the FMA
/// instruction's result, from element-wise +, −, ×: no FMA instruction needed.
namespace soft_fma {

/// s + e = x + y exactly, s = RN(x + y) (Knuth's TwoSum; exact unless x + y overflows)
inline void two_sum(VecD8 x, VecD8 y, VecD8& s, VecD8& e) {
  s = x + y;
  const VecD8 yv = s - x;
  e = (x - (s - yv)) + (y - yv);
}

/// x = hi + lo, each with at most 26 significant bits (Veltkamp's splitting, C = 2^27 + 1;
/// exact while C·x does not overflow)
inline void split(VecD8 x, VecD8& hi, VecD8& lo) {
  const VecD8 g = x * 134217729.0;
  hi = g - (g - x);
  lo = x - hi;
}

/// RO(s + e), rounded to odd (s = RN(s + e), e its error from two_sum): s where e = 0 or
/// s's last significand bit is 1, else s's neighbour toward e (± 1 on the bit pattern of s,
/// which is nonzero since a sum that rounds to 0 is exact). A NaN e (inf or NaN inputs)
/// changes nothing. Sign tests by floating compare: SSE2 has no 64-bit integer compare.
inline VecD8 round_odd(VecD8 s, VecD8 e) {
  const VecI64x8 bits = __builtin_bit_cast(VecI64x8, s);
  const VecI64x8 same = ((e > 0.0) & (s > 0.0)) | ((e < 0.0) & (s < 0.0));
  const VecI64x8 opposite = ((e > 0.0) & (s < 0.0)) | ((e < 0.0) & (s > 0.0));
  const VecI64x8 even = (bits & 1) ^ 1;
  const VecI64x8 r = bits + (even & same) - (even & opposite);
  return __builtin_bit_cast(VecD8, r);
}

// Double lanes with every input nonzero in [2^-450, 2^450] (kLo, kHi): C·x stays below 2^478,
// a·b below 2^900, and every term of the algorithm is a multiple of 2^-1004 (ulp(a) ulp(b)
// ≥ 2^-502 · 2^-502, ulp(c) ≥ 2^-502), so no step overflows or leaves the normal range and
// the proof for an unbounded exponent applies.
constexpr double kLo = 0x1p-450, kHi = 0x1p450;

/// Scalar std::fma in the lanes where ok is 0 (inputs out of range, inf or NaN: rare)
[[gnu::noinline, gnu::cold]] inline void fma_lanes(VecD8& r, const VecI64x8& ok, const VecD8& a,
                                                  const VecD8& b, const VecD8& c) {
  for (int k = 0; k < 8; ++k)
    if (ok[k] == 0) r[k] = std::fma(a[k], b[k], c[k]);
}

/// RN(a·b + c) in double lanes (Boldo & Melquiond, "Emulation of FMA and correctly rounded
/// sums: proved algorithms using rounding to odd", IEEE TC 2008): a·b = uh + ul exactly
/// (Dekker's product on Veltkamp's halves), th + tl = c + uh (TwoSum), v = RO(tl + ul),
/// result RN(th + v). Lanes with a or b zero: a·b + c as two operations (the product ±0 is
/// exact); with c zero and a·b not: RN(a·b); out of range: std::fma. An exact cancellation
/// gives th = +0 and v = ±0, so +0 as RN has it.
[[gnu::always_inline]] inline VecD8 fma(VecD8 a, VecD8 b, VecD8 c) {
  const VecD8 uh = a * b;
  VecD8 ah, al, bh, bl;
  split(a, ah, al);
  split(b, bh, bl);
  const VecD8 ul = (((ah * bh - uh) + ah * bl) + al * bh) + al * bl;
  VecD8 th, tl, s, e;
  two_sum(c, uh, th, tl);
  two_sum(tl, ul, s, e);
  const VecD8 r = th + round_odd(s, e);
  const VecI64x8 zero_ab = (a == 0.0) | (b == 0.0), zero_c = c == 0.0;
  const VecI64x8 abs_mask = ~(VecI64x8{} + INT64_MIN);
  const auto in = [&](VecD8 x) {
    const VecD8 ax = __builtin_bit_cast(VecD8, __builtin_bit_cast(VecI64x8, x) & abs_mask);
    return (ax >= kLo) & (ax <= kHi);
  };
  const VecI64x8 ok = zero_ab | zero_c | (in(a) & in(b) & in(c));
  VecD8 out = zero_ab ? uh + c : (zero_c ? uh : r);
  std::int64_t all = -1;
  for (int k = 0; k < 8; ++k) all &= ok[k];
  if (all == 0) fma_lanes(out, ok, a, b, c);
  return out;
}

}  // namespace soft_fma

/// Float lanes: a·b + c rounded twice, on every path. The float kernels (Barnes–Hut's near
/// and far fields) are approximations to 1e-5 already, and fused they compiled to twice the
/// spills in the AVX2+FMA instance (sakura_tree's T_i + T_f 2x); unfused they give the same
/// bits everywhere as before.
namespace unfused_float {
inline PF mul_add(PF a, PF b, PF c) { return PF{a.v * b.v + c.v}; }
}  // namespace unfused_float

// a·b + c and c − a·b fused (one rounding; float: see unfused_float); a·x + b·y + c·z as
// mul_add(c, z, mul_add(b, y, a·x))
#define MAGSIM_FUSED_OPS(P)                                                                  \
  inline P neg_mul_add(P a, P b, P c) { return mul_add(P{-a.v}, b, c); }                     \
  inline P dot3(P a, P b, P c, P x, P y, P z) { return mul_add(c, z, mul_add(b, y, mul(a, x))); }

namespace fused_hw {
inline PD mul_add(PD a, PD b, PD c) {
  PD r;
  for (int k = 0; k < 8; ++k) r.v[k] = __builtin_fma(a.v[k], b.v[k], c.v[k]);
  return r;
}
using unfused_float::mul_add;
MAGSIM_FUSED_OPS(PD)
MAGSIM_FUSED_OPS(PF)
}  // namespace fused_hw

namespace fused_soft {
#ifdef __FMA__
using fused_hw::mul_add;
#else
inline PD mul_add(PD a, PD b, PD c) { return PD{soft_fma::fma(a.v, b.v, c.v)}; }
using unfused_float::mul_add;
#endif
MAGSIM_FUSED_OPS(PD)
MAGSIM_FUSED_OPS(PF)
}  // namespace fused_soft

#undef MAGSIM_FUSED_OPS

/// A lane set's type for the scalar T (double → D, float → F); each instance of a kernel body
/// names its set as LaneOf and reads LaneOf<T>::V
template <class T, class D, class F>
struct LaneSetOf {
  using V = std::conditional_t<std::is_same_v<T, double>, D, F>;
};
/// The portable lane set
template <class T>
using PortableLaneOf = LaneSetOf<T, PD, PF>;

/// A constant in every lane of V (cst<PD>(x), cst<V8>(x), …)
template <class V>
inline V cst(double x) {
  return splat(V(), x);
}

/// 1/√q as 1 ÷ √q (two correctly rounded steps) in the lanes of m, 0 elsewhere
inline PD inv_sqrt(MD m, PD q) {
  PD s;
  for (int k = 0; k < 8; ++k) s.v[k] = std::sqrt(q.v[k]);
  return keep(m, PD{1.0 / s.v});
}
inline PF inv_sqrt(MF m, PF q) {
  PF s;
  for (int k = 0; k < 16; ++k) s.v[k] = std::sqrt(q.v[k]);
  return keep(m, PF{1.0f / s.v});
}

/// Lanes whose ids differ from `self` (ids as doubles, NaN never equal; or as int32)
inline MD differ_lanes(const double* ids, double self, PD) {
  const PD i = ld(ids, PD{});
  return MD{i.v != self};
}
inline MF differ_lanes(const std::int32_t* ids, std::int32_t self, PF) {
  VecI32x16 i;
  std::memcpy(&i, ids, sizeof i);
  return MF{i != self};
}

/// acc + v lane by lane (double); 16 float lanes: lane k of acc gets float lanes k and k + 8,
/// widened exactly, as acc_k + (v_k + v_{k+8})
inline PD fold(PD acc, PD v) { return add(acc, v); }
inline PD fold(PD acc, PF v) {
  VecF8 lo, hi;
  std::memcpy(&lo, &v.v, sizeof lo);
  std::memcpy(&hi, reinterpret_cast<const char*>(&v.v) + sizeof lo, sizeof hi);
  return PD{acc.v + (__builtin_convertvector(lo, VecD8) + __builtin_convertvector(hi, VecD8))};
}
/// the eight lanes summed in one fixed tree
inline double hsum(PD v) {
  return ((v.v[0] + v.v[4]) + (v.v[1] + v.v[5])) + ((v.v[2] + v.v[6]) + (v.v[3] + v.v[7]));
}

#pragma GCC diagnostic pop

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
/// The AVX-512 lane set (specialized by hand: a vector type with attributes as a template
/// argument, as LaneSetOf would take it, draws -Wignored-attributes)
template <class T>
struct Avx512LaneOf;
template <>
struct Avx512LaneOf<double> {
  using V = V8;
};
template <>
struct Avx512LaneOf<float> {
  using V = V16;
};

inline bool any(__mmask8 m) { return m != 0; }
inline bool any(__mmask16 m) { return m != 0; }
inline __mmask8 first_lanes(V8, std::size_t n) { return static_cast<__mmask8>((1u << n) - 1u); }
inline __mmask16 first_lanes(V16, std::size_t n) { return static_cast<__mmask16>((1u << n) - 1u); }
// clang-format on

template <>
inline V8 cst<V8>(double x) { return _mm512_set1_pd(x); }
template <>
inline V16 cst<V16>(double x) { return _mm512_set1_ps(static_cast<float>(x)); }
// mul_add, neg_mul_add, dot3 as for the portable lanes (fused: one rounding)
inline V8 mul_add(V8 a, V8 b, V8 c) { return _mm512_fmadd_pd(a, b, c); }
inline V16 mul_add(V16 a, V16 b, V16 c) { return add(mul(a, b), c); }  // as unfused_float
inline V8 neg_mul_add(V8 a, V8 b, V8 c) { return _mm512_fnmadd_pd(a, b, c); }
inline V16 neg_mul_add(V16 a, V16 b, V16 c) { return sub(c, mul(a, b)); }
inline V8 dot3(V8 a, V8 b, V8 c, V8 x, V8 y, V8 z) { return mul_add(c, z, mul_add(b, y, mul(a, x))); }
inline V16 dot3(V16 a, V16 b, V16 c, V16 x, V16 y, V16 z) { return mul_add(c, z, mul_add(b, y, mul(a, x))); }

/// 1/√q as 1 ÷ √q in the lanes of k (0 elsewhere), the same bits as the portable lanes: two
/// correctly rounded steps, within 1.5 ulp of 1/√q (cheaper here than a float start and two
/// Newton steps, and exact-rounding on every CPU)
inline V8 inv_sqrt(__mmask8 k, V8 q) {
  return _mm512_maskz_div_pd(k, _mm512_set1_pd(1.0), _mm512_maskz_sqrt_pd(k, q));
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
