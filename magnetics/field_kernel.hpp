// magnetics/field_kernel.hpp — internal: the SIMD pair kernel behind the direct sum
// (dipole_field.cpp) and the near field of Barnes–Hut (barnes_hut.cpp), in double and in
// single precision (both in pair_kernel.cpp), over the packed sources of source_buffer.hpp.
// Not part of the public API: include only from magnetics/*.cpp (and the kernel's own
// tests and benchmark). It sits below both field sums and their dispatcher (fields.hpp), so
// it includes none of their headers.
#pragma once

#include "magnetics/source_buffer.hpp"
#include "magnetics/types.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

// AVX-512 kernels are compiled per function (target attribute) and chosen at run time, so
// the rest of the build stays at AVX2 (see CMakeLists.txt). The portable build
// (-DMAGSIM_NATIVE=OFF defines MAGSIM_PORTABLE_KERNELS) has none: its field sums must not
// depend on the CPU it runs on.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(MAGSIM_PORTABLE_KERNELS)
#include <immintrin.h>
#define MAGSIM_AVX512_KERNEL 1
#define MAGSIM_TARGET_AVX512 __attribute__((target("avx512f")))
#endif
// The AVX2+FMA kernels (simd_avx2.hpp) are compiled per region too, chosen at run time, in
// every x86-64 build: for CPUs with FMA but no AVX-512.
#if defined(__x86_64__) && defined(__GNUC__)
#define MAGSIM_FMA_KERNEL 1
#endif

namespace magsim::mag::detail {

inline constexpr double kInv4Pi = 1.0 / (4.0 * kPi);  ///< 1/4π of eq. 1

/// A read-only view of padded source arrays (the direct sum's packed sources or a gathered
/// copy).
struct SourceView {
  const double *x, *y, *z, *mx, *my, *mz, *id, *grp;
  std::size_t n;  ///< a multiple of kSourcePad
  /// interaction radii a_i (m); nullptr = unbounded point dipoles (see sum_pairs)
  const double* rad;
};

/// The view of sources [b, e) of a padded buffer (bounded: with their radii).
inline SourceView view_of(const SourceBuffer& s, bool bounded, std::size_t b, std::size_t e) {
  return SourceView{s.x.data() + b,  s.y.data() + b,  s.z.data() + b,   s.mx.data() + b,
                    s.my.data() + b, s.mz.data() + b, s.id.data() + b,  s.grp.data() + b,
                    e - b,           bounded ? s.rad.data() + b : nullptr};
}

/// A target point: its own moment index (−1: none) and group for the exclusions.
struct Target {
  double x, y, z;
  double id;   ///< moment index; a source with the same id is skipped (self)
  double grp;  ///< group id as a double, NaN when the target has no group (< 0)
  double rad;  ///< its interaction radius a_t (m), used with SourceView::rad
};

/// What a pair sum adds.
enum class PairTerms { H, HJ };

/// Adds to H[0..2] the field (eq. 1) at t of every source in v except t's own, and with
/// PairTerms::HJ to J[0..5] (xx, yy, zz, xy, xz, yz) the Jacobian of those not in t's group.
/// Softened with eps2 = ε². Results in A/m (A/m²). Dispatches to AVX-512 where the CPU has
/// it, else AVX2+FMA, else portable lanes; all give the same bits (simd.hpp).
///
/// Bounded pairs (v.rad != nullptr): a pair closer than R = a_i + a_t is evaluated at the
/// separation R along its own direction, r → r·R/|r| (field and Jacobian alike), so an
/// overlap cannot raise the pair's field or force above their values at contact; pairs at
/// |r| ≥ R are exact. The Jacobian there is the dipole Jacobian at the clamped point, not
/// the derivative of the clamped field (which has no radial part): the force stays
/// continuous through |r| = R and bounded, at the price of not being a gradient inside an
/// overlap. Softening then applies to the clamped separation.
void sum_pairs(const SourceView& v, const Target& t, double eps2, PairTerms terms, double* H,
               double* J);

// ---- single precision (Barnes–Hut near field, BarnesHutOptions::near_float) -------------

/// Float sources are padded to a multiple of this (one AVX-512 register of floats).
inline constexpr std::size_t kSourcePadF = 16;
/// Position of a float padding source, relative to the group centre (m): with the target a
/// few cm from the centre, q ≈ 3e8 m², so every power of 1/|r| the float kernel forms (up to
/// 1/|r|⁷ ≈ 2e-30) stays a normal float; the zero moment makes every term exactly zero.
inline constexpr float kPadPositionF = 1e4f;
/// Group id that no source carries (a target without a group).
inline constexpr std::int32_t kNoGroupF = INT32_MIN;

/// Float source arrays, positions RELATIVE to a centre (the Barnes–Hut target group's), so
/// that float carries ~1e-9 m absolute error for a group a few cm across (never convert
/// absolute world coordinates to float). Moments in A·m²; id = moment index (−1 padding);
/// grp = group (−1 none).
struct SourceViewF {
  const float *x, *y, *z, *mx, *my, *mz;
  const std::int32_t *id, *grp;
  std::size_t n;  ///< a multiple of kSourcePadF
  const float* rad;  ///< interaction radii (m); nullptr = unbounded (as SourceView::rad)
};

/// A target relative to the same centre as the sources of its SourceViewF.
struct TargetF {
  float x, y, z;
  std::int32_t id;   ///< moment index; a source with the same id is skipped (self)
  std::int32_t grp;  ///< group id, kNoGroupF when the target has no group (< 0)
  float rad;         ///< its interaction radius (m), used with SourceViewF::rad
};

/// sum_pairs in single precision: the same terms (eq. 1, softened, bounded pairs as in
/// sum_pairs; the Jacobian without the
/// target's group; never the target itself), each source evaluated in float, summed per
/// lane in float over at most kChunkF sources and then in double (so the rounding of the
/// sum stays ~1e-7 relative to Σ|terms| however long the list). AVX-512 when
/// simd_kernel_active(), else portable lanes: 16 float lanes either way, the same bits
/// (simd.hpp). Results added to H, J as
/// sum_pairs does. Assumes separations ≫ 1e-5 m (or a softening): 1/|r|⁷ must not overflow.
void sum_pairs_f32(const SourceViewF& v, const TargetF& t, float eps2, PairTerms terms,
                   double* H, double* J);
/// Sources per chunk of float partial sums in sum_pairs_f32 (each float lane sums
/// kChunkF / 16 of them; then the chunk is added in double). 1024 measured ~7 % faster than
/// 256 with the same error (float vs double near field RMS ~4e-7 either way).
inline constexpr std::size_t kChunkF = 1024;

/// The three instances of the field kernels (sum_pairs, sum_pairs_f32 and the Barnes–Hut
/// far cells), fastest first. They give the same bits; the choice changes speed only.
enum class KernelPath {
  Avx512,   ///< AVX-512 registers (native builds, CPUs with AVX-512F)
  Fma,      ///< AVX2+FMA registers (simd_avx2.hpp; CPUs with both)
  Generic,  ///< portable lanes for any x86-64: fused multiply-adds emulated (simd.hpp soft_fma)
};
/// "avx512", "fma" or "generic"
const char* kernel_path_name(KernelPath p);

/// The path the kernels take: the fastest that the build has, the CPU has, the environment
/// allows and limit_kernel_path has not excluded.
///
/// MAGSIM_KERNEL in the environment (read once, at the first field evaluation): "portable"
/// excludes AVX-512 (the path of a CPU with AVX2+FMA but no AVX-512), "generic" excludes FMA
/// too (the path of a CPU without FMA); unset or "auto": the fastest. (The command-line
/// programs refuse any other value, tools/cli/cli_common.hpp.)
KernelPath kernel_path();
/// For tests and benchmarks that compare the paths: at most `fastest` from now on (Avx512:
/// no limit); the environment's limit still holds. Not to be called while a field
/// evaluation runs.
void limit_kernel_path(KernelPath fastest);
/// kernel_path() == KernelPath::Avx512
bool simd_kernel_active();
/// limit_kernel_path(on ? Avx512 : Fma): the AVX-512 path off or back on
void enable_simd_kernel(bool on);
/// True when MAGSIM_KERNEL was set to "portable" or "generic" (read once).
bool portable_kernel_forced();

}  // namespace magsim::mag::detail
