// magnetics/pair_kernel.cpp — the pair kernel of field_kernel.hpp (sum_pairs in double for
// the direct sum and the Barnes–Hut near field, sum_pairs_f32 in float for the Barnes–Hut
// near field). One body (pair_sweep.inc) is compiled three times: over portable lanes for
// any CPU, over AVX2+FMA registers (simd_avx2.hpp) and over AVX-512 registers. All run 8
// double or 16 float lanes with the same operations in the same order (simd.hpp), so they
// give the same bits, and the choice between them (kernel_path) changes speed only. Float
// sums run over chunks of kChunkF sources per lane set and are then added in double, so the
// float rounding of the sum does not grow with the list; a double sweep is one chunk.
#include "magnetics/field_kernel.hpp"
#include "magnetics/simd.hpp"
#include "magnetics/simd_avx2.hpp"

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
};
template <>
struct Precision<SourceViewF> {
  using T = float;
  using Tgt = TargetF;
  static constexpr std::size_t kChunk = kChunkF;
  static constexpr std::size_t kLanes = 16;
  static constexpr float kTiny = 1e-30f;
};

// Sources per chunk of partial sums (all of them in a double sweep): each of the kLanes
// lanes sums kChunk / kLanes of them in the chunk.
template <class P>
std::size_t chunk_of(std::size_t n) {
  return P::kChunk ? P::kChunk : std::max<std::size_t>(n, 1);
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

}  // namespace

// The sweep over portable lanes (any CPU) …
namespace portable {
using namespace simd::fused_soft;  // no FMA instruction: a·b + c in +, −, ×
template <class T>
using LaneOf = simd::PortableLaneOf<T>;
#include "magnetics/pair_sweep.inc"
}  // namespace portable

#ifdef MAGSIM_FMA_KERNEL
// … over AVX2 registers where the CPU has AVX2 and FMA (two per lane set) …
#pragma GCC push_options
#pragma GCC target("avx2,fma")
namespace fma {
template <class T>
using LaneOf = simd::Avx2LaneOf<T>;
#include "magnetics/pair_sweep.inc"
}  // namespace fma
#pragma GCC pop_options
#endif

#ifdef MAGSIM_AVX512_KERNEL
// … and over AVX-512 registers: the same source, the same bits
#pragma GCC push_options
#pragma GCC target("avx512f")
namespace avx512 {
template <class T>
using LaneOf = simd::Avx512LaneOf<T>;
#include "magnetics/pair_sweep.inc"
}  // namespace avx512
#pragma GCC pop_options
#endif

namespace {

// The fastest path this build and CPU have; MAGSIM_KERNEL's limit (read once)
KernelPath cpu_best() {
  static const KernelPath best = [] {
#ifdef MAGSIM_AVX512_KERNEL
    if (__builtin_cpu_supports("avx512f")) return KernelPath::Avx512;
#endif
#ifdef MAGSIM_FMA_KERNEL
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return KernelPath::Fma;
#endif
    return KernelPath::Generic;
  }();
  return best;
}
KernelPath env_limit() {
  static const KernelPath limit = [] {
    const char* v = std::getenv("MAGSIM_KERNEL");
    if (v != nullptr && std::strcmp(v, "generic") == 0) return KernelPath::Generic;
    if (v != nullptr && std::strcmp(v, "portable") == 0) return KernelPath::Fma;
    return KernelPath::Avx512;
  }();
  return limit;
}
// the slower (larger) of two paths
KernelPath slower(KernelPath a, KernelPath b) { return a > b ? a : b; }

std::atomic<KernelPath> g_limit{KernelPath::Avx512};

// Picks the instance: AVX-512, FMA or generic, with or without J, bounded or not.
template <class View>
void dispatch(const View& v, const typename Precision<View>::Tgt& t,
              typename Precision<View>::T eps2, PairTerms terms, double* H, double* J) {
  const bool bound = v.rad != nullptr, jac = terms == PairTerms::HJ;
  const KernelPath path = kernel_path();
#ifdef MAGSIM_AVX512_KERNEL
  if (path == KernelPath::Avx512) {
    if (jac) bound ? avx512::sweep<true, true>(v, t, eps2, H, J) : avx512::sweep<true, false>(v, t, eps2, H, J);
    else bound ? avx512::sweep<false, true>(v, t, eps2, H, J) : avx512::sweep<false, false>(v, t, eps2, H, J);
    return;
  }
#endif
#ifdef MAGSIM_FMA_KERNEL
  if (path == KernelPath::Fma) {
    if (jac) bound ? fma::sweep<true, true>(v, t, eps2, H, J) : fma::sweep<true, false>(v, t, eps2, H, J);
    else bound ? fma::sweep<false, true>(v, t, eps2, H, J) : fma::sweep<false, false>(v, t, eps2, H, J);
    return;
  }
#endif
  if (jac) bound ? portable::sweep<true, true>(v, t, eps2, H, J) : portable::sweep<true, false>(v, t, eps2, H, J);
  else bound ? portable::sweep<false, true>(v, t, eps2, H, J) : portable::sweep<false, false>(v, t, eps2, H, J);
}

}  // namespace

const char* kernel_path_name(KernelPath p) {
  switch (p) {
    case KernelPath::Avx512: return "avx512";
    case KernelPath::Fma: return "fma";
    case KernelPath::Generic: return "generic";
  }
  return "generic";
}

KernelPath kernel_path() {
  return slower(slower(cpu_best(), env_limit()), g_limit.load(std::memory_order_relaxed));
}

void limit_kernel_path(KernelPath fastest) { g_limit = fastest; }

void enable_simd_kernel(bool on) { limit_kernel_path(on ? KernelPath::Avx512 : KernelPath::Fma); }

bool portable_kernel_forced() { return env_limit() != KernelPath::Avx512; }

bool simd_kernel_active() { return kernel_path() == KernelPath::Avx512; }

void sum_pairs(const SourceView& v, const Target& t, double eps2, PairTerms terms, double* H,
               double* J) {
  dispatch(v, t, eps2, terms, H, J);
}

void sum_pairs_f32(const SourceViewF& v, const TargetF& t, float eps2, PairTerms terms,
                   double* H, double* J) {
  dispatch(v, t, eps2, terms, H, J);
}

}  // namespace magsim::mag::detail
