// magnetics/barnes_hut_far.cpp — the far-cell series of Barnes–Hut (barnes_hut.cpp). One
// body (far_block.inc) is compiled over portable lanes (for any CPU), over AVX2+FMA
// registers (simd_avx2.hpp) and over AVX-512 registers, each in double (CellBuffer, 8 cells
// per block) and in single precision (CellBufferF, 16 cells per block,
// BarnesHutOptions::far_float); all give the same bits (simd.hpp).
#include "magnetics/barnes_hut_internal.hpp"
#include "magnetics/simd.hpp"
#include "magnetics/simd_avx2.hpp"

#include <cmath>
#include <type_traits>

namespace magsim::mag::bh {

namespace {

// ---- far-cell kernel ---------------------------------------------------------------------
//
// The series of the file comment, written out (u_n = q^{-n/2}, ρ = r·M − tr S, w = S r,
// s = rᵀ S r; with order 2 also o1 = O·r (matrix), o2 = O:rr, o3 = O⋮rrr, τ = t·r,
// t_a = O_abb):
//   A   = 3ρ u5 + (15 s − 22.5 τ) u7 + 52.5 o3 u9
//   4π h = A r − u3 M + u5 (4.5 t − 6 w) − 22.5 u7 o2
//   c_r = −7.5 ρ u7 + (78.75 τ − 52.5 s) u9 − 236.25 o3 u11
//   K   = 3 u5 M + 30 u7 w − 22.5 u7 t + 157.5 u9 o2 + c_r r
//   4π J = A I + r Kᵀ + K rᵀ − 6 u5 S − 45 u7 o1
// With order 1 every O term is dropped (τ = o3 = 0, t = o1 = o2 = 0).
//
// In single precision (BarnesHutOptions::far_float) the same series runs on a group's scaled
// cells (CellBufferF: r' = r/L, S' = S/L, O' = O/L², so the sums below are L³ · 4π h and L⁴ · 4π J;
// sH = 1/(4π L³) and sJ = 1/(4π L⁴) undo both in double). 1/√q as simd.hpp's inv_sqrt; lanes
// past the last cell masked to 1/√q = 0 (their cells are zeros, so every term is exactly 0).
// Partial sums in float over at most kFarChunkF cells (kFarChunkF / 16 per lane), then in
// double, in a fixed order, so the float rounding of the sum does not grow with the list.

// Cells per chunk of float partial sums (64 per AVX-512 lane; lists are rarely longer).
constexpr std::size_t kFarChunkF = 1024;

// What differs between the precisions: the cell buffer, the cells per block (W) and the
// cells per chunk of partial sums (0: one chunk; double sums need no chunks).
template <class T>
struct FarPrecision;
template <>
struct FarPrecision<double> {
  using Buffer = CellBuffer;
  static constexpr std::size_t kW = 8;
  static constexpr std::size_t kChunkCells = 0;
  static constexpr bool kMasked = false;  // padded with zero cells far away (CellBuffer::pad)
};
template <>
struct FarPrecision<float> {
  using Buffer = CellBufferF;
  static constexpr std::size_t kW = 16;
  static constexpr std::size_t kChunkCells = kFarChunkF;
  static constexpr bool kMasked = true;  // lanes past the last cell hold zeros: masked
};

// Blocks per chunk of partial sums for a kernel that sums `per_lane` cells per partial sum
// (the portable loop may not be vectorized: each of its sums then takes a whole chunk).
template <class T>
std::size_t chunk_blocks(std::size_t nb, std::size_t per_sum) {
  const std::size_t c = FarPrecision<T>::kChunkCells;
  return c ? std::max<std::size_t>(1, c / per_sum) : std::max<std::size_t>(nb, 1);
}

}  // namespace

// The series over portable lanes (any CPU) …
namespace portable {
using namespace detail::simd::fused_soft;  // no FMA instruction: a·b + c in +, −, ×
template <class T>
using LaneOf = detail::simd::PortableLaneOf<T>;
#include "magnetics/far_block.inc"
}  // namespace portable

#ifdef MAGSIM_FMA_KERNEL
// … over AVX2 registers where the CPU has AVX2 and FMA (two per lane set) …
#pragma GCC push_options
#pragma GCC target("avx2,fma")
namespace fma {
template <class T>
using LaneOf = detail::simd::Avx2LaneOf<T>;
#include "magnetics/far_block.inc"
}  // namespace fma
#pragma GCC pop_options
#endif

#ifdef MAGSIM_AVX512_KERNEL
// … and over AVX-512 registers: the same source, the same bits
#pragma GCC push_options
#pragma GCC target("avx512f")
namespace avx512 {
template <class T>
using LaneOf = detail::simd::Avx512LaneOf<T>;
#include "magnetics/far_block.inc"
}  // namespace avx512
#pragma GCC pop_options
#endif

namespace {

template <class T, bool kH, bool kJ>
void far_run(const typename FarPrecision<T>::Buffer& cb, int order, const T* p, T eps2,
             double sH, double sJ, double* H, double* J) {
  const detail::KernelPath path = detail::kernel_path();
#ifdef MAGSIM_AVX512_KERNEL
  if (path == detail::KernelPath::Avx512) {
    if (order >= 2) avx512::far_lanes<T, kH, kJ, 2>(cb, p, eps2, sH, sJ, H, J);
    else avx512::far_lanes<T, kH, kJ, 1>(cb, p, eps2, sH, sJ, H, J);
    return;
  }
#endif
#ifdef MAGSIM_FMA_KERNEL
  if (path == detail::KernelPath::Fma) {
    if (order >= 2) fma::far_lanes<T, kH, kJ, 2>(cb, p, eps2, sH, sJ, H, J);
    else fma::far_lanes<T, kH, kJ, 1>(cb, p, eps2, sH, sJ, H, J);
    return;
  }
#endif
  if (order >= 2) portable::far_lanes<T, kH, kJ, 2>(cb, p, eps2, sH, sJ, H, J);
  else portable::far_lanes<T, kH, kJ, 1>(cb, p, eps2, sH, sJ, H, J);
}

template <class T>
void far_terms(const typename FarPrecision<T>::Buffer& cb, int order, FarTerms terms,
               const T* p, T eps2, double sH, double sJ, double* H, double* J) {
  if (cb.size() == 0) return;
  switch (terms) {
    case FarTerms::HJ: far_run<T, true, true>(cb, order, p, eps2, sH, sJ, H, J); break;
    case FarTerms::H: far_run<T, true, false>(cb, order, p, eps2, sH, sJ, H, J); break;
    case FarTerms::J: far_run<T, false, true>(cb, order, p, eps2, sH, sJ, H, J); break;
  }
}

}  // namespace

void far_sum(const CellBuffer& cb, int order, FarTerms terms, const double* p, double eps2,
             double* H, double* J) {
  far_terms<double>(cb, order, terms, p, eps2, kInv4Pi, kInv4Pi, H, J);
}

void far_sum(const CellBufferF& cb, int order, FarTerms terms, const float* p, float eps2,
             double sH, double sJ, double* H, double* J) {
  far_terms<float>(cb, order, terms, p, eps2, sH, sJ, H, J);
}

}  // namespace magsim::mag::bh
