// magnetics/field_kernel.hpp — internal: the packed-source layout and the SIMD pair kernel
// behind compute_fields (dipole_field.cpp) and the near field of Barnes–Hut (barnes_hut.cpp).
// Not part of the public API: include only from magnetics/*.cpp (and the kernel's own
// tests and benchmark).
#pragma once

#include "magnetics/types.hpp"

#include <cstddef>
#include <vector>

// AVX-512 kernels are compiled per function (target attribute) and chosen at run time, so
// the rest of the build stays at AVX2 (see CMakeLists.txt)
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define MAGSIM_AVX512_KERNEL 1
#define MAGSIM_TARGET_AVX512 __attribute__((target("avx512f")))
#endif

namespace magsim::mag::detail {

inline constexpr double kInv4Pi = 1.0 / (4.0 * kPi);  ///< 1/4π of eq. 1

/// Sources are padded to a multiple of this with zero moments far away (they add exactly 0).
inline constexpr std::size_t kSourcePad = 8;
/// Position of a padding source or cell (m): far enough to never matter, near enough that
/// every power of 1/|r| the kernels form (up to 1/|r|¹¹) stays a normal double; its zero
/// moment makes every term exactly zero.
inline constexpr double kPadPosition = 1e15;

/// Flat source arrays (structure of arrays).
struct SourceBuffer {
  std::vector<double> x, y, z;     ///< (ns) position (m)
  std::vector<double> mx, my, mz;  ///< (ns) moment (A·m²)
  std::vector<double> id;          ///< (ns) moment index (−1 for padding), for self-exclusion
  std::vector<double> grp;         ///< (ns) group id (negative groups stored as −1)

  std::size_t size() const { return x.size(); }
  void clear();
  void push(double px, double py, double pz, double qx, double qy, double qz, double index,
            double group);
};

/// A read-only view of padded source arrays (as FieldWorkspace's or a gathered copy).
struct SourceView {
  const double *x, *y, *z, *mx, *my, *mz, *id, *grp;
  std::size_t n;  ///< a multiple of kSourcePad
};

/// A target point: its own moment index (−1: none) and group for the exclusions.
struct Target {
  double x, y, z;
  double id;   ///< moment index; a source with the same id is skipped (self)
  double grp;  ///< group id as a double, NaN when the target has no group (< 0)
};

/// What a pair sum adds.
enum class PairTerms { H, HJ };

/// Adds to H[0..2] the field (eq. 1) at t of every source in v except t's own, and with
/// PairTerms::HJ to J[0..5] (xx, yy, zz, xy, xz, yz) the Jacobian of those not in t's group.
/// Softened with eps2 = ε². Results in A/m (A/m²). Dispatches to AVX-512 where the CPU has
/// it, else a portable loop; the sum order is fixed, so results are deterministic.
void sum_pairs(const SourceView& v, const Target& t, double eps2, PairTerms terms, double* H,
               double* J);

/// True when sum_pairs (and the Barnes–Hut far-cell kernel) run the AVX-512 path: the CPU
/// has it and it has not been switched off.
bool simd_kernel_active();
/// Switches the AVX-512 path off (false) or back on, for tests and benchmarks that compare
/// it with the portable loop. Not to be called while a field evaluation runs.
void enable_simd_kernel(bool on);

}  // namespace magsim::mag::detail
