// magnetics/pair_kernel.cpp — the pair kernel of field_kernel.hpp (sum_pairs in double for
// the direct sum and the Barnes–Hut near field, sum_pairs_f32 in float for the Barnes–Hut
// near field): one body for the AVX-512 sweep and one for the portable loop, each
// instantiated per precision.
//
// Sources are swept W at a time (8 doubles or 16 floats per AVX-512 register) with a
// branch-free body: self and same-group terms are masked, not skipped. 1/√q comes from the
// 14-bit estimate vrsqrt14 refined (simd.hpp: to ≈ 1e-16 in double, below float rounding in
// float), which is what makes the loop fast; the portable `omp simd` loop computes the same
// algebra with 1/std::sqrt. Float sums run over chunks of kChunkF sources per lane set and
// are then added in double, so the float rounding of the sum does not grow with the list;
// a double sweep is one chunk. Every sum runs in a fixed order: deterministic. The double
// paths agree to ~1e-16, the float paths to float rounding (not bitwise).
#include "magnetics/field_kernel.hpp"
#include "magnetics/simd.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace magsim::mag::detail {

namespace {

// What differs between the precisions: the source view and target, the scalar, the chunk
// of float partial sums (0: one chunk), and the floor under r² in the bounded branch.
template <class View>
struct Precision;
template <>
struct Precision<SourceView> {
  using T = double;
  using Tgt = Target;
  static constexpr std::size_t kChunk = 0;
  static constexpr std::size_t kLanes = 8;
  static constexpr double kTiny = 1e-300;
#ifdef MAGSIM_AVX512_KERNEL
  using V = simd::V8;
#endif
};
template <>
struct Precision<SourceViewF> {
  using T = float;
  using Tgt = TargetF;
  static constexpr std::size_t kChunk = kChunkF;
  static constexpr std::size_t kLanes = 16;
  static constexpr float kTiny = 1e-30f;
#ifdef MAGSIM_AVX512_KERNEL
  using V = simd::V16;
#endif
};

// Sources per chunk of partial sums (all of them in double). `lanes`: the chunk is shared
// by this many partial sums (the AVX-512 lanes); the portable loop need not be vectorized,
// so it sums as many sources per chunk as one lane does (lanes = 1 there).
template <class P>
std::size_t chunk_of(std::size_t n, std::size_t lanes) {
  return P::kChunk ? P::kChunk / (P::kLanes / lanes) : std::max<std::size_t>(n, 1);
}

// Adds the chunk sums (ax ay az bx by bz ja jxx jyy jzz jxy jxz jyz, as doubles) to H and J:
//   h = (1/4π) Σ (3 (r·m) r / q^{5/2} − m / q^{3/2}),  J = (3/4π) (Σ ja I + Σ j..).
void finish(const double* acc, bool jac, double* Hout, double* Jout) {
  Hout[0] += (3.0 * acc[0] - acc[3]) * kInv4Pi;
  Hout[1] += (3.0 * acc[1] - acc[4]) * kInv4Pi;
  Hout[2] += (3.0 * acc[2] - acc[5]) * kInv4Pi;
  if (!jac) return;
  const double s = 3.0 * kInv4Pi;
  Jout[0] += (acc[6] + acc[7]) * s; Jout[1] += (acc[6] + acc[8]) * s;
  Jout[2] += (acc[6] + acc[9]) * s;
  Jout[3] += acc[10] * s; Jout[4] += acc[11] * s; Jout[5] += acc[12] * s;
}

// Portable sweep (any CPU), `omp simd` vectorized. kBound: bounded pairs (sum_pairs).
template <bool kJac, bool kBound, class View>
void sweep_portable(const View& v, const typename Precision<View>::Tgt& t,
                    typename Precision<View>::T eps2, double* Hout, double* Jout) {
  using P = Precision<View>;
  using T = typename P::T;
  const T* __restrict sx = v.x;
  const T* __restrict sy = v.y;
  const T* __restrict sz = v.z;
  const T* __restrict mx = v.mx;
  const T* __restrict my = v.my;
  const T* __restrict mz = v.mz;
  const auto* __restrict si = v.id;
  const auto* __restrict sg = v.grp;
  const T* __restrict sr = v.rad;
  const T px = t.x, py = t.y, pz = t.z, trad = t.rad;
  const auto self = t.id, grp = t.grp;
  double acc[13] = {};
  const std::size_t chunk = chunk_of<P>(v.n, 1);
  for (std::size_t c = 0; c < v.n; c += chunk) {
    const std::size_t e = std::min(v.n, c + chunk);
    T ax = 0, ay = 0, az = 0, bx = 0, by = 0, bz = 0;
    T ja = 0, jxx = 0, jyy = 0, jzz = 0, jxy = 0, jxz = 0, jyz = 0;
#pragma omp simd reduction(+ : ax, ay, az, bx, by, bz, ja, jxx, jyy, jzz, jxy, jxz, jyz)
    for (std::size_t i = c; i < e; ++i) {
      T dx = px - sx[i], dy = py - sy[i], dz = pz - sz[i];
      const bool is_self = si[i] == self;
      T r2 = dx * dx + dy * dy + dz * dz;
      if constexpr (kBound) {
        // |r| < R = a_i + a_t: evaluate at r·R/|r| (|r| = 0 keeps r = 0: then only −m/R³)
        const T R = sr[i] + trad;
        const T s = r2 < R * R ? R / std::sqrt(std::max(r2, P::kTiny)) : T(1);
        dx *= s; dy *= s; dz *= s;
        r2 = std::max(r2, R * R);
      }
      const T q = is_self ? T(1) : r2 + eps2;
      const T inv = is_self ? T(0) : T(1) / std::sqrt(q);
      const T inv2 = inv * inv;
      const T inv3 = inv2 * inv;
      const T inv5 = inv3 * inv2;
      const T rm = dx * mx[i] + dy * my[i] + dz * mz[i];
      // eq. 1: h = (1/4π)(3 r (r·m) − q m)/q^{5/2}, accumulated as Σ (r·m) r / q^{5/2} and
      // Σ m / q^{3/2}
      const T a = rm * inv5;
      ax += a * dx; ay += a * dy; az += a * dz;
      bx += inv3 * mx[i]; by += inv3 * my[i]; bz += inv3 * mz[i];
      if constexpr (kJac) {
        // Jacobian (see dipole_jacobian): ∂h/∂r = (1/4π)[3(I(r·m) + r mᵀ + m rᵀ)/q^{5/2}
        //   − 15 r rᵀ (r·m)/q^{7/2}]; J/3 = u (rm I + r mᵀ + m rᵀ) − 5 rm u/q r rᵀ,
        // u = q^{-5/2} (0 within the target's group)
        const T u = sg[i] == grp ? T(0) : inv5;
        const T aj = rm * u;
        const T t5 = T(5) * aj * inv2;
        const T gx = u * mx[i], gy = u * my[i], gz = u * mz[i];
        const T kx = gx - t5 * dx, ky = gy - t5 * dy, kz = gz - t5 * dz;
        ja += aj;
        jxx += dx * (gx + kx); jyy += dy * (gy + ky); jzz += dz * (gz + kz);
        jxy += dx * gy + dy * kx; jxz += dx * gz + dz * kx; jyz += dy * gz + dz * ky;
      }
    }
    const T part[13] = {ax, ay, az, bx, by, bz, ja, jxx, jyy, jzz, jxy, jxz, jyz};
    for (int k = 0; k < (kJac ? 13 : 6); ++k) acc[k] += part[k];
  }
  finish(acc, kJac, Hout, Jout);
}

#ifdef MAGSIM_AVX512_KERNEL

// The same sweep, W sources per register; the algebra of sweep_portable.
template <bool kJac, bool kBound, class View>
MAGSIM_TARGET_AVX512 void sweep_avx512(const View& v, const typename Precision<View>::Tgt& t,
                                       typename Precision<View>::T eps2, double* Hout,
                                       double* Jout) {
  using namespace simd;
  using P = Precision<View>;
  using V = typename P::V;
  constexpr int W = sizeof(V) / sizeof(typename P::T);  // 8 doubles or 16 floats
  const V px = cst<V>(t.x), py = cst<V>(t.y), pz = cst<V>(t.z);
  const V e2 = cst<V>(eps2), five = cst<V>(5.0), trad = cst<V>(t.rad);
  const V zero = cst<V>(0.0);
  V8 acc[13];
  for (V8& a : acc) a = cst<V8>(0.0);
  const std::size_t chunk = chunk_of<P>(v.n, P::kLanes);
  for (std::size_t c = 0; c < v.n; c += chunk) {
    const std::size_t end = std::min(v.n, c + chunk);
    V ax = zero, ay = zero, az = zero, bx = zero, by = zero, bz = zero;
    V ja = zero, jxx = zero, jyy = zero, jzz = zero, jxy = zero, jxz = zero, jyz = zero;
    for (std::size_t i = c; i < end; i += W) {
      V dx = sub(px, ld(v.x + i)), dy = sub(py, ld(v.y + i)), dz = sub(pz, ld(v.z + i));
      const V mx = ld(v.mx + i), my = ld(v.my + i), mz = ld(v.mz + i);
      const auto other = differ(v.id + i, t.id);
      V q;
      if constexpr (kBound) {
        // |r| < R = a_i + a_t: evaluate at r·R/|r| (rare: only touching pairs take the branch)
        const V R = add(ld(v.rad + i), trad);
        const V R2 = mul(R, R);
        V r2 = mul(dx, dx);
        r2 = fma(dy, dy, r2);
        r2 = fma(dz, dz, r2);
        const auto in = less(r2, R2) & other;
        if (in) {
          const V s = div(in, R, sqrt(in, max(r2, cst<V>(P::kTiny))));
          dx = mul_in(in, dx, s);
          dy = mul_in(in, dy, s);
          dz = mul_in(in, dz, s);
        }
        q = add(max(r2, R2), e2);
      } else {
        q = fma(dx, dx, e2);
        q = fma(dy, dy, q);
        q = fma(dz, dz, q);
      }
      const V inv = rsqrt(other, q);
      const V inv2 = mul(inv, inv);
      const V inv3 = mul(inv2, inv);
      const V inv5 = mul(inv3, inv2);
      V rm = mul(dx, mx);
      rm = fma(dy, my, rm);
      rm = fma(dz, mz, rm);
      // eq. 1
      const V a = mul(rm, inv5);
      ax = fma(a, dx, ax);
      ay = fma(a, dy, ay);
      az = fma(a, dz, az);
      bx = fma(inv3, mx, bx);
      by = fma(inv3, my, by);
      bz = fma(inv3, mz, bz);
      if constexpr (kJac) {
        // Jacobian of eq. 1 (see dipole_jacobian), same-group sources masked
        const V u = keep(differ(v.grp + i, t.grp), inv5);
        const V aj = mul(rm, u);
        const V t5 = mul(aj, mul(inv2, five));
        const V gx = mul(u, mx), gy = mul(u, my), gz = mul(u, mz);
        const V kx = fnma(t5, dx, gx), ky = fnma(t5, dy, gy), kz = fnma(t5, dz, gz);
        ja = add(ja, aj);
        jxx = fma(dx, add(gx, kx), jxx);
        jyy = fma(dy, add(gy, ky), jyy);
        jzz = fma(dz, add(gz, kz), jzz);
        jxy = fma(dy, kx, fma(dx, gy, jxy));
        jxz = fma(dz, kx, fma(dx, gz, jxz));
        jyz = fma(dz, ky, fma(dy, gz, jyz));
      }
    }
    const V part[13] = {ax, ay, az, bx, by, bz, ja, jxx, jyy, jzz, jxy, jxz, jyz};
    for (int k = 0; k < (kJac ? 13 : 6); ++k) acc[k] = fold(acc[k], part[k]);
  }
  double sums[13];
  for (int k = 0; k < (kJac ? 13 : 6); ++k) sums[k] = hsum(acc[k]);
  finish(sums, kJac, Hout, Jout);
}

bool cpu_has_avx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}

#endif  // MAGSIM_AVX512_KERNEL

std::atomic<bool> g_simd_enabled{true};

// Picks the instance: AVX-512 or portable, with or without J, bounded or not.
template <class View>
void dispatch(const View& v, const typename Precision<View>::Tgt& t,
              typename Precision<View>::T eps2, PairTerms terms, double* H, double* J) {
  const bool bound = v.rad != nullptr, jac = terms == PairTerms::HJ;
#ifdef MAGSIM_AVX512_KERNEL
  if (simd_kernel_active()) {
    if (jac) bound ? sweep_avx512<true, true>(v, t, eps2, H, J) : sweep_avx512<true, false>(v, t, eps2, H, J);
    else bound ? sweep_avx512<false, true>(v, t, eps2, H, J) : sweep_avx512<false, false>(v, t, eps2, H, J);
    return;
  }
#endif
  if (jac) bound ? sweep_portable<true, true>(v, t, eps2, H, J) : sweep_portable<true, false>(v, t, eps2, H, J);
  else bound ? sweep_portable<false, true>(v, t, eps2, H, J) : sweep_portable<false, false>(v, t, eps2, H, J);
}

}  // namespace

void enable_simd_kernel(bool on) { g_simd_enabled = on; }

bool portable_kernel_forced() {
  static const bool forced = [] {
    const char* v = std::getenv("MAGSIM_KERNEL");
    return v != nullptr && std::strcmp(v, "portable") == 0;
  }();
  return forced;
}

bool simd_kernel_active() {
#ifdef MAGSIM_AVX512_KERNEL
  return cpu_has_avx512() && !portable_kernel_forced() &&
         g_simd_enabled.load(std::memory_order_relaxed);
#else
  return false;
#endif
}

void sum_pairs(const SourceView& v, const Target& t, double eps2, PairTerms terms, double* H,
               double* J) {
  dispatch(v, t, eps2, terms, H, J);
}

void sum_pairs_f32(const SourceViewF& v, const TargetF& t, float eps2, PairTerms terms,
                   double* H, double* J) {
  dispatch(v, t, eps2, terms, H, J);
}

}  // namespace magsim::mag::detail
