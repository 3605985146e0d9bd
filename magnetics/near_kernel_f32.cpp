// magnetics/near_kernel_f32.cpp — the pair kernel of field_kernel.hpp in single precision,
// for the near field of Barnes–Hut (FieldOptions::bh_near_float).
//
// The double kernel (dipole_field.cpp) sweeps 8 sources per AVX-512 register; this one 16.
// Positions arrive relative to the target group's centre (a few cm at most), so float
// carries them to ~1e-9 m; 1/√q is vrsqrt14ps (|rel. error| ≤ 2⁻¹⁴) refined by one
// Newton–Raphson step (≈ 1.5·2⁻²⁸, below float rounding). Each lane sums in float over one
// chunk of kChunkF sources (kChunkF/16 terms per lane), then the chunk's lanes are added
// in double — so the float rounding of the sum does not grow with the list. The portable
// loop computes the same algebra (1/√q exactly rounded instead of the estimate; float
// partial sums over kChunkF/16 sources), so the two agree to float rounding. Both sum in a fixed order: deterministic.
#include "magnetics/field_kernel.hpp"

#include <algorithm>
#include <cmath>

namespace magsim::mag::detail {

namespace {

// Portable sweep: the algebra of sum_pairs_portable (dipole_field.cpp) in float, one
// chunk of sources at a time, chunk sums added in double.
template <bool kJac, bool kBound>
void sum_pairs_f32_portable(const SourceViewF& v, const TargetF& t, float eps2, double* Hout,
                            double* Jout) {
  const float* __restrict sx = v.x;
  const float* __restrict sy = v.y;
  const float* __restrict sz = v.z;
  const float* __restrict mx = v.mx;
  const float* __restrict my = v.my;
  const float* __restrict mz = v.mz;
  const std::int32_t* __restrict si = v.id;
  const std::int32_t* __restrict sg = v.grp;
  const float* __restrict sr = v.rad;
  const float px = t.x, py = t.y, pz = t.z, trad = t.rad;
  const std::int32_t self = t.id, grp = t.grp;
  double acc[13] = {};  // ax ay az bx by bz ja jxx jyy jzz jxy jxz jyz
  // float partial sums of kChunkF / 16 sources (as many terms as an AVX-512 lane sums:
  // the loop below need not be vectorized, and then each float sums the whole chunk)
  constexpr std::size_t kChunk = kChunkF / kSourcePadF;
  for (std::size_t c = 0; c < v.n; c += kChunk) {
    const std::size_t e = std::min(v.n, c + kChunk);
    float ax = 0, ay = 0, az = 0, bx = 0, by = 0, bz = 0;
    float ja = 0, jxx = 0, jyy = 0, jzz = 0, jxy = 0, jxz = 0, jyz = 0;
#pragma omp simd reduction(+ : ax, ay, az, bx, by, bz, ja, jxx, jyy, jzz, jxy, jxz, jyz)
    for (std::size_t i = c; i < e; ++i) {
      float dx = px - sx[i], dy = py - sy[i], dz = pz - sz[i];
      const bool is_self = si[i] == self;
      float r2 = dx * dx + dy * dy + dz * dz;
      if constexpr (kBound) {
        // bounded pair (field_kernel.hpp): |r| < R = a_i + a_t is evaluated at r·R/|r|
        const float R = sr[i] + trad;
        const float s = r2 < R * R ? R / std::sqrt(std::max(r2, 1e-30f)) : 1.0f;
        dx *= s; dy *= s; dz *= s;
        r2 = std::max(r2, R * R);
      }
      const float q = is_self ? 1.0f : r2 + eps2;
      const float inv = is_self ? 0.0f : 1.0f / std::sqrt(q);
      const float inv2 = inv * inv;
      const float inv3 = inv2 * inv;
      const float inv5 = inv3 * inv2;
      const float rm = dx * mx[i] + dy * my[i] + dz * mz[i];
      // eq. 1: h = (1/4π)(3 r (r·m) − q m)/q^{5/2}, accumulated as Σ (r·m) r / q^{5/2} and
      // Σ m / q^{3/2}
      const float a = rm * inv5;
      ax += a * dx; ay += a * dy; az += a * dz;
      bx += inv3 * mx[i]; by += inv3 * my[i]; bz += inv3 * mz[i];
      if constexpr (kJac) {
        // Jacobian (see dipole_jacobian): ∂h/∂r = (1/4π)[3(I(r·m) + r mᵀ + m rᵀ)/q^{5/2}
        //   − 15 r rᵀ (r·m)/q^{7/2}]; J/3 = u (rm I + r mᵀ + m rᵀ) − 5 rm u/q r rᵀ,
        // u = q^{-5/2} (0 within the target's group)
        const float u = sg[i] == grp ? 0.0f : inv5;
        const float aj = rm * u;
        const float t5 = 5.0f * aj * inv2;
        const float gx = u * mx[i], gy = u * my[i], gz = u * mz[i];
        const float kx = gx - t5 * dx, ky = gy - t5 * dy, kz = gz - t5 * dz;
        ja += aj;
        jxx += dx * (gx + kx); jyy += dy * (gy + ky); jzz += dz * (gz + kz);
        jxy += dx * gy + dy * kx; jxz += dx * gz + dz * kx; jyz += dy * gz + dz * ky;
      }
    }
    const float part[13] = {ax, ay, az, bx, by, bz, ja, jxx, jyy, jzz, jxy, jxz, jyz};
    for (int k = 0; k < (kJac ? 13 : 6); ++k) acc[k] += part[k];
  }
  Hout[0] += (3.0 * acc[0] - acc[3]) * kInv4Pi;
  Hout[1] += (3.0 * acc[1] - acc[4]) * kInv4Pi;
  Hout[2] += (3.0 * acc[2] - acc[5]) * kInv4Pi;
  if constexpr (kJac) {
    const double s = 3.0 * kInv4Pi;
    Jout[0] += (acc[6] + acc[7]) * s; Jout[1] += (acc[6] + acc[8]) * s;
    Jout[2] += (acc[6] + acc[9]) * s;
    Jout[3] += acc[10] * s; Jout[4] += acc[11] * s; Jout[5] += acc[12] * s;
  }
}

#ifdef MAGSIM_AVX512_KERNEL

// 1/√q in the lanes of `keep` (0 elsewhere): y0 = vrsqrt14ps(q) (|rel. error| ≤ 2⁻¹⁴),
// one Newton–Raphson step y = y0 + (y0/2)(1 − q y0²) (rel. error ≈ 1.5·2⁻²⁸ ≈ 6e-9).
MAGSIM_TARGET_AVX512 inline __m512 rsqrt_ps(__mmask16 keep, __m512 q) {
  const __m512 y = _mm512_maskz_rsqrt14_ps(keep, q);
  const __m512 e = _mm512_fnmadd_ps(q, _mm512_mul_ps(y, y), _mm512_set1_ps(1.0f));
  return _mm512_fmadd_ps(_mm512_mul_ps(y, _mm512_set1_ps(0.5f)), e, y);
}

// The 16 float lanes of v, widened and added lane by lane to the 8 double lanes of acc
// (lane k gets float lanes k and k + 8): exact widening, a fixed order. (The masked forms
// avoid GCC 12's false -Wmaybe-uninitialized inside the unmasked intrinsics.)
MAGSIM_TARGET_AVX512 inline __m512d widen_add(__m512d acc, __m512 v) {
  const __m512d vd = _mm512_castps_pd(v);
  const __m256 l = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 0));
  const __m256 h = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 1));
  const __m512d lo = _mm512_maskz_cvtps_pd(0xff, l);
  const __m512d hi = _mm512_maskz_cvtps_pd(0xff, h);
  return _mm512_add_pd(acc, _mm512_add_pd(lo, hi));
}

// Horizontal sum of the eight double lanes in a fixed order (deterministic).
MAGSIM_TARGET_AVX512 inline double hsum(__m512d v) {
  alignas(64) double t[8];
  _mm512_store_pd(t, v);
  return ((t[0] + t[4]) + (t[1] + t[5])) + ((t[2] + t[6]) + (t[3] + t[7]));
}

// The sweep over sixteen sources at a time; the algebra of sum_pairs_avx512 (dipole_field.cpp).
template <bool kJac, bool kBound>
MAGSIM_TARGET_AVX512 void sum_pairs_f32_avx512(const SourceViewF& v, const TargetF& t,
                                               float eps2, double* Hout, double* Jout) {
  const __m512 trad = _mm512_set1_ps(t.rad);
  const __m512 px = _mm512_set1_ps(t.x), py = _mm512_set1_ps(t.y), pz = _mm512_set1_ps(t.z);
  const __m512i self = _mm512_set1_epi32(t.id), grp = _mm512_set1_epi32(t.grp);
  const __m512 e2 = _mm512_set1_ps(eps2);
  const __m512 five = _mm512_set1_ps(5.0f);
  // double accumulators across chunks: ax ay az bx by bz ja jxx jyy jzz jxy jxz jyz
  __m512d acc[13];
  for (__m512d& a : acc) a = _mm512_setzero_pd();
  for (std::size_t c = 0; c < v.n; c += kChunkF) {
    const std::size_t end = std::min(v.n, c + kChunkF);
    __m512 ax = _mm512_setzero_ps(), ay = ax, az = ax, bx = ax, by = ax, bz = ax;
    __m512 ja = ax, jxx = ax, jyy = ax, jzz = ax, jxy = ax, jxz = ax, jyz = ax;
    for (std::size_t i = c; i < end; i += 16) {
      __m512 dx = _mm512_sub_ps(px, _mm512_loadu_ps(v.x + i));
      __m512 dy = _mm512_sub_ps(py, _mm512_loadu_ps(v.y + i));
      __m512 dz = _mm512_sub_ps(pz, _mm512_loadu_ps(v.z + i));
      const __m512 mx = _mm512_loadu_ps(v.mx + i);
      const __m512 my = _mm512_loadu_ps(v.my + i);
      const __m512 mz = _mm512_loadu_ps(v.mz + i);
      const __mmask16 other =
          _mm512_cmpneq_epi32_mask(_mm512_loadu_si512(v.id + i), self);
      __m512 q;
      if constexpr (kBound) {
        // bounded pair: |r| < R = a_i + a_t is evaluated at r·R/|r| (rare branch)
        const __m512 R = _mm512_add_ps(_mm512_loadu_ps(v.rad + i), trad);
        const __m512 R2 = _mm512_mul_ps(R, R);
        __m512 r2 = _mm512_mul_ps(dx, dx);
        r2 = _mm512_fmadd_ps(dy, dy, r2);
        r2 = _mm512_fmadd_ps(dz, dz, r2);
        const __mmask16 in = _mm512_cmp_ps_mask(r2, R2, _CMP_LT_OQ) & other;
        if (in) {
          const __m512 d = _mm512_maskz_sqrt_ps(in, _mm512_maskz_max_ps(0xffff, r2, _mm512_set1_ps(1e-30f)));
          const __m512 s = _mm512_maskz_div_ps(in, R, d);
          dx = _mm512_mask_mul_ps(dx, in, dx, s);
          dy = _mm512_mask_mul_ps(dy, in, dy, s);
          dz = _mm512_mask_mul_ps(dz, in, dz, s);
        }
        q = _mm512_add_ps(_mm512_maskz_max_ps(0xffff, r2, R2), e2);
      } else {
        q = _mm512_fmadd_ps(dx, dx, e2);
        q = _mm512_fmadd_ps(dy, dy, q);
        q = _mm512_fmadd_ps(dz, dz, q);
      }
      const __m512 inv = rsqrt_ps(other, q);
      const __m512 inv2 = _mm512_mul_ps(inv, inv);
      const __m512 inv3 = _mm512_mul_ps(inv2, inv);
      const __m512 inv5 = _mm512_mul_ps(inv3, inv2);
      __m512 rm = _mm512_mul_ps(dx, mx);
      rm = _mm512_fmadd_ps(dy, my, rm);
      rm = _mm512_fmadd_ps(dz, mz, rm);
      // eq. 1: h = (1/4π)(3 r (r·m) − q m)/q^{5/2}
      const __m512 a = _mm512_mul_ps(rm, inv5);
      ax = _mm512_fmadd_ps(a, dx, ax);
      ay = _mm512_fmadd_ps(a, dy, ay);
      az = _mm512_fmadd_ps(a, dz, az);
      bx = _mm512_fmadd_ps(inv3, mx, bx);
      by = _mm512_fmadd_ps(inv3, my, by);
      bz = _mm512_fmadd_ps(inv3, mz, bz);
      if constexpr (kJac) {
        // Jacobian of eq. 1 (see dipole_jacobian): ∂h/∂r = (1/4π)[3(I(r·m) + r mᵀ + m rᵀ)
        // /q^{5/2} − 15 r rᵀ (r·m)/q^{7/2}], same-group sources masked
        const __mmask16 ext = _mm512_cmpneq_epi32_mask(_mm512_loadu_si512(v.grp + i), grp);
        const __m512 u = _mm512_maskz_mov_ps(ext, inv5);
        const __m512 aj = _mm512_mul_ps(rm, u);
        const __m512 t5 = _mm512_mul_ps(aj, _mm512_mul_ps(inv2, five));
        const __m512 gx = _mm512_mul_ps(u, mx);
        const __m512 gy = _mm512_mul_ps(u, my);
        const __m512 gz = _mm512_mul_ps(u, mz);
        const __m512 kx = _mm512_fnmadd_ps(t5, dx, gx);
        const __m512 ky = _mm512_fnmadd_ps(t5, dy, gy);
        const __m512 kz = _mm512_fnmadd_ps(t5, dz, gz);
        ja = _mm512_add_ps(ja, aj);
        jxx = _mm512_fmadd_ps(dx, _mm512_add_ps(gx, kx), jxx);
        jyy = _mm512_fmadd_ps(dy, _mm512_add_ps(gy, ky), jyy);
        jzz = _mm512_fmadd_ps(dz, _mm512_add_ps(gz, kz), jzz);
        jxy = _mm512_fmadd_ps(dy, kx, _mm512_fmadd_ps(dx, gy, jxy));
        jxz = _mm512_fmadd_ps(dz, kx, _mm512_fmadd_ps(dx, gz, jxz));
        jyz = _mm512_fmadd_ps(dz, ky, _mm512_fmadd_ps(dy, gz, jyz));
      }
    }
    acc[0] = widen_add(acc[0], ax); acc[1] = widen_add(acc[1], ay);
    acc[2] = widen_add(acc[2], az); acc[3] = widen_add(acc[3], bx);
    acc[4] = widen_add(acc[4], by); acc[5] = widen_add(acc[5], bz);
    if constexpr (kJac) {
      acc[6] = widen_add(acc[6], ja); acc[7] = widen_add(acc[7], jxx);
      acc[8] = widen_add(acc[8], jyy); acc[9] = widen_add(acc[9], jzz);
      acc[10] = widen_add(acc[10], jxy); acc[11] = widen_add(acc[11], jxz);
      acc[12] = widen_add(acc[12], jyz);
    }
  }
  Hout[0] += (3.0 * hsum(acc[0]) - hsum(acc[3])) * kInv4Pi;
  Hout[1] += (3.0 * hsum(acc[1]) - hsum(acc[4])) * kInv4Pi;
  Hout[2] += (3.0 * hsum(acc[2]) - hsum(acc[5])) * kInv4Pi;
  if constexpr (kJac) {
    const double s = 3.0 * kInv4Pi;
    const double a = hsum(acc[6]);
    Jout[0] += (a + hsum(acc[7])) * s; Jout[1] += (a + hsum(acc[8])) * s;
    Jout[2] += (a + hsum(acc[9])) * s;
    Jout[3] += hsum(acc[10]) * s; Jout[4] += hsum(acc[11]) * s; Jout[5] += hsum(acc[12]) * s;
  }
}

#endif  // MAGSIM_AVX512_KERNEL

}  // namespace

void sum_pairs_f32(const SourceViewF& v, const TargetF& t, float eps2, PairTerms terms,
                   double* H, double* J) {
#ifdef MAGSIM_AVX512_KERNEL
  const bool bound = v.rad != nullptr;
  if (simd_kernel_active()) {
    if (terms == PairTerms::HJ) {
      if (bound) sum_pairs_f32_avx512<true, true>(v, t, eps2, H, J);
      else sum_pairs_f32_avx512<true, false>(v, t, eps2, H, J);
    } else {
      if (bound) sum_pairs_f32_avx512<false, true>(v, t, eps2, H, J);
      else sum_pairs_f32_avx512<false, false>(v, t, eps2, H, J);
    }
    return;
  }
#else
  const bool bound = v.rad != nullptr;
#endif
  if (terms == PairTerms::HJ) {
    if (bound) sum_pairs_f32_portable<true, true>(v, t, eps2, H, J);
    else sum_pairs_f32_portable<true, false>(v, t, eps2, H, J);
  } else {
    if (bound) sum_pairs_f32_portable<false, true>(v, t, eps2, H, J);
    else sum_pairs_f32_portable<false, false>(v, t, eps2, H, J);
  }
}

}  // namespace magsim::mag::detail
